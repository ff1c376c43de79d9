#!/usr/bin/env bash
# The roll-out for real, outside CI (minutes of debootstrap and apt): two Debian 12 machines' root file systems,
# each a kiosk of an inventory with a gallery of its own, reached by Ansible's chroot connection; the package
# served from a signed reprepro repository made here (a throwaway key), over HTTP on localhost. Then:
#   1. the playbook runs: it installs and configures both (package, fleet.toml, the PIN's hash, the library);
#   2. it runs again: no change on either;
#   3. a library with a broken picture: refused by `library check` before anything is copied (the kiosks'
#      libraries byte for byte as they were).
# The base root file system is made once and kept outside the clone ($HK_FLEET_DIR, default /var/tmp/hk-fleet);
# the two machines are fresh copies of it each run. Needs root (debootstrap, chroot, mounts), debootstrap,
# reprepro, gnupg, ansible, and python3 for the HTTP server. systemd-nspawn would boot the machines, but a
# sandbox without systemd as PID 1 cannot host that; the kiosk is not started (no restart: haptic_kiosk_restart).
# Usage: scripts/fleet-check.sh DEB KIOSK_EXE   (its summary goes to standard output; docs/FLEET.md has one)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
if [ $# -ne 2 ]; then
  echo "usage: scripts/fleet-check.sh DEB KIOSK_EXE" >&2
  exit 2
fi
deb="$(realpath "$1")"
kiosk="$(realpath "$2")"
if [ "$(id -u)" -ne 0 ]; then
  echo "fleet-check: needs root (debootstrap, chroot, mounts)" >&2
  exit 2
fi
for tool in debootstrap reprepro gpg ansible-playbook python3; do
  command -v "$tool" >/dev/null || { echo "fleet-check: $tool is not installed" >&2; exit 2; }
done
work="${HK_FLEET_DIR:-/var/tmp/hk-fleet}"
base="$work/base"
hosts=(kiosk-a kiosk-b)
mkdir -p "$work"

# The base machine: Debian 12, minimal, with what Ansible needs (python3).
if [ ! -x "$base/usr/bin/python3" ]; then
  echo "fleet-check: debootstrap bookworm into $base (once)"
  debootstrap --variant=minbase --include=python3,ca-certificates,systemd,dbus,udev bookworm "$base" \
    http://deb.debian.org/debian > "$work/debootstrap.log"
fi

mounted=()
cleanup() {
  for m in "${mounted[@]}"; do umount -l "$m" 2>/dev/null || true; done
  [ -n "${http_pid:-}" ] && kill "$http_pid" 2>/dev/null || true
}
trap cleanup EXIT

# Fresh machines from the base, with /proc, /sys and /dev for dpkg's scripts.
for h in "${hosts[@]}"; do
  rm -rf "${work:?}/$h"
  cp -a "$base" "$work/$h"
  for fs in proc sys dev; do
    mount --bind "/$fs" "$work/$h/$fs"
    mounted+=("$work/$h/$fs")
  done
done

# The museum's repository: a throwaway signing key, reprepro, served on localhost.
repo="$work/repo"
export GNUPGHOME="$work/gnupg"
rm -rf "$repo" "$GNUPGHOME"
mkdir -p "$repo/conf" "$GNUPGHOME"
chmod 700 "$GNUPGHOME"
gpg --batch --quiet --passphrase '' --quick-gen-key "Museum kiosk archive (fleet-check) <it@museum.example>" \
  rsa3072 sign never
gpg --batch --armor --export it@museum.example > "$work/museum-archive-key.asc"
cat > "$repo/conf/distributions" <<'EOF'
Codename: bookworm
Components: main
Architectures: amd64
SignWith: it@museum.example
EOF
reprepro -b "$repo" --silent includedeb bookworm "$deb"
port=8731
(cd "$repo" && exec python3 -m http.server "$port" --bind 127.0.0.1 > "$work/http.log" 2>&1) &
http_pid=$!
sleep 1

# The inventory: one kiosk a gallery.
cat > "$work/inventory.ini" <<EOF
[gallery_north]
kiosk-a ansible_connection=community.general.chroot ansible_host=$work/kiosk-a

[gallery_south]
kiosk-b ansible_connection=community.general.chroot ansible_host=$work/kiosk-b

[kiosks:children]
gallery_north
gallery_south
EOF
pin_hash="$(printf '2468\n' | "$kiosk" pin hash 2>/dev/null)"
export ANSIBLE_CONFIG="$root/deploy/ansible/ansible.cfg" ANSIBLE_NOCOLOR=1 ASAN_OPTIONS=detect_leaks=0
run() {  # the playbook with the fleet-check's values; $1: the library folder
  ansible-playbook -i "$work/inventory.ini" "$root/deploy/ansible/site.yml" \
    -e "haptic_kiosk_apt_repo=http://127.0.0.1:$port" -e "haptic_kiosk_apt_key=$work/museum-archive-key.asc" \
    -e "haptic_kiosk_check_command=$kiosk" -e "haptic_kiosk_library_src=$1" -e haptic_kiosk_restart=false \
    -e "vault_haptic_kiosk_pin_hash=$pin_hash"
}
library_sums() {
  for h in "${hosts[@]}"; do (cd "$work/$h/var/lib/haptic-kiosk/library" && sha256sum ./* | sed "s#^#$h #"); done
}

echo "fleet-check: first run (installs and configures both)"
run "$root/data/pictures" | tee "$work/run1.log"
grep -E '^(kiosk-a|kiosk-b) +: ' "$work/run1.log" | grep -q 'failed=0' || { echo "fleet-check: the first run failed" >&2; exit 1; }
echo "fleet-check: second run (no change)"
run "$root/data/pictures" | tee "$work/run2.log"
if grep -E '^(kiosk-a|kiosk-b) +: ' "$work/run2.log" | grep -vq 'changed=0.*failed=0'; then
  echo "fleet-check: the second run changed something or failed" >&2
  exit 1
fi
# What the kiosks got.
for h in "${hosts[@]}"; do
  echo "== $h"
  chroot "$work/$h" dpkg-query -W -f='${Package} ${Version}\n' haptic-kiosk
  cat "$work/$h/etc/haptic-kiosk/fleet.toml"
  grep -c '^pin_hash = "\$argon2id' "$work/$h/etc/haptic-kiosk/settings.toml" | sed 's/^/pin_hash lines in settings.toml: /'
  ls "$work/$h/var/lib/haptic-kiosk/library" | tr '\n' ' '
  echo
  # The installed kiosk reads what it was given: the PIN rolled out opens, the library checks clean.
  chroot "$work/$h" sh -c "printf '2468\n' | haptic-kiosk pin check --config /etc/haptic-kiosk/settings.toml" ||
    { echo "fleet-check: $h: the PIN rolled out does not open the panel" >&2; exit 1; }
  echo "pin check: the PIN rolled out opens the panel"
  chroot "$work/$h" haptic-kiosk library check /var/lib/haptic-kiosk/library --config /etc/haptic-kiosk/settings.toml
done
echo "fleet-check: a broken library (half a PNG)"
library_sums > "$work/before.sums"
broken="$work/broken-library"
rm -rf "$broken"
cp -a "$root/data/pictures" "$broken"
head -c 2000 "$root/data/pictures/coins.png" > "$broken/coins.png"
if run "$broken" > "$work/run3.log" 2>&1; then
  cat "$work/run3.log"
  echo "fleet-check: the broken library went out" >&2
  exit 1
fi
grep -E 'coins.png: |PLAY RECAP|^(kiosk|localhost)' "$work/run3.log" || true
library_sums > "$work/after.sums"
cmp -s "$work/before.sums" "$work/after.sums" || { echo "fleet-check: a kiosk's library changed" >&2; exit 1; }
echo "fleet-check: the kiosks' libraries are as they were"
echo "fleet-check: all passed"
