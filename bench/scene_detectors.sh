#!/usr/bin/env bash
# The scene of every picture of tests/data/images, before and after issue 15 (a two-tone picture traced from a
# threshold instead of found by Canny; chain ends across gaps up to gap_close_m joined): per picture, for the
# old pipeline ([vision] detector = "canny", gap_close_m = 0, max_shapes = 1000: no shape budget) and the defaults: the detector used, shapes
# (curves kept), closed share, level-0 segments in use, gaps closed and build time [ms] (the sum of
# summary.json build_ms).
# Writes OUT/scene_detectors.csv and OUT/contact_sheet.png (every picture's overlay, before | after:
# bench/contact_sheet.py), and prints the table.
# Usage: bench/scene_detectors.sh [BUILD_DIR] [OUT_DIR]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build}"
out="${2:-$root/docs/bench}"
exe="$build/app/haptic-kiosk"
[ -x "$exe" ] || { echo "scene_detectors.sh: $exe not built" >&2; exit 1; }
mkdir -p "$out"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
printf '[vision]\ndetector = "canny"\ngap_close_m = 0\nmax_shapes = 1000\n' > "$work/canny.toml"
for img in "$root"/tests/data/images/*; do
  name="$(basename "$img")"
  "$exe" explore "$img" --out "$work/canny/$name" --duration 0.05 --config "$work/canny.toml" > /dev/null
  "$exe" explore "$img" --out "$work/auto/$name" --duration 0.05 > /dev/null
done
/usr/bin/python3 "$root/bench/contact_sheet.py" "$work" "$out/contact_sheet.png" >&2
/usr/bin/python3 - "$work" "$out/scene_detectors.csv" <<'PY'
import csv, json, os, sys
work, path = sys.argv[1], sys.argv[2]
rows = []
for name in sorted(os.listdir(os.path.join(work, "auto"))):
    row = {"picture": name}
    for mode in ("canny", "auto"):
        d = json.load(open(os.path.join(work, mode, name, "summary.json")))
        curves = json.load(open(os.path.join(work, mode, name, "scene.json")))["curves"]
        row[mode + "_detector"] = d["detector"]
        row[mode + "_shapes"] = len(curves)
        row[mode + "_closed"] = round(sum(c["closed"] for c in curves) / max(len(curves), 1), 2)
        row[mode + "_segments"] = d["segments_in_use"]
        row[mode + "_gaps_closed"] = d["chains"]["gaps_closed"]
        row[mode + "_build_ms"] = round(sum(d["build_ms"].values()), 1)
    rows.append(row)
with open(path, "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
    w.writeheader()
    w.writerows(rows)
print("| picture | detector | shapes | closed | segments | gaps closed | build ms |")
print("|---|---|---|---|---|---|---|")
for r in rows:
    print(f"| {r['picture']} | {r['auto_detector']} | {r['canny_shapes']} → {r['auto_shapes']} | {r['canny_closed']:.2f} → {r['auto_closed']:.2f} "
          f"| {r['canny_segments']} → {r['auto_segments']} | {r['auto_gaps_closed']} | {r['canny_build_ms']} → {r['auto_build_ms']} |")
PY
