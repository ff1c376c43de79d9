#!/usr/bin/env bash
# Assembles the seed corpora and dictionaries of the fuzz harnesses from tests/data and fuzz/seeds, at run
# time, so that no big file is copied into fuzz/:
#   fuzz/make_corpus.sh DEST [harness ...]      (default: every harness)
# writes DEST/corpus/<harness>/ (one file per seed) and DEST/dicts/<harness>.dict. scripts/fuzz.sh calls it
# with a temporary DEST; DEST must not be inside the repository's tracked folders.
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
[ $# -ge 1 ] || { echo "usage: $0 DEST [harness ...]" >&2; exit 2; }
dest=$1
shift
all=(image pdf config messages hand_csv hapi_reply stick_name ocr annotations)
[ $# -gt 0 ] && harnesses=("$@") || harnesses=("${all[@]}")
data=$repo/tests/data
seeds=$repo/fuzz/seeds
dicts=$repo/fuzz/dicts

# copy_seeds HARNESS MAX_BYTES FILE...: the files of at most MAX_BYTES bytes (libFuzzer would cut longer
# ones at -max_len, which only makes broken copies of them); missing globs are skipped.
copy_seeds() {
  local h=$1 max=$2 f
  shift 2
  mkdir -p "$dest/corpus/$h"
  for f in "$@"; do
    [ -f "$f" ] || continue
    [ "$(stat -c %s "$f")" -le "$max" ] || continue
    cp "$f" "$dest/corpus/$h/$(basename "$(dirname "$f")")_$(basename "$f")"
  done
}

# toml_keys FILE...: a dictionary entry for every [table] and every key = in the files.
toml_keys() {
  grep -hoE '^\[[a-z_0-9]+\]|^[a-zA-Z_0-9]+ =' "$@" | sed -e 's/ =$//' | sort -u | sed -e 's/.*/"&"/'
}

mkdir -p "$dest/dicts"
for h in "${harnesses[@]}"; do
  case $h in
    image)
      copy_seeds image 65536 "$seeds"/image/* "$data"/images/* "$data"/camera/still/* "$data"/bad/*.png "$data"/bad/*.jpg
      cp "$dicts/image.dict" "$dest/dicts/image.dict" ;;
    pdf)
      copy_seeds pdf 65536 "$seeds"/pdf/* "$data"/documents/*.pdf "$data"/bad/*.pdf
      cp "$dicts/pdf.dict" "$dest/dicts/pdf.dict" ;;
    config)
      copy_seeds config 65536 "$seeds"/config/* "$data"/config/*.toml "$data"/bad/config_*.toml
      { cat "$dicts/toml.dict"; toml_keys "$data"/config/*.toml; } > "$dest/dicts/config.dict" ;;
    messages)
      # The catalogues compiled from audio-cues/po (msgfmt: gettext is a build dependency) and the hand-made seed.
      mkdir -p "$dest/mo"
      for po in "$repo"/audio-cues/po/*.po; do msgfmt -o "$dest/mo/$(basename "$po" .po).mo" "$po"; done
      copy_seeds messages 131072 "$seeds"/messages/* "$dest"/mo/*.mo
      { printf '%s\n' '"\x95\x04\x12\xde"' '"\xde\x12\x04\x95"' '"Plural-Forms: nplurals=2; plural=(n > 1);"'
        grep -hoE 'NP?C_\("[a-z_.A-Z0-9]+"' "$repo"/audio-cues/src/messages_en.cpp | sed -e 's/^NP*C_(//'
        grep -hoE '\{[a-z_]+\}' "$repo"/audio-cues/src/messages_en.cpp | sort -u | sed -e 's/.*/"&"/'; } > "$dest/dicts/messages.dict" ;;
    hand_csv)
      copy_seeds hand_csv 65536 "$seeds"/hand_csv/* "$data"/bad/hand_*.csv
      cp "$dicts/csv.dict" "$dest/dicts/hand_csv.dict" ;;
    hapi_reply)
      copy_seeds hapi_reply 4096 "$seeds"/hapi_reply/*
      cp "$dicts/hapi.dict" "$dest/dicts/hapi_reply.dict" ;;
    stick_name)
      copy_seeds stick_name 4096 "$seeds"/stick_name/*
      # The test data's own paths, as a stick would list them.
      (cd "$data" && find . -type f | sed -e 's|^\./||' | head -200) | {
        i=0
        while IFS= read -r p; do i=$((i + 1)); printf '%s' "$p" > "$dest/corpus/stick_name/path_$i"; done
      }
      cp "$dicts/name.dict" "$dest/dicts/stick_name.dict" ;;
    ocr)
      copy_seeds ocr 16384 "$seeds"/ocr/*
      cp "$dicts/ocr.dict" "$dest/dicts/ocr.dict" ;;
    annotations)
      copy_seeds annotations 16384 "$data"/annotations/*.json "$data"/bad/annotations_*.json
      cp "$dicts/annotations.dict" "$dest/dicts/annotations.dict" ;;
    *)
      echo "make_corpus: unknown harness '$h' (known: ${all[*]})" >&2
      exit 2 ;;
  esac
  # Inputs that once crashed a harness (the GoogleTest regression tests feed them too). Not for pdf: the ones
  # kept there are inputs poppler is slow on, which would only slow the fuzzer down.
  [ "$h" = pdf ] || copy_seeds "$h" 1048576 "$data/fuzz/$h"/*
done
