#!/usr/bin/env bash
# Runs every benchmark and regenerates every chart and table of docs/PERFORMANCE.md:
# Google Benchmark JSON and analysis JSON in docs/bench/, PNG charts beside them, tables in
# docs/PERFORMANCE.md between its BEGIN/END markers; then every fuzz harness for 2 minutes
# (HK_BENCH_FUZZ_SECONDS; CI runs them for 10 s). Takes ~35 minutes on 2 cores.
# Usage: scripts/bench.sh [--quick]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
quick=""
[ "${1:-}" = "--quick" ] && quick="--quick"
bash "$root/scripts/install-deps.sh"
if ! /usr/bin/python3 -c "import matplotlib" 2>/dev/null; then
  sudo_cmd=""; [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get install -y -qq --no-install-recommends python3-matplotlib >/dev/null
fi
bash "$root/scripts/build.sh" "$root/build" >/dev/null
out="$root/docs/bench"
mkdir -p "$out"
b="$root/build/bench"
min_time=0.5
[ -n "$quick" ] && min_time=0.05
taskset -c 1 "$b/bench_first_hit" $quick --benchmark_min_time=$min_time --benchmark_out="$out/first_hit.json" --benchmark_out_format=json >/dev/null
# Five runs of each picture and method, one after the other; plot_bench.py keeps each one's fastest, the
# run least disturbed by the shared machine's slow spells. (Not randomly interleaved: switching pictures
# between runs makes every run resize the per-thread buffers, which is not the steady state measured.)
# BM_SceneBuildPaired/<picture> runs ours and both OpenCV variants side by side, one build of each in turn,
# and gives each one's fastest single build: the three sample the same moments of the machine.
taskset -c 1 "$b/bench_scene_build" --benchmark_min_time=$(awk "BEGIN { print $min_time / 5 }") --benchmark_repetitions=5 \
  --benchmark_out="$out/scene_build.json" --benchmark_out_format=json >/dev/null
"$b/bench_detectors" --benchmark_min_time=$min_time --benchmark_out="$out/detectors.json" --benchmark_out_format=json >/dev/null
"$b/bench_anytime" --out "$out/anytime.json" 2>/dev/null
[ -x "$b/bench_accuracy" ] && "$b/bench_accuracy" --images "$root/tests/data/images" --out "$out/accuracy.json"
[ -x "$b/bench_stability" ] && "$b/bench_stability" $quick --out "$out/stability.json"
"$b/bench_earcon_latency" --out "$out/earcon_latency.json" > "$out/earcon_latency.md"
"$b/bench_audio_latency" > "$out/audio_latency.json" 2>/dev/null || true
"$b/bench_servo_rate" --seconds 5 --out "$out/servo_rate.json" 2>/dev/null > "$out/servo_rate.md"
"$b/bench_levels" --out "$out/levels.json" > "$out/levels.md"
"$b/bench_tolerance_cut" --out "$out/tolerance_cut.json" > "$out/tolerance_cut.md"
"$b/bench_servo_tick" --cpu 0 --out "$out/servo_tick.json" > "$out/servo_tick.md"
"$b/bench_stick_scan" --out "$out/stick_scan.json" > "$out/stick_scan.txt"
"$b/bench_pdf_pages" --out "$out/pdf_pages.json" > "$out/pdf_pages.md"
"$b/bench_stick_first_page" --out "$out/stick_first_page.json" > "$out/stick_first_page.md"
"$b/bench_device_loop" --seconds 5 --out "$out/device_loop.json" 2>/dev/null > "$out/device_loop.md"
"$b/bench_tour_time" > "$out/tour_time.md"
"$b/bench_random_visits" --seeds 4 --json "$out/random_visits.json" > "$out/random_visits.txt"  # long seeded random visits: every key answered, the kiosk new after Finish
"$b/bench_speech_times" > "$out/speech_times.md"  # how long the kiosk talks, and how soon a key is answered
"$b/bench_voices" > "$out/voices.md"  # each voice's first audio and speed, a change of language, the catalogues
"$b/bench_ocr_pages" > "$out/ocr_pages.md"  # text read from scans and pictures: time, memory, recall, false blocks
"$b/bench_decode" > "$out/decode.md"  # a picture file's decode, full and as the scene build does it (reduced JPEG), and the scene after it
"$b/bench_next_picture" --out "$out/next_picture.md" > /dev/null  # Next pressed -> first servo tick on the new scene: cold, prefetched, cached; tests/data pictures, 24/12 MP JPEGs, 13 MP PNGs, a 51-page PDF
"$b/bench_meaning_cost" > "$out/meaning_cost.md"  # descriptors, faces and describe_scene against the rest of a cold scene build, per picture
"$b/bench_tactile_copies" > "$out/tactile_copies.md"  # take-home copies: lay out, PDF and SVG times, the guidelines' distances per picture
taskset -c 1 "$b/bench_section_cost" --segments 100000 1000000 > "$out/section_cost.md"  # first_hit by kind of query (PERFORMANCE "The boundary section's full queries")
"$b/bench_capture_latency" --out "$out/capture_latency.json" > "$out/capture_latency.md"
"$b/bench_library_reload" --out "$out/library_reload.md" > /dev/null  # 100 pictures copied into the watched library: live after, frames meanwhile
"$b/bench_metrics_endpoint" --out "$out/metrics_endpoint.md" > /dev/null  # GET /metrics at 100/s: latency, and the servo's missed deadlines with and without
[ -x "$b/bench_rectify" ] && "$b/bench_rectify" --benchmark_min_time=$min_time --benchmark_out="$out/rectify.json" --benchmark_out_format=json >/dev/null
bash "$root/bench/coverage.sh" "$root/build" "$out" >/dev/null  # coverage per picture: CSV, chart and its table
bash "$root/bench/scene_detectors.sh" "$root/build" "$out" > "$out/scene_detectors.md"  # each picture's scene, canny → auto, and per detector
# Tables printed by the audio and servo benches go between their markers in PERFORMANCE.md.
/usr/bin/python3 - "$out" "$root/docs/PERFORMANCE.md" <<'PY'
import re, sys
doc = open(sys.argv[2]).read()
for name, part in (("tolerance_cut", 1), ("tolerance_cut_polygons", 2), ("tolerance_cut_corners", 3), ("servo_tick", 0), ("earcon_latency", 0), ("servo_rate", 0), ("levels", 0), ("levels_speed", 1), ("stick_first_page", 0), ("pdf_pages", 0), ("device_loop", 0), ("device_loop_servo", 1), ("capture_latency", 0), ("scene_detectors", 0), ("scene_detectors_compare", 1)):
    md = next((p for p in ("levels", "device_loop", "tolerance_cut", "scene_detectors") if name.startswith(p)), name)
    lines = [l for l in open(f"{sys.argv[1]}/{md}.md").read().strip().split("\n\n")[part].splitlines() if l.startswith("|")]
    # Whatever is between the markers (nothing, the first time) becomes the table.
    doc = re.sub(rf"(<!-- BEGIN {name} -->\n).*?(<!-- END {name} -->)", lambda m: m.group(1) + "\n".join(lines) + "\n" + m.group(2), doc, flags=re.S)
open(sys.argv[2], "w").write(doc)
PY
/usr/bin/python3 "$root/bench/plot_bench.py" "$out" "$root/docs/PERFORMANCE.md"
/usr/bin/python3 "$root/bench/plot_accuracy.py" "$out/accuracy.json" --outdir "$out"
/usr/bin/python3 "$root/bench/plot_levels.py" "$out/levels.json" --outdir "$out"
if [ -f "$out/stability.json" ]; then
  /usr/bin/python3 "$root/bench/plot_stability.py" "$out/stability.json" --outdir "$out"
fi
# The long fuzz runs (CI runs each harness for 10 s): HK_BENCH_FUZZ_SECONDS each, 0 to leave them out.
if [ "${HK_BENCH_FUZZ_SECONDS:-120}" != 0 ]; then
  bash "$root/scripts/fuzz.sh" --seconds "${HK_BENCH_FUZZ_SECONDS:-120}"
fi
echo "bench: charts in $out, tables in docs/PERFORMANCE.md"
