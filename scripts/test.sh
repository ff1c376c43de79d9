#!/usr/bin/env bash
# Fresh machine → every test: installs packages; builds with AddressSanitizer + UBSan and warnings as
# errors and runs the GoogleTest suites through CTest, in shards of about 25 tests a process
# (HK_TEST_SHARDS, tests/CMakeLists.txt); runs every libFuzzer harness for 30 s (scripts/fuzz.sh); builds the Debian package and checks it (lintian, file list, systemd-analyze verify).
# The benchmarks are not built here (scripts/bench.sh builds and runs them), to keep CI under 40 minutes.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="$root/build-asan"
bash "$root/scripts/install-deps.sh"
bash "$root/scripts/build.sh" "$build" -DHK_SANITIZE=ON -DHK_WERROR=ON -DHK_BUILD_BENCH=OFF -DHK_TEST_SHARDS=ON
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
(cd "$build" && ctest --output-on-failure -j "$(nproc)" --timeout 1200)
unset ASAN_OPTIONS UBSAN_OPTIONS
bash "$root/scripts/fuzz.sh" --seconds "${HK_FUZZ_SECONDS:-30}"
bash "$root/scripts/package.sh"
version="$(sed -n 's/^project([^)]*VERSION \([0-9][0-9.]*\).*/\1/p' "$root/CMakeLists.txt" | head -n 1)"
bash "$root/scripts/check-package.sh" "$root/dist/haptic-kiosk_${version}_$(dpkg --print-architecture).deb"
