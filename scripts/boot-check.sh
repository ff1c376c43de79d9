#!/usr/bin/env bash
# Boots a fresh Debian 12 with the package installed, in qemu, and checks that it lands in the kiosk
# (a Debian package that boots into the kiosk).
#
#   scripts/boot-check.sh [--deb dist/haptic-kiosk_<version>_amd64.deb] [--work DIR] [--wait-s S] [--accel tcg|kvm] [--keep]
#
# 1. debootstrap bookworm (minbase + systemd, udev, dbus, a kernel) into DIR/rootfs, from the Debian
#    archive this machine's apt uses (its sources are copied into the guest; cached: a rootfs already
#    there is reused);
# 2. installs the package with apt, exactly as README's "Installing on a fresh Debian 12" does, so its
#    dependencies (cage, Xwayland, Mesa, ...) come from the archive; no other change to the system but a
#    root login on the serial console for the report below;
# 3. makes a raw ext4 disk of the rootfs (mke2fs -d: no loop device, no mount) and boots it in
#    qemu-system-x86_64, 1 CPU, 2 GiB, a virtio GPU (wlroots 0.15, cage's, needs PRIME import, which qemu's std VGA lacks), no network; software emulation (tcg) unless
#    --accel kvm (on this workplace's VMs /dev/kvm exists but a KVM guest never gets past the BIOS, so
#    kvm is not the default);
# 4. a report unit of the check (not of the package) waits until haptic-kiosk.service has been active for
#    S seconds (default 120 under emulation) or has failed, then writes `systemctl status`, the unit's
#    journal and the processes of its cgroup to a second serial port (ttyS1) and
#    powers off; meanwhile the script takes a screenshot of the VGA screen (qemu monitor, screendump)
#    when the report starts, as DIR/screen.ppm and DIR/screen.png;
# 5. exits 0 when the unit was active and running the kiosk under cage, 1 otherwise, printing why.
#
# Needs root (debootstrap, chroot), debootstrap, qemu-system-x86, e2fsprogs, python3 (PNG). Takes minutes
# the first time (debootstrap and the package's dependencies download ~700 MB) and a minute with KVM (many
# under software emulation) after that. Not part of CI: those downloads and the boot would take a good part
# of CI's 40 minutes.
set -euo pipefail

root_dir=$(cd "$(dirname "$0")/.." && pwd)
deb=""
work=/var/tmp/hk-boot-check
wait_s=120
keep=0
accel=tcg
usage() { echo "usage: scripts/boot-check.sh [--deb FILE.deb] [--work DIR] [--wait-s S] [--accel tcg|kvm] [--keep]" >&2; exit 2; }
while [ $# -gt 0 ]; do
  case "$1" in
    --deb) [ $# -ge 2 ] || usage; deb=$2; shift 2 ;;
    --work) [ $# -ge 2 ] || usage; work=$2; shift 2 ;;
    --wait-s) [ $# -ge 2 ] || usage; wait_s=$2; shift 2 ;;
    --accel) [ $# -ge 2 ] || usage; accel=$2; shift 2 ;;
    --keep) keep=1; shift ;;
    *) usage ;;
  esac
done
[ -n "$deb" ] || deb=$(ls "$root_dir"/dist/haptic-kiosk_*_amd64.deb 2>/dev/null | tail -1 || true)
[ -f "$deb" ] || { echo "boot-check: no package: build it with scripts/package.sh or name it with --deb" >&2; exit 2; }
[[ $wait_s =~ ^[0-9]+$ ]] || { echo "boot-check: --wait-s needs a whole number of seconds" >&2; exit 2; }
[ "$accel" = tcg ] || [ "$accel" = kvm ] || { echo "boot-check: --accel is tcg or kvm, not '$accel'" >&2; exit 2; }
[ "$(id -u)" = 0 ] || { echo "boot-check: needs root (debootstrap and chroot)" >&2; exit 2; }
for tool in debootstrap qemu-system-x86_64 mke2fs; do
  command -v "$tool" >/dev/null || { echo "boot-check: $tool missing (apt-get install debootstrap qemu-system-x86 e2fsprogs)" >&2; exit 2; }
done

# The archive this machine's apt uses for bookworm: the first URI of a deb822 stanza or one-line entry
# that names the suite "bookworm" (no host is written into this script).
host_mirror() {
  local f
  for f in /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] || continue
    awk 'BEGIN{RS="";FS="\n"} /(^|\n)Suites:[^\n]*(^| )bookworm( |$|\n)/ && /(^|\n)Types:[^\n]*deb( |$|\n)/ {
           for (i = 1; i <= NF; i++) if ($i ~ /^URIs:/) { split($i, u, " "); print u[2]; exit } }' "$f"
  done
  [ -f /etc/apt/sources.list ] && awk '$1 == "deb" && $3 == "bookworm" { print $2; exit }' /etc/apt/sources.list
  return 0
}
mirror=$(host_mirror | head -n 1)
[ -n "$mirror" ] || { echo "boot-check: no bookworm entry in this machine's apt sources to debootstrap from" >&2; exit 2; }

rootfs=$work/rootfs
mkdir -p "$work"
log=$work/boot-check.log
: > "$log"
say() { echo "boot-check: $*"; }

# 1. The base system, once.
if [ ! -x "$rootfs/usr/bin/apt-get" ] || [ ! -f "$rootfs/.hk-base-done" ]; then
  rm -rf "$rootfs"
  say "debootstrap bookworm into $rootfs (log: $log)"
  debootstrap --variant=minbase --include=systemd,systemd-sysv,udev,dbus,kmod,procps,linux-image-amd64,initramfs-tools,login,passwd \
    bookworm "$rootfs" "$mirror" >> "$log" 2>&1
  touch "$rootfs/.hk-base-done"
fi

# 2. The package, as an administrator installs it (README), inside the rootfs.
in_root() {
  mount -t proc proc "$rootfs/proc"
  mount --rbind /dev "$rootfs/dev"
  mount -t sysfs sys "$rootfs/sys"
  local rc=0
  chroot "$rootfs" /usr/bin/env DEBIAN_FRONTEND=noninteractive LC_ALL=C.UTF-8 "$@" >> "$log" 2>&1 || rc=$?
  umount -R "$rootfs/dev" || umount -l "$rootfs/dev"
  umount "$rootfs/sys" "$rootfs/proc"
  return $rc
}
# The guest's apt uses the same sources as this machine's (bookworm, its updates and security).
rm -f "$rootfs/etc/apt/sources.list" "$rootfs"/etc/apt/sources.list.d/*
[ -f /etc/apt/sources.list ] && cp /etc/apt/sources.list "$rootfs/etc/apt/sources.list"
for f in /etc/apt/sources.list.d/*.sources /etc/apt/sources.list.d/*.list; do
  [ -f "$f" ] && cp "$f" "$rootfs/etc/apt/sources.list.d/"
done
cp "$deb" "$rootfs/tmp/haptic-kiosk.deb"
say "installing $(basename "$deb") and its dependencies with apt"
in_root apt-get update
in_root apt-get install -y --reinstall /tmp/haptic-kiosk.deb  # --reinstall: a rebuilt package of the same version
version=$(chroot "$rootfs" dpkg-query -W -f='${Version}' haptic-kiosk)
say "installed haptic-kiosk $version; unit enabled: $(chroot "$rootfs" systemctl is-enabled haptic-kiosk.service 2>&1 || true)"

# What the check itself adds: a file system table, root on the serial console, and the report unit.
echo "/dev/vda / ext4 defaults 0 1" > "$rootfs/etc/fstab"
echo "hk-boot-check" > "$rootfs/etc/hostname"
chroot "$rootfs" passwd -d root >> "$log" 2>&1
cat > "$rootfs/usr/local/sbin/hk-boot-report" <<EOF
#!/bin/sh
# Waits for haptic-kiosk.service to have been active ${wait_s} s (or to have failed), reports, powers off.
exec > /dev/ttyS1 2>&1
waited=0
while [ \$waited -lt 900 ]; do
  state=\$(systemctl is-active haptic-kiosk.service)
  [ "\$state" = failed ] && break
  if [ "\$state" = active ]; then
    since=\$(systemctl show -p ActiveEnterTimestampMonotonic --value haptic-kiosk.service)
    now=\$(cut -d' ' -f1 /proc/uptime | cut -d. -f1)
    [ \$((now - since / 1000000)) -ge ${wait_s} ] && break
  fi
  sleep 5; waited=\$((waited + 5))
done
echo "HK-REPORT-BEGIN"
echo "is-active: \$(systemctl is-active haptic-kiosk.service)"
echo "n-restarts: \$(systemctl show -p NRestarts --value haptic-kiosk.service)"
echo "main-pid: \$(systemctl show -p MainPID --value haptic-kiosk.service)"
echo "uptime-s: \$(cut -d' ' -f1 /proc/uptime)"
systemctl status --no-pager -l haptic-kiosk.service | sed -n '1,40p'
echo "active-vt: \$(cat /sys/class/tty/tty0/active)"
echo "--- sessions"
loginctl list-sessions --no-legend
for s in \$(loginctl list-sessions --no-legend | awk '{print \$1}'); do
  loginctl show-session "\$s" -p Name -p TTY -p VTNr -p State -p Active -p Type -p Class | tr '\n' ' '; echo
done
# PAM moves the unit's processes into the session's scope, so they are found by the unit's main process
# and its descendants, not by the unit's cgroup.
echo "--- processes of the unit (user, caps, command)"
main=\$(systemctl show -p MainPID --value haptic-kiosk.service)
pids="\$main"
frontier="\$main"
while [ -n "\$frontier" ]; do
  next=""
  for p in \$frontier; do next="\$next \$(cat /proc/\$p/task/*/children 2>/dev/null)"; done
  frontier=\$(echo \$next)
  pids="\$pids \$frontier"
done
for p in \$pids; do
  [ -r /proc/\$p/status ] || continue
  echo "\$(stat -c %U /proc/\$p) \$(grep CapEff /proc/\$p/status | tr -d '\t') \$(tr '\0' ' ' < /proc/\$p/cmdline)"
done
echo "--- journal of the unit"
journalctl -b -u haptic-kiosk.service --no-pager -o short-monotonic | grep -v pam_ | tail -n 40
echo "--- the kiosk's log, first start (journalctl -t haptic-kiosk: cage's, Xwayland's and the kiosk's lines)"
journalctl -b -t haptic-kiosk --no-pager -o short-monotonic | head -n 60
echo "HK-SCREEN-NOW"
sleep 20
echo "HK-REPORT-END"
systemctl poweroff
EOF
chmod 0755 "$rootfs/usr/local/sbin/hk-boot-report"
cat > "$rootfs/etc/systemd/system/hk-boot-report.service" <<'EOF'
[Unit]
Description=boot-check report (scripts/boot-check.sh; not part of the package)
After=haptic-kiosk.service
[Service]
Type=simple
ExecStart=/usr/local/sbin/hk-boot-report
[Install]
WantedBy=graphical.target
EOF
ln -sf /etc/systemd/system/hk-boot-report.service "$rootfs/etc/systemd/system/graphical.target.wants/hk-boot-report.service" 2>/dev/null ||
  { mkdir -p "$rootfs/etc/systemd/system/graphical.target.wants"; ln -sf /etc/systemd/system/hk-boot-report.service "$rootfs/etc/systemd/system/graphical.target.wants/hk-boot-report.service"; }
# The emulated GPU has no 3D: wlroots' GLES2 renderer falls back to Mesa's kms_swrast there and cage then
# dies of SIGSEGV (seen here), so the guest's cage draws with wlroots' pixman renderer. A drop-in of the
# check, not of the package: a kiosk machine's GPU takes the default renderer.
mkdir -p "$rootfs/etc/systemd/system/haptic-kiosk.service.d"
printf '[Service]\nEnvironment=WLR_RENDERER=pixman\n' > "$rootfs/etc/systemd/system/haptic-kiosk.service.d/boot-check.conf"
chroot "$rootfs" systemctl set-default graphical.target >> "$log" 2>&1

# 3. The disk, and the boot.
kernel=$(ls "$rootfs"/boot/vmlinuz-* | tail -1)
initrd=$(ls "$rootfs"/boot/initrd.img-* | tail -1)
disk=$work/disk.img
rm -f "$disk"
truncate -s 6G "$disk"
mke2fs -q -t ext4 -d "$rootfs" -F "$disk"
console=$work/console.log  # the guest's console (ttyS0)
serial=$work/serial.log    # the report unit's own port (ttyS1: no getty there)
mon=$work/monitor.sock
rm -f "$console" "$serial" "$mon"
say "booting in qemu ($accel); console: $console"
qemu-system-x86_64 -machine q35,accel=$accel -m 2048 -smp 1 -kernel "$kernel" -initrd "$initrd" \
  -append "root=/dev/vda rw console=tty0 console=ttyS0,115200 quiet" \
  -drive file="$disk",format=raw,if=virtio -vga none -device virtio-gpu-pci -display none -nic none \
  -serial file:"$console" -serial file:"$serial" -monitor unix:"$mon",server,nowait -no-reboot &
qemu=$!
cleanup() { kill "$qemu" 2>/dev/null || true; [ "$keep" = 1 ] || rm -f "$disk"; }
trap cleanup EXIT

# 4. Wait for the report; screenshot when it says so.
deadline=$((SECONDS + 1800))
shot=0
while kill -0 "$qemu" 2>/dev/null && [ $SECONDS -lt $deadline ]; do
  if [ $shot = 0 ] && grep -q HK-SCREEN-NOW "$serial" 2>/dev/null; then
    python3 - "$mon" "$work/screen.ppm" <<'PY'
import socket, sys, time
s = socket.socket(socket.AF_UNIX)
s.connect(sys.argv[1])
s.sendall(("screendump %s\n" % sys.argv[2]).encode())
time.sleep(3)
s.close()
PY
    shot=1
  fi
  sleep 5
done
kill -0 "$qemu" 2>/dev/null && { say "no report within 30 minutes"; exit 1; }
if [ -f "$work/screen.ppm" ]; then
  python3 - "$work/screen.ppm" "$work/screen.png" <<'PY' || true
import sys, zlib, struct
import re
data = open(sys.argv[1], "rb").read()
# P6 header: magic, width, height, maxval, then exactly one whitespace byte (pixels may start with bytes
# that look like whitespace, so no split()).
m = re.match(rb"P6\s+(\d+)\s+(\d+)\s+(\d+)\s", data)
w, h, body = int(m.group(1)), int(m.group(2)), data[m.end():]
raw = b"".join(b"\0" + body[y * w * 3:(y + 1) * w * 3] for y in range(h))
chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
open(sys.argv[2], "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
PY
fi

# 5. The verdict.
report=$(sed -n '/HK-REPORT-BEGIN/,/HK-REPORT-END/p' "$serial" | tr -d '\r')
[ -n "$report" ] || { say "the guest wrote no report (console: $console)"; exit 1; }
echo "$report" > "$work/report.txt"
say "report in $work/report.txt, screen in $work/screen.png"
active=$(echo "$report" | sed -n 's/^is-active: //p')
procs=$(echo "$report" | sed -n '/--- processes/,/--- journal/p')
ok=1
[ "$active" = active ] || { say "haptic-kiosk.service is $active, not active"; ok=0; }
echo "$procs" | grep -Eq '^haptic-kiosk CapEff:[0-9a-f]+ /usr/bin/cage ' || { say "no cage running as haptic-kiosk in the unit"; ok=0; }
echo "$report" | grep -q '^active-vt: tty1' || { say "the screen shows $(echo "$report" | sed -n 's/^active-vt: //p'), not the kiosk's tty1"; ok=0; }
echo "$procs" | grep -Eq '^haptic-kiosk CapEff:[0-9a-f]+ /usr/bin/haptic-kiosk ' || { say "no haptic-kiosk process running as haptic-kiosk in the unit"; ok=0; }
[ $ok = 1 ] && say "booted into the kiosk: unit active, cage and the kiosk running as haptic-kiosk on tty1, in front" || exit 1
