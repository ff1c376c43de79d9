#!/usr/bin/env bash
# Fresh machine → every test, in stages (each stage's minutes printed at the end):
#   deps      installs the Debian packages (scripts/install-deps.sh)
#   checks    app/'s rooms depend one way (check-rooms.sh); the sources are formatted (check-format.sh)
#   build     AddressSanitizer + UBSan, warnings as errors, through ccache when it is installed
#             (scripts/compiler-cache.sh: its cache lives outside the checkout and survives a fresh clone)
#   tests     the GoogleTest suites through CTest, in shards of about 25 tests a process (HK_TEST_SHARDS)
#   fuzz      every libFuzzer harness for HK_FUZZ_SECONDS (10 s here; scripts/bench.sh runs them longer)
#   package   the Debian package, built and checked (lintian, file list, systemd-analyze verify)
#   limits    the PDF and OCR workers' memory limits, which ASan cannot host, on the package's Release build
#   fleet     the Ansible playbook (syntax, ansible-lint, the role in check mode against this machine, a broken
#             library refused first) and the Prometheus files (promtool): tests/fleet/check.sh
# The benchmarks are not built here (scripts/bench.sh builds and runs them).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="$root/build-asan"
stages=()
# Runs one stage and records its duration [s].
stage() {
  local name="$1" t0
  shift
  t0=$(date +%s)
  "$@"
  stages+=("$name $(( $(date +%s) - t0 ))")
}
# intercept_tls_get_addr=0: GCC 12's LeakSanitizer follows dynamic TLS through __tls_get_addr, and with glibc 2.36's
# thread vectors its tracer can read a freed one at exit ("Tracer caught signal 11"; seen with libsystemd and
# libcamera's lttng-ust loaded together). Without the interception, dynamic TLS blocks are still scanned as the heap
# allocations they are.
run_tests() {
  (cd "$build" && ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:intercept_tls_get_addr=0" UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
    LSAN_OPTIONS="suppressions=$root/tests/lsan.supp" ctest --output-on-failure -j "$(nproc)" --timeout 1200)
}
package_and_check() {
  bash "$root/scripts/package.sh"
  local version
  version="$(sed -n 's/^project([^)]*VERSION \([0-9][0-9.]*\).*/\1/p' "$root/CMakeLists.txt" | head -n 1)"
  bash "$root/scripts/check-package.sh" "$root/dist/haptic-kiosk_${version}_$(dpkg --print-architecture).deb"
}
# The workers' memory limits, which the AddressSanitizer build cannot host: test_worker_limits built in the
# package's Release build (its vision library already compiled there), run on the workers built beside it.
worker_limits() {
  local pkg="$root/build-package"
  cmake -S "$root" -B "$pkg" -DHK_WORKER_LIMIT_TESTS=ON > /dev/null
  cmake --build "$pkg" -j "$(nproc)" --target test_worker_limits hk-pdf-worker hk-ocr-worker
  HK_PDF_WORKER="$pkg/vision/hk-pdf-worker" HK_OCR_WORKER="$pkg/vision/hk-ocr-worker" "$pkg/test_worker_limits" --gtest_brief=1
}
# The fleet's files against the package just built and the kiosk of the sanitizer build.
fleet_check() {
  local version
  version="$(sed -n 's/^project([^)]*VERSION \([0-9][0-9.]*\).*/\1/p' "$root/CMakeLists.txt" | head -n 1)"
  bash "$root/tests/fleet/check.sh" "$root/dist/haptic-kiosk_${version}_$(dpkg --print-architecture).deb" \
    "$build/app/haptic-kiosk"
}
checks() {
  bash "$root/scripts/check-rooms.sh"
  bash "$root/scripts/check-format.sh"
}
t_all=$(date +%s)
stage deps bash "$root/scripts/install-deps.sh"
stage checks checks
stage build bash "$root/scripts/build.sh" "$build" -DHK_SANITIZE=ON -DHK_WERROR=ON -DHK_BUILD_BENCH=OFF -DHK_TEST_SHARDS=ON
stage tests run_tests
stage fuzz bash "$root/scripts/fuzz.sh" --seconds "${HK_FUZZ_SECONDS:-10}"
stage package package_and_check
stage limits worker_limits
stage fleet fleet_check
echo "test.sh: stage minutes"
for s in "${stages[@]}" "all $(( $(date +%s) - t_all ))"; do
  awk -v name="${s% *}" -v s="${s#* }" 'BEGIN { printf "  %-8s %5.1f\n", name, s / 60 }'
done
