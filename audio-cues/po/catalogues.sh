#!/usr/bin/env bash
# The message catalogues' build step and check (GNU gettext's own tools), for each gettext domain:
#   catalogues.sh pot   DOMAIN POT SOURCE...           write the template POT from the English sources (xgettext)
#   catalogues.sh build DOMAIN PO_DIR OUT SOURCE...    check and compile every PO_DIR/*.po into
#                                                      OUT/LANG/LC_MESSAGES/DOMAIN.mo
# The domains:
#   haptic-kiosk        what visitors hear: NC_(key, text) and NPC_(key, one, many) in audio-cues/src/messages_en.cpp,
#                       every entry a {placeholder} template (python-brace-format)
#   haptic-kiosk-panel  the operator's panel: tr("…") in app/kiosk/src/operator_panel.cpp, tr("…") and
#                       trn("one", "many", n) in app/visit/src/operator_session.cpp, N_("…") and each settings
#                       field's help (HK_FIELD's 8th argument, HK_FIELD_IN's 9th) in config/src/fields.cpp, N_("…")
#                       (device names) in config/src/device_profile.cpp
# build fails, naming the file, when the committed PO_DIR/DOMAIN.pot is not what the English sources make, when a
# catalogue lacks a message of the template or leaves one untranslated or fuzzy (msgcmp), or when a translation's
# placeholders ({name}, or printf's %s) differ from the English text's (msgfmt --check).
set -euo pipefail

make_pot() {  # DOMAIN OUT SOURCE...
  local domain=$1 out=$2
  shift 2
  local keywords
  case "$domain" in
    haptic-kiosk) keywords=(--keyword=NC_:1c,2 --keyword=NPC_:1c,2,3) ;;
    haptic-kiosk-panel) keywords=(--keyword=tr --keyword=trn:1,2 --keyword=N_ --keyword=HK_FIELD:8 --keyword=HK_FIELD_IN:9) ;;
    *)
      echo "catalogues: unknown domain '$domain'" >&2
      exit 2
      ;;
  esac
  xgettext --language=C++ --from-code=UTF-8 --keyword= "${keywords[@]}" \
    --add-comments=TRANSLATORS: --no-location --package-name="$domain" \
    --msgid-bugs-address="maintainers@users.noreply.h-seed-44a4b0a8.example" -o "$out.tmp" "$@"
  if [ "$domain" = haptic-kiosk ]; then
    # Every message is a brace-format template: msgfmt --check then holds its translation to its placeholders.
    sed -e 's/^msgctxt /#, python-brace-format\nmsgctxt /' -e '/^"POT-Creation-Date: /d' "$out.tmp" > "$out"
  else
    sed -e '/^"POT-Creation-Date: /d' "$out.tmp" > "$out"
  fi
  rm -f "$out.tmp"
}

case "${1:-}" in
  pot)
    make_pot "$2" "$3" "${@:4}"
    ;;
  build)
    domain=$2 po_dir=$3 out=$4
    mkdir -p "$out"
    make_pot "$domain" "$out/$domain.pot" "${@:5}"
    if ! cmp -s "$out/$domain.pot" "$po_dir/$domain.pot"; then
      echo "catalogues: $po_dir/$domain.pot is not what the English sources make; run" >&2
      echo "  bash audio-cues/po/catalogues.sh pot $domain $po_dir/$domain.pot ${*:5}" >&2
      echo "then msgmerge each $po_dir/LANG.po and translate what is new" >&2
      diff "$po_dir/$domain.pot" "$out/$domain.pot" | head -20 >&2 || true
      exit 1
    fi
    for po in "$po_dir"/*.po; do
      lang=$(basename "$po" .po)
      # msgcmp: every message of the template is in the catalogue, translated and not fuzzy.
      if ! msgcmp "$po" "$out/$domain.pot" 2> "$out/$domain.$lang.msgcmp"; then
        echo "catalogues: $po lacks messages of $domain.pot (or leaves them untranslated or fuzzy):" >&2
        head -5 "$out/$domain.$lang.msgcmp" >&2
        exit 1
      fi
      mkdir -p "$out/$lang/LC_MESSAGES"
      if ! msgfmt --check -o "$out/$lang/LC_MESSAGES/$domain.mo" "$po" 2> "$out/$domain.$lang.msgfmt"; then
        echo "catalogues: $po does not compile:" >&2
        grep -v "warning:" "$out/$domain.$lang.msgfmt" | head -5 >&2
        exit 1
      fi
    done
    ;;
  *)
    echo "usage: catalogues.sh pot DOMAIN POT SOURCE... | build DOMAIN PO_DIR OUT SOURCE..." >&2
    exit 2
    ;;
esac
