#!/usr/bin/env bash
# Fresh machine → explore a shipped picture: installs packages, builds, runs the headless pipeline.
# Usage: scripts/demo.sh [IMAGE] [OUT_DIR]
# Builds only what it runs, in its own build folder (build-demo; HK_DEMO_BUILD_DIR overrides): haptic-kiosk,
# and through the vision library's dependencies the PDF and OCR workers it starts (hk-pdf-worker,
# hk-ocr-worker, found by the paths compiled into vision). No tests, no benchmarks.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
image="${1:-$root/tests/data/images/horse.png}"
out="${2:-$root/out/demo}"
build="${HK_DEMO_BUILD_DIR:-$root/build-demo}"
bash "$root/scripts/install-deps.sh" --demo
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHK_BUILD_TESTS=OFF -DHK_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" -j "$(nproc)" --target haptic-kiosk
mkdir -p "$out"
"$build/app/haptic-kiosk" explore "$image" --out "$out" --audio-out "$out/earcons.wav"
echo "demo: open $out/overlay.png and play $out/earcons.wav; trace.csv, cues.csv, scene.json and summary.json are beside them"
