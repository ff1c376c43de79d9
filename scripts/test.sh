#!/usr/bin/env bash
# Fresh machine → every test: installs packages, builds with AddressSanitizer + UBSan and warnings as
# errors, runs the GoogleTest suites through CTest.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="$root/build-asan"
bash "$root/scripts/install-deps.sh"
bash "$root/scripts/build.sh" "$build" -DHK_SANITIZE=ON -DHK_WERROR=ON
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
cd "$build"
ctest --output-on-failure -j "$(nproc)" --timeout 1200
