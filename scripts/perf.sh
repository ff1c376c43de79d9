#!/usr/bin/env bash
# Explores every test image with the default settings and prints the per-stage build times and the
# servo tick times as the Markdown table of docs/PERFORMANCE.md. Usage: scripts/perf.sh [OUT_DIR]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-$root/out/perf}"
command -v python3 >/dev/null || { apt-get update -qq && apt-get install -y -qq python3-minimal >/dev/null; }
bash "$root/scripts/install-deps.sh"
bash "$root/scripts/build.sh" "$root/build" >/dev/null
for img in "$root"/tests/data/images/*.{png,jpg}; do
  name="$(basename "${img%.*}")"
  "$root/build/app/haptic-kiosk" explore "$img" --out "$out/$name" >/dev/null 2>&1
done
python3 - "$out" <<'PY'
import json, os, sys
out = sys.argv[1]
print("| image | px | curves | segments (level in use) | load ms | edges ms | linking ms | multires ms | tree ms | tick p50 ns | tick p99 ns | tick p99.9 ns | tick max ns | box tests / tick | contact ticks |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
for name in sorted(os.listdir(out)):
    try:
        s = json.load(open(os.path.join(out, name, "summary.json")))
        sc = json.load(open(os.path.join(out, name, "scene.json")))
    except FileNotFoundError:
        continue
    b, t, c = s["build_ms"], s["tick_ns"], s["contact_ticks"]
    px = f'{sc["image"]["width_px"]}x{sc["image"]["height_px"]}'
    print(f'| {name} | {px} | {s["curves"]} | {s["segments_in_use"]} | {b["load"]:.1f} | {b["edges"]:.1f} | {b["linking"]:.1f} | '
          f'{b["multires"]:.2f} | {b["tree"]:.2f} | {t["p50"]:.0f} | {t["p99"]:.0f} | {t["p999"]:.0f} | {t["max"]:.0f} | '
          f'{s["per_tick"]["box_tests_mean"]:.0f} | {c["edge"] + c["vertex"]} / {s["ticks"]} |')
PY
