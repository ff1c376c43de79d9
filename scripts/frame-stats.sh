#!/usr/bin/env bash
# The kiosk window's frame times while pictures change: runs haptic-kiosk under Xvfb (1920 x 1080, full
# screen) on a picture library, starting on its first picture, and presses Next (the [keys] next default,
# RIGHT, through the same routing as a real key) many times quickly, then writes and prints the
# --frame-stats JSON (app/kiosk/include/kiosk/frame_stats.hpp says what "interval" and "work" are).
# Usage: scripts/frame-stats.sh [LIBRARY] [OUT_JSON]
#   LIBRARY   picture folder (default data/pictures)
#   OUT_JSON  where the JSON goes (default out/frame-stats.json)
# Environment: HK_KIOSK (the executable; default build/app/haptic-kiosk), HK_PRESSES (Next presses, default
# 100), HK_EVERY (frames between presses, at least 2: a press is released the frame after; default 6, i.e.
# 10 presses per second of kiosk time), HK_NEXT_KEY (default RIGHT). Sound goes to ALSA's null device.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
library="$(realpath "${1:-$root/data/pictures}")"
out="$(realpath -m "${2:-$root/out/frame-stats.json}")"
exe="${HK_KIOSK:-$root/build/app/haptic-kiosk}"
presses="${HK_PRESSES:-100}"
every="${HK_EVERY:-6}"
key="${HK_NEXT_KEY:-RIGHT}"
[[ -x "$exe" ]] || { echo "frame-stats: no kiosk at $exe (build the haptic-kiosk target, or set HK_KIOSK)" >&2; exit 1; }
[[ -d "$library" ]] || { echo "frame-stats: no folder $library" >&2; exit 1; }
(( every >= 2 )) || { echo "frame-stats: HK_EVERY must be at least 2" >&2; exit 1; }
command -v xvfb-run >/dev/null || { echo "frame-stats: xvfb-run is not installed (scripts/install-deps.sh)" >&2; exit 1; }
first="$(find "$library" -maxdepth 1 -type f \( -iname '*.png' -o -iname '*.jpg' -o -iname '*.jpeg' -o -iname '*.bmp' \
         -o -iname '*.tif' -o -iname '*.tiff' -o -iname '*.webp' \) | LC_ALL=C sort | head -n 1)"
[[ -n "$first" ]] || { echo "frame-stats: no pictures in $library" >&2; exit 1; }
mkdir -p "$(dirname "$out")"

tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/home"
printf 'pcm.!default { type null }\nctl.!default { type hw card 0 }\n' >"$tmp/home/.asoundrc"
start=60  # one second on the first picture before the first press
for ((i = 0; i < presses; ++i)); do echo "$((start + i * every)) press $key"; done >"$tmp/script.txt"
frames=$((start + presses * every + 120))  # two seconds after the last press for its scene to come

echo "frame-stats: $presses x $key every $every frames over $library (starting on $(basename "$first")), $frames frames" >&2
if ! HOME="$tmp/home" timeout 900 xvfb-run -a -s "-screen 0 1920x1080x24" "$exe" --no-hotplug --library "$library" \
     --show "$first" --script "$tmp/script.txt" --screenshot "$tmp/last.png" --frames "$frames" \
     --frame-stats "$out" >"$tmp/log.txt" 2>&1; then
  tail -n 40 "$tmp/log.txt" >&2
  echo "frame-stats: the kiosk failed" >&2
  exit 1
fi
grep -o 'frame stats: .*' "$tmp/log.txt" >&2 || true
cat "$out"
