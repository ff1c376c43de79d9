# Sourced by scripts/build.sh, package.sh and fuzz.sh: compile through ccache when it is installed, with its
# cache outside the checkout so a fresh clone of the same sources (CI) compiles from it.
#   CCACHE_DIR      where the cache lives (default ~/.cache/haptic-kiosk-ccache, 8 GB at most)
#   HK_CCACHE=0     compile without it
# Paths under the checkout are hashed relative to it (CCACHE_BASEDIR), and the build folder's path is left
# out of the hash (CCACHE_NOHASHDIR), so clones at different paths share entries; the absolute paths the
# build compiles in (data folders, helper programs) are confined to one small file per target
# (tests/support/test_paths.cpp, vision's pdf.cpp and ocr.cpp, the kiosk's kiosk_app.cpp).
# Sets hk_cache_args: the CMake arguments that put ccache in front of the compilers (empty without it).
hk_cache_args=()
if [ "${HK_CCACHE:-1}" != 0 ] && command -v ccache > /dev/null 2>&1; then
  export CCACHE_DIR="${CCACHE_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/haptic-kiosk-ccache}"
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$root}"
  export CCACHE_NOHASHDIR=1
  export CCACHE_MAXSIZE="${CCACHE_MAXSIZE:-8G}"
  export CCACHE_SLOPPINESS="${CCACHE_SLOPPINESS:-pch_defines,time_macros,include_file_mtime,include_file_ctime}"
  hk_cache_args=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi
