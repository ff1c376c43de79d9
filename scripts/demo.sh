#!/usr/bin/env bash
# Fresh machine → explore a shipped picture: installs packages, builds, runs the headless pipeline.
# Usage: scripts/demo.sh [IMAGE] [OUT_DIR]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
image="${1:-$root/tests/data/images/horse.png}"
out="${2:-$root/out/demo}"
bash "$root/scripts/install-deps.sh"
bash "$root/scripts/build.sh" "$root/build"
mkdir -p "$out"
"$root/build/app/haptic-kiosk" explore "$image" --out "$out" --audio-out "$out/earcons.wav"
echo "demo: open $out/overlay.png and play $out/earcons.wav; trace.csv, cues.csv, scene.json and summary.json are beside them"
