#!/usr/bin/env bash
# The message catalogues' build step and check (GNU gettext's own tools):
#   catalogues.sh pot  SOURCE POT            write the template POT from the English source (xgettext)
#   catalogues.sh build SOURCE PO_DIR OUT    check and compile every PO_DIR/*.po into OUT/LANG/LC_MESSAGES/haptic-kiosk.mo
# build fails, naming the file, when the committed PO_DIR/haptic-kiosk.pot is not what the English source makes,
# when a catalogue lacks a message of the template or leaves one untranslated or fuzzy (msgcmp), or when a
# translation's {placeholders} differ from the English text's (msgfmt --check: every entry is python-brace-format).
set -euo pipefail
domain=haptic-kiosk

make_pot() {  # SOURCE OUT
  xgettext --language=C++ --from-code=UTF-8 --keyword= --keyword=NC_:1c,2 --keyword=NPC_:1c,2,3 \
    --add-comments=TRANSLATORS: --no-location --package-name="$domain" \
    --msgid-bugs-address="maintainers@users.noreply.h-seed-44a4b0a8.example" -o "$2.tmp" "$1"
  # Every message is a brace-format template: msgfmt --check then holds its translation to its placeholders.
  sed -e 's/^msgctxt /#, python-brace-format\nmsgctxt /' -e '/^"POT-Creation-Date: /d' "$2.tmp" > "$2"
  rm -f "$2.tmp"
}

case "${1:-}" in
  pot)
    make_pot "$2" "$3"
    ;;
  build)
    source=$2 po_dir=$3 out=$4
    mkdir -p "$out"
    make_pot "$source" "$out/$domain.pot"
    if ! cmp -s "$out/$domain.pot" "$po_dir/$domain.pot"; then
      echo "catalogues: $po_dir/$domain.pot is not what $source makes; run scripts/update-po.sh" >&2
      diff "$po_dir/$domain.pot" "$out/$domain.pot" | head -20 >&2 || true
      exit 1
    fi
    for po in "$po_dir"/*.po; do
      lang=$(basename "$po" .po)
      # msgcmp: every message of the template is in the catalogue, translated and not fuzzy.
      if ! msgcmp "$po" "$out/$domain.pot" 2> "$out/$lang.msgcmp"; then
        echo "catalogues: $po lacks messages of $domain.pot (or leaves them untranslated or fuzzy):" >&2
        head -5 "$out/$lang.msgcmp" >&2
        exit 1
      fi
      mkdir -p "$out/$lang/LC_MESSAGES"
      if ! msgfmt --check -o "$out/$lang/LC_MESSAGES/$domain.mo" "$po" 2> "$out/$lang.msgfmt"; then
        echo "catalogues: $po does not compile:" >&2
        grep -v "warning:" "$out/$lang.msgfmt" | head -5 >&2
        exit 1
      fi
    done
    ;;
  *)
    echo "usage: catalogues.sh pot SOURCE POT | build SOURCE PO_DIR OUT" >&2
    exit 2
    ;;
esac
