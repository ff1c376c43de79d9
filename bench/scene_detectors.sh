#!/usr/bin/env bash
# The scene of every picture of tests/data/images and of two generated textures (bench_detectors
# --write-textures: fine noise, wood grain), with the old pipeline and the defaults, and with each edge detector.
#  - Before → after: the old pipeline ([vision] detector = "canny", gap_close_m = 0, max_shapes = 1000: no
#    shape budget) against the defaults (two-tone pictures traced, line drawings by Canny, the rest by
#    "surround": texture dropped; gaps closed; 30 shapes): the detector used, shapes (curves kept), closed share,
#    level-0 segments in use, gaps closed and build time [ms] (the sum of summary.json build_ms).
#  - Detectors: each of canny, surround, bilateral, edpf on every picture with the other defaults: shapes,
#    closed share, edges dropped as texture, edge + linking time [ms] (summary.json build_ms, first call in the
#    process; steady-state times per detector are bench_detectors').
# Writes OUT/scene_detectors.csv, OUT/detectors.csv and OUT/contact_sheet.png (every picture's overlay, before
# | after: bench/contact_sheet.py), and prints both tables.
# Usage: bench/scene_detectors.sh [BUILD_DIR] [OUT_DIR]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build}"
out="${2:-$root/docs/bench}"
exe="$build/app/haptic-kiosk"
[ -x "$exe" ] || { echo "scene_detectors.sh: $exe not built" >&2; exit 1; }
[ -x "$build/bench/bench_detectors" ] || { echo "scene_detectors.sh: $build/bench/bench_detectors not built" >&2; exit 1; }
mkdir -p "$out"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/pictures"
cp "$root"/tests/data/images/* "$work/pictures/"
"$build/bench/bench_detectors" --write-textures "$work/pictures"
printf '[vision]\ndetector = "canny"\ngap_close_m = 0\nmax_shapes = 1000\n' > "$work/canny.toml"
for det in canny surround bilateral edpf; do printf '[vision]\ndetector = "%s"\n' "$det" > "$work/det_$det.toml"; done
for img in "$work"/pictures/*; do
  name="$(basename "$img")"
  "$exe" explore "$img" --out "$work/canny/$name" --duration 0.05 --config "$work/canny.toml" > /dev/null 2>&1
  "$exe" explore "$img" --out "$work/auto/$name" --duration 0.05 > /dev/null 2>&1
  for det in canny surround bilateral edpf; do
    "$exe" explore "$img" --out "$work/det_$det/$name" --duration 0.05 --config "$work/det_$det.toml" > /dev/null 2>&1
  done
done
/usr/bin/python3 "$root/bench/contact_sheet.py" "$work" "$out/contact_sheet.png" >&2
/usr/bin/python3 - "$work" "$out/scene_detectors.csv" "$out/detectors.csv" <<'PY'
import csv, json, os, sys
work, path, det_path = sys.argv[1], sys.argv[2], sys.argv[3]
detectors = ("canny", "surround", "bilateral", "edpf")

def load(mode, name):
    d = json.load(open(os.path.join(work, mode, name, "summary.json")))
    curves = json.load(open(os.path.join(work, mode, name, "scene.json")))["curves"]
    return d, curves

rows, det_rows = [], []
for name in sorted(os.listdir(os.path.join(work, "auto"))):
    row = {"picture": name}
    for mode in ("canny", "auto"):
        d, curves = load(mode, name)
        row[mode + "_detector"] = d["detector"]
        row[mode + "_shapes"] = len(curves)
        row[mode + "_closed"] = round(sum(c["closed"] for c in curves) / max(len(curves), 1), 2)
        row[mode + "_segments"] = d["segments_in_use"]
        row[mode + "_gaps_closed"] = d["chains"]["gaps_closed"]
        row[mode + "_build_ms"] = round(sum(d["build_ms"].values()), 1)
    rows.append(row)
    drow = {"picture": name}
    for det in detectors:
        d, curves = load("det_" + det, name)
        drow[det + "_used"] = d["detector"]
        drow[det + "_shapes"] = len(curves)
        drow[det + "_closed"] = round(sum(c["closed"] for c in curves) / max(len(curves), 1), 2)
        drow[det + "_texture"] = d["chains"]["texture"]
        drow[det + "_edges_ms"] = round(d["build_ms"]["edges"] + d["build_ms"]["linking"], 1)
    det_rows.append(drow)
for p, rs in ((path, rows), (det_path, det_rows)):
    with open(p, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rs[0].keys()))
        w.writeheader()
        w.writerows(rs)
print("| picture | detector | shapes | closed | segments | gaps closed | build ms |")
print("|---|---|---|---|---|---|---|")
for r in rows:
    print(f"| {r['picture']} | {r['auto_detector']} | {r['canny_shapes']} → {r['auto_shapes']} | {r['canny_closed']:.2f} → {r['auto_closed']:.2f} "
          f"| {r['canny_segments']} → {r['auto_segments']} | {r['auto_gaps_closed']} | {r['canny_build_ms']} → {r['auto_build_ms']} |")
print()
print("| picture | " + " | ".join(detectors) + " |")
print("|---|" + "---|" * len(detectors))
for r in det_rows:
    cells = []
    for det in detectors:
        used = "" if r[det + "_used"] == det else f" ({r[det + '_used']})"
        tex = f", {r[det + '_texture']} texture" if r[det + "_texture"] else ""
        cells.append(f"{r[det + '_shapes']} / {r[det + '_closed']:.2f}{tex}, {r[det + '_edges_ms']} ms{used}")
    print(f"| {r['picture']} | " + " | ".join(cells) + " |")
PY
