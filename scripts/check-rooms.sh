#!/usr/bin/env bash
# Checks that app/'s rooms depend one way (docs/DESIGN.md "The rooms of app/"): a file of a room includes
# app headers only by room ("visit/describe.hpp") and only of itself or the rooms it may use. Prints each
# include that points back or sideways, or names a neighbour by bare name, and fails if there is one.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
# room: the rooms it may include (besides itself)
declare -A allowed=(
  [formats]=""
  [sticks]=""
  [meaning]="formats"
  [pictures]="formats sticks meaning"
  [copies]="formats sticks meaning pictures"
  [runtime]="formats"
  [visit]="formats sticks meaning pictures copies runtime"
  [cli]="formats sticks meaning pictures copies runtime visit"
  [kiosk]="formats sticks meaning pictures copies runtime visit cli"
)
rooms="formats sticks meaning pictures copies runtime visit cli kiosk"
bad=0
for room in $rooms; do
  while IFS= read -r -d '' file; do
    while IFS= read -r line; do
      target="$(sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/\1/p' <<<"$line")"
      [ -n "$target" ] || continue
      rel="${file#"$root"/}"
      if [[ "$target" != */* ]]; then
        echo "check-rooms: $rel includes \"$target\" by bare name; include it by room (\"room/$target\")"
        bad=1
        continue
      fi
      other="${target%%/*}"
      [[ " $rooms " == *" $other "* ]] || continue  # a module's header (haptics/, vision/, ...)
      [ "$other" = "$room" ] && continue
      if [[ " ${allowed[$room]} " != *" $other "* ]]; then
        echo "check-rooms: $rel (room $room) includes \"$target\": $room may use only {${allowed[$room]}}"
        bad=1
      fi
    done < <(grep -E '^[[:space:]]*#[[:space:]]*include[[:space:]]*"' "$file" || true)
  done < <(find "$root/app/$room" -name '*.[ch]pp' -print0)
done
if [ "$bad" -ne 0 ]; then
  echo "check-rooms: includes point back between app/'s rooms (see above)" >&2
  exit 1
fi
echo "check-rooms: app/'s rooms depend one way ($rooms)"
