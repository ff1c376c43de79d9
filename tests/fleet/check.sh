#!/usr/bin/env bash
# The fleet's files, checked as CI can without other machines (scripts/test.sh, stage "fleet"):
#   - the playbooks: ansible-playbook --syntax-check and ansible-lint (production profile);
#   - the role in check mode against this machine as the one kiosk (tests/fleet/local.ini), installing the
#     package just built, with the shipped pictures as the library (no restart: no systemd here);
#   - a library with a broken picture: the playbook stops at `library check`, before any kiosk is touched;
#   - the Prometheus files: promtool check config and rules, and the alerts' unit tests (alerts.test.yml).
# scripts/fleet-check.sh does the real roll-out onto two machines (outside CI: minutes of debootstrap).
# Usage: tests/fleet/check.sh DEB KIOSK_EXE
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
deb="$(realpath "$1")"
kiosk="$(realpath "$2")"
ansible_dir="$root/deploy/ansible"
export ANSIBLE_CONFIG="$ansible_dir/ansible.cfg" ANSIBLE_NOCOLOR=1 ANSIBLE_FORCE_COLOR=0
# The kiosk binary of the sanitizer build reads the library too: leak reports are not what this checks.
export ASAN_OPTIONS="detect_leaks=0"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

echo "fleet: syntax and lint"
(cd "$ansible_dir" && ansible-playbook --syntax-check -i inventory/museum.ini site.yml)
(cd "$ansible_dir" && ansible-lint --offline -p site.yml)

common=(-i "$root/tests/fleet/local.ini" "$ansible_dir/site.yml" --check
  -e haptic_kiosk_apt_repo= -e "haptic_kiosk_deb=$deb" -e "haptic_kiosk_check_command=$kiosk" -e haptic_kiosk_restart=false)

echo "fleet: the role in check mode against this machine"
ansible-playbook "${common[@]}" -e "haptic_kiosk_library_src=$root/data/pictures" | tee "$tmp/good.log"
grep -q 'failed=0' "$tmp/good.log"

echo "fleet: a broken library is refused before any kiosk is touched"
mkdir "$tmp/broken"
cp "$root/data/pictures/horse.png" "$root/data/pictures/horse.toml" "$tmp/broken/"
head -c 2000 "$root/data/pictures/coins.png" > "$tmp/broken/coins.png"
if ansible-playbook "${common[@]}" -e "haptic_kiosk_library_src=$tmp/broken" > "$tmp/broken.log" 2>&1; then
  cat "$tmp/broken.log"
  echo "fleet: the broken library was not refused" >&2
  exit 1
fi
grep -q 'coins.png: ' "$tmp/broken.log" || { cat "$tmp/broken.log"; echo "fleet: no line names coins.png" >&2; exit 1; }
if grep -q 'TASK \[haptic_kiosk' "$tmp/broken.log"; then
  cat "$tmp/broken.log"
  echo "fleet: the role ran after the library check failed" >&2
  exit 1
fi

echo "fleet: Prometheus files"
promtool check config "$root/deploy/prometheus/prometheus.yml"
promtool check rules "$root/deploy/prometheus/haptic-kiosk.rules.yml"
promtool test rules "$root/tests/fleet/alerts.test.yml"
echo "fleet: all checks passed"
