#!/usr/bin/env bash
# Function lengths of the product code (common, config, haptics, vision, audio-cues, app), read by
# Universal Ctags (package universal-ctags; lambdas count in the function around them): a histogram, then every function over the limit, longest first.
# Usage: scripts/function-lengths.sh [LIMIT_LINES=80]. Exits 1 when a function is over the limit.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
limit="${1:-80}"
cd "$root"
ctags -R --languages=C++ --kinds-C++=f --fields=+ne -o - common config haptics vision audio-cues app |
  awk -F'\t' -v limit="$limit" '
    { line = ""; end = ""
      for (i = 4; i <= NF; ++i) { if ($i ~ /^line:/) line = substr($i, 6); if ($i ~ /^end:/) end = substr($i, 5) }
      if (line == "" || end == "" || $1 ~ /^__anon/) next
      n = end - line + 1; total++
      if (n <= 20) b[1]++; else if (n <= 40) b[2]++; else if (n <= 60) b[3]++; else if (n <= limit) b[4]++; else b[5]++
      if (n > limit) over[$2 ":" line " " $1] = n }
    END {
      printf "functions: %d\n  1-20 lines: %d\n  21-40: %d\n  41-60: %d\n  61-%d: %d\n  over %d: %d\n", total, b[1], b[2], b[3], limit, b[4], limit, b[5]
      for (k in over) printf "%6d  %s\n", over[k], k | "sort -rn"
      close("sort -rn")
      exit (b[5] > 0) }'
