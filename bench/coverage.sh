#!/usr/bin/env bash
# Coverage per picture: how much of the curves' length (summary.json coverage.length_fraction, the
# level-0 length within 1 mm of the proxy's path) three model hands reach on every picture of tests/data/images:
#   raster            --hand raster (its natural duration: one boustrophedon, ~27 s)
#   explorer          --hand explorer --duration 120 (seed 1)
#   explorer_grooves  the same with [haptics] render = "grooves"
# Writes OUT/coverage.csv (picture,raster,explorer,explorer_grooves,explorer_wall_s), then OUT/coverage.png and
# the table of docs/PERFORMANCE.md between its coverage markers (bench/plot_coverage.py).
# Usage: bench/coverage.sh [BUILD_DIR] [OUT_DIR]    (two runs at a time)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build}"
out="${2:-$root/docs/bench}"
exe="$build/app/haptic-kiosk"
[ -x "$exe" ] || { echo "coverage.sh: $exe not built" >&2; exit 1; }
mkdir -p "$out"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
printf '[haptics]\nrender = "grooves"\n' > "$work/grooves.toml"

run_one() {  # picture kind -> prints "kind picture fraction wall_seconds"
  local img="$1" kind="$2" name; name="$(basename "$img")"
  local dir="$work/$kind/${name%.*}"; mkdir -p "$dir"
  local args=(explore "$img" --out "$dir")
  case "$kind" in
    raster) args+=(--hand raster) ;;
    explorer) args+=(--hand explorer --duration 120) ;;
    explorer_grooves) args+=(--hand explorer --duration 120 --config "$work/grooves.toml") ;;
  esac
  local t0 t1; t0=$(date +%s.%N)
  "$exe" "${args[@]}" >/dev/null
  t1=$(date +%s.%N)
  local f; f=$(/usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['coverage']['length_fraction'])" "$dir/summary.json")
  echo "$kind $name $f $(echo "$t1 - $t0" | bc)"
  rm -f "$dir/trace.csv"
}
export -f run_one
export exe work

kinds="raster explorer explorer_grooves"
for img in "$root"/tests/data/images/*.png "$root"/tests/data/images/*.jpg; do
  for k in $kinds; do echo "$img $k"; done
done | xargs -P 2 -L 1 bash -c 'run_one "$0" "$1"' > "$work/results.txt"

/usr/bin/python3 - "$work/results.txt" "$out/coverage.csv" <<'PY'
import sys
rows = {}
for line in open(sys.argv[1]):
    kind, name, frac, wall = line.split()
    r = rows.setdefault(name, {})
    r[kind] = float(frac)
    if kind == "explorer":
        r["wall"] = float(wall)
with open(sys.argv[2], "w") as f:
    f.write("picture,raster,explorer,explorer_grooves,explorer_wall_s\n")
    for name in sorted(rows):
        r = rows[name]
        g = f"{r['explorer_grooves']:.4f}" if "explorer_grooves" in r else ""
        f.write(f"{name},{r.get('raster', 0):.4f},{r.get('explorer', 0):.4f},{g},{r.get('wall', 0):.1f}\n")
PY
/usr/bin/python3 "$root/bench/plot_coverage.py" "$out/coverage.csv" --outdir "$out" --doc "$root/docs/PERFORMANCE.md"
echo "coverage: $out/coverage.csv, $out/coverage.png"
