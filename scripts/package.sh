#!/usr/bin/env bash
# Builds the Debian package dist/haptic-kiosk_<version>_amd64.deb (README "Installing on a fresh Debian 12"):
# installs the build packages, makes a Release build without tests or benchmarks, installed under /usr
# (pictures and messages in /usr/share/haptic-kiosk, helpers in /usr/libexec/haptic-kiosk), and packs it
# with CPack's DEB generator (packaging/CMakeLists.txt). The version is project(... VERSION ...) in
# CMakeLists.txt. Usage: scripts/package.sh [BUILD_DIR]  (default: build-package; HK_JOBS=N for -j N)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build-package}"
jobs="${HK_JOBS:-$(nproc)}"

bash "$root/scripts/install-deps.sh"

version="$(sed -n 's/^project([^)]*VERSION \([0-9][0-9.]*\).*/\1/p' "$root/CMakeLists.txt" | head -n 1)"
if [ -z "$version" ]; then
  echo "package: no 'project(... VERSION x.y.z ...)' in $root/CMakeLists.txt" >&2
  exit 1
fi
deb="haptic-kiosk_${version}_$(dpkg --print-architecture).deb"

# The changelog's date (and CPack's time stamps) from the last commit, so a rebuild of the same tree gives
# the same package.
export SOURCE_DATE_EPOCH="${SOURCE_DATE_EPOCH:-$(git -C "$root" log -1 --format=%ct 2>/dev/null || date +%s)}"

# Debian's hardening flags (lintian looks for them in the binaries), without -g: they are stripped anyway.
# No -ffile-prefix-map of the checkout's path (reproducible=-fixfilepath): ccache (compiler-cache.sh) hashes
# sources relative to the checkout, so the same sources in another clone compile from the cache.
export DEB_BUILD_MAINT_OPTIONS="hardening=+all reproducible=-fixfilepath,-fixdebugpath"
cxxflags="$(dpkg-buildflags --get CXXFLAGS | sed -e 's/\(^\| \)-g\( \|$\)/ /g') $(dpkg-buildflags --get CPPFLAGS)"
ldflags="$(dpkg-buildflags --get LDFLAGS)"

source "$root/scripts/compiler-cache.sh"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DHK_BUILD_TESTS=OFF -DHK_BUILD_BENCH=OFF "${hk_cache_args[@]}" \
  -DCMAKE_INSTALL_PREFIX=/usr -DHK_DATA_DIR=/usr/share/haptic-kiosk -DHK_LOCALE_DIR=/usr/share/haptic-kiosk/locale -DHK_LIBEXEC_DIR=/usr/libexec/haptic-kiosk \
  -DCMAKE_CXX_FLAGS="$cxxflags" -DCMAKE_EXE_LINKER_FLAGS="$ldflags" >/dev/null
cmake --build "$build" -j "$jobs"

rm -f "$build"/package/*.deb
(cd "$build" && cpack -G DEB >/dev/null)
if [ ! -f "$build/package/$deb" ]; then
  echo "package: cpack did not make $build/package/$deb (made: $(ls "$build/package" 2>/dev/null | tr '\n' ' '))" >&2
  exit 1
fi
mkdir -p "$root/dist"
cp "$build/package/$deb" "$root/dist/$deb"
echo "package: dist/$deb ($(du -h "$root/dist/$deb" | cut -f1))"
