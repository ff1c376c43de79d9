#!/usr/bin/env bash
# Fresh machine → explore a shipped picture: installs packages, builds, runs the headless pipeline.
# Usage: scripts/demo.sh [IMAGE] [OUT_DIR]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
image="${1:-$root/tests/data/images/horse.png}"
out="${2:-$root/out/demo}"
bash "$root/scripts/install-deps.sh"
bash "$root/scripts/build.sh" "$root/build"
"$root/build/app/haptic-kiosk" explore "$image" --out "$out"
echo "demo: open $out/overlay.png; trace.csv, scene.json and summary.json are beside it"
