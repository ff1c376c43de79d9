#!/usr/bin/env bash
# Checks a built Debian package (scripts/package.sh): lintian finds no error (warnings are shown; the
# overrides, each with its reason, are packaging/lintian-overrides), its file list is
# packaging/expected-files.txt exactly (a diff is shown otherwise; after a deliberate change, regenerate it
# with HK_UPDATE_EXPECTED_FILES=1), and systemd-analyze verify accepts the unit it ships.
# Usage: scripts/check-package.sh dist/haptic-kiosk_<version>_amd64.deb
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
if [ $# -ne 1 ]; then
  echo "usage: scripts/check-package.sh dist/haptic-kiosk_<version>_amd64.deb" >&2
  exit 2
fi
deb="$1"
if [ ! -f "$deb" ]; then
  echo "check-package: '$deb': no such file" >&2
  exit 2
fi
for tool in lintian dpkg-deb systemd-analyze; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "check-package: $tool is not installed (bash scripts/install-deps.sh installs it)" >&2
    exit 2
  fi
done
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
failed=()

# 1. lintian: errors fail; warnings and overrides are listed.
echo "check-package: lintian $deb"
if ! lintian --fail-on error --show-overrides "$deb"; then
  failed+=("lintian found errors")
fi

# 2. The file list, against the one kept in the repository.
expected="$root/packaging/expected-files.txt"
dpkg-deb --fsys-tarfile "$deb" | tar -t | sed -e 's#^\./#/#' -e 's#/$##' | grep -v '^$' | LC_ALL=C sort > "$tmp/files.txt"
if [ "${HK_UPDATE_EXPECTED_FILES:-}" = 1 ]; then
  cp "$tmp/files.txt" "$expected"
  echo "check-package: wrote $expected"
fi
if diff -u --label "packaging/expected-files.txt" --label "$(basename "$deb")" "$expected" "$tmp/files.txt"; then
  echo "check-package: file list as expected ($(wc -l < "$tmp/files.txt") entries)"
else
  failed+=("the file list differs from packaging/expected-files.txt (diff above)")
fi

# 2b. The data and voices of every language offered: Tesseract's per language, CMU Flite's English voices.
depends="$(dpkg-deb -f "$deb" Depends)"
for p in tesseract-ocr-eng tesseract-ocr-fra tesseract-ocr-deu tesseract-ocr-spa libflite1; do
  if ! grep -qE "(^|, )$p( |,|$)" <<<"$depends"; then
    failed+=("Depends lacks $p (Depends: $depends)")
  fi
done

# 3. The unit, as extracted from the package. systemd-analyze verify needs no running systemd (it loads
# the unit offline) but wants ExecStart's program, /usr/bin/cage, to exist on this machine (install-deps
# installs it); man pages are not looked up (the package's own is not installed here).
dpkg-deb -x "$deb" "$tmp/root"
unit="$tmp/root/lib/systemd/system/haptic-kiosk.service"
if [ ! -f "$unit" ]; then
  failed+=("no /lib/systemd/system/haptic-kiosk.service in the package")
elif ! command -v cage >/dev/null 2>&1; then
  failed+=("cage is not installed, so the unit cannot be verified (bash scripts/install-deps.sh)")
else
  echo "check-package: systemd-analyze verify haptic-kiosk.service"
  if ! SYSTEMD_LOG_LEVEL=warning systemd-analyze verify --man=no "$unit" 2>&1 | tee "$tmp/verify.txt"; then
    failed+=("systemd-analyze verify failed")
  elif grep -q "haptic-kiosk.service" "$tmp/verify.txt"; then
    failed+=("systemd-analyze verify complained about haptic-kiosk.service (above)")
  fi
fi

if [ ${#failed[@]} -gt 0 ]; then
  for f in "${failed[@]}"; do echo "check-package: FAILED: $f" >&2; done
  exit 1
fi
echo "check-package: $(basename "$deb") passed"
