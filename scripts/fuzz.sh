#!/usr/bin/env bash
# Builds the libFuzzer harnesses (fuzz/, clang, -fsanitize=fuzzer,address,undefined) and runs each for a
# while on seeds assembled from tests/data (fuzz/make_corpus.sh), in a temporary corpus folder, so the
# repository is not modified. Installs nothing (scripts/install-deps.sh does).
#
#   scripts/fuzz.sh [--seconds N] [--jobs J] [--build DIR] [harness ...]
#     --seconds N   fuzzing time per harness (default 30)
#     --jobs J      harnesses run at once, and build jobs (default: nproc)
#     --build DIR   build folder (default: build-fuzz in the repository root)
#     harness       image pdf config messages hand_csv hapi_reply stick_name ocr annotations (default: all)
#
# Each harness runs with -max_total_time=N -timeout=10 (pdf: 30, see timeout_s) -rss_limit_mb=2048, a
# -max_len suited to its input and its dictionary (fuzz/dicts).
# Prints one line per harness, "harness NAME: RUNS runs, CRASHES crashes" (RUNS: libFuzzer's
# stat::number_of_executed_units; CRASHES: crash-, leak-, timeout- and oom- inputs written), then where the
# inputs and logs were saved. Exits 1 when a harness crashed or did not run to its end (failed to start,
# killed), 2 on a usage error.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
seconds=30
jobs=$(nproc)
build=$repo/build-fuzz
all=(image pdf config messages hand_csv hapi_reply stick_name ocr annotations)
harnesses=()
usage() { sed -n '6,11p' "$0" | sed -e 's/^# \{0,1\}//' >&2; exit 2; }
while [ $# -gt 0 ]; do
  case $1 in
    --seconds) [ $# -ge 2 ] || usage; seconds=$2; shift 2 ;;
    --jobs) [ $# -ge 2 ] || usage; jobs=$2; shift 2 ;;
    --build) [ $# -ge 2 ] || usage; build=$2; shift 2 ;;
    -h|--help) usage ;;
    -*) echo "fuzz.sh: unknown option $1" >&2; usage ;;
    *) harnesses+=("$1"); shift ;;
  esac
done
[[ $seconds =~ ^[0-9]+$ && $seconds -ge 1 ]] || { echo "fuzz.sh: --seconds needs a whole number >= 1" >&2; exit 2; }
[[ $jobs =~ ^[0-9]+$ && $jobs -ge 1 ]] || { echo "fuzz.sh: --jobs needs a whole number >= 1" >&2; exit 2; }
[ ${#harnesses[@]} -gt 0 ] || harnesses=("${all[@]}")
for h in "${harnesses[@]}"; do
  [[ " ${all[*]} " == *" $h "* ]] || { echo "fuzz.sh: unknown harness '$h' (known: ${all[*]})" >&2; exit 2; }
done
build=$(mkdir -p "$build" && cd "$build" && pwd)

# Largest input per harness [bytes].
declare -A max_len=([image]=65536 [pdf]=65536 [config]=32768 [messages]=131072 [hand_csv]=8192 [hapi_reply]=1024
                    [stick_name]=1024 [ocr]=16384 [annotations]=16384)
# Slowest run that is not a "timeout" finding [s]. pdf: poppler is not our code and the kiosk runs it only in
# the worker process, which is killed after 5 s of CPU; a run within that (slower here, in-process under ASan)
# is no bug, so only a pathological one (over 30 s) is reported.
declare -A timeout_s=([pdf]=30)

# Configure (clang; only the harnesses' sources are compiled) and build.
if [ -f "$build/CMakeCache.txt" ] && ! grep -q '^CMAKE_CXX_COMPILER:.*clang' "$build/CMakeCache.txt"; then
  echo "fuzz.sh: $build was configured with another compiler; use an empty --build folder" >&2
  exit 2
fi
t0=$(date +%s)
root="$repo"
source "$repo/scripts/compiler-cache.sh"
CC=clang CXX=clang++ cmake -S "$repo" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DHK_FUZZ=ON \
  -DHK_BUILD_TESTS=OFF -DHK_BUILD_BENCH=OFF "${hk_cache_args[@]}" > "$build/fuzz-configure.log" 2>&1 ||
  { cat "$build/fuzz-configure.log" >&2; echo "fuzz.sh: configure failed" >&2; exit 1; }
targets=()
for h in "${harnesses[@]}"; do targets+=(--target "fuzz_$h"); done
cmake --build "$build" -j "$jobs" "${targets[@]}" > "$build/fuzz-build.log" 2>&1 ||
  { tail -50 "$build/fuzz-build.log" >&2; echo "fuzz.sh: build failed (log: $build/fuzz-build.log)" >&2; exit 1; }
echo "fuzz: configured and built in $(( $(date +%s) - t0 )) s"

work=$(mktemp -d "${TMPDIR:-/tmp}/hk-fuzz.XXXXXX")
trap 'rm -rf "$work"' EXIT
"$repo/fuzz/make_corpus.sh" "$work" "${harnesses[@]}"
out=$build/fuzz-artifacts/$(date +%Y%m%d-%H%M%S)-$$
mkdir -p "$out"

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:symbolize=1}
export LSAN_OPTIONS=suppressions=$repo/fuzz/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
if [ -z "${ASAN_SYMBOLIZER_PATH:-}" ] && command -v llvm-symbolizer-14 > /dev/null; then
  export ASAN_SYMBOLIZER_PATH=$(command -v llvm-symbolizer-14)
fi

run_one() {
  local h=$1
  mkdir -p "$out/$h"
  # libFuzzer ends itself after -max_total_time; the outer timeout only catches a harness stuck outside a run.
  set +e
  timeout --kill-after=10 $((seconds + 120)) "$build/fuzz/fuzz_$h" "$work/corpus/$h" -max_total_time="$seconds" -timeout="${timeout_s[$h]:-10}" \
    -rss_limit_mb=2048 -max_len="${max_len[$h]}" -dict="$work/dicts/$h.dict" -print_final_stats=1 \
    -artifact_prefix="$out/$h/" > "$out/$h.log" 2>&1
  echo $? > "$out/$h.rc"
  set -e
}

running=0
for h in "${harnesses[@]}"; do
  if [ "$running" -ge "$jobs" ]; then
    wait -n || true
    running=$((running - 1))
  fi
  run_one "$h" &
  running=$((running + 1))
done
wait || true

status=0
notes=()
for h in "${harnesses[@]}"; do
  runs=$(sed -n 's/^stat::number_of_executed_units: *\([0-9]*\).*/\1/p' "$out/$h.log" | tail -1)
  crashes=$(find "$out/$h" -maxdepth 1 -type f \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' -o -name 'oom-*' \) | wc -l)
  rc=$(cat "$out/$h.rc" 2> /dev/null || echo 127)
  echo "harness $h: ${runs:-0} runs, $crashes crashes"
  if [ "$crashes" -gt 0 ]; then
    status=1
    notes+=("fuzz: $h: inputs in $out/$h/, log $out/$h.log (reproduce: $build/fuzz/fuzz_$h <input>)")
  elif [ "$rc" != 0 ] || [ -z "$runs" ]; then
    status=1
    notes+=("fuzz: $h: did not run to its end (exit status $rc), log $out/$h.log")
  fi
done
for n in "${notes[@]}"; do echo "$n"; done
echo "fuzz: logs in $out"
exit $status
