#!/usr/bin/env bash
# Configures and builds haptic-kiosk. Usage: scripts/build.sh [BUILD_DIR] [extra cmake args...]
# e.g. scripts/build.sh build-asan -DHK_SANITIZE=ON. Compiles through ccache when installed (compiler-cache.sh).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build}"
shift || true
source "$root/scripts/compiler-cache.sh"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "${hk_cache_args[@]}" "$@" >/dev/null
cmake --build "$build" -j "$(nproc)"
