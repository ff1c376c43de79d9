#!/usr/bin/env bash
# Installs the Debian 12 packages haptic-kiosk needs. Safe to run again.
# Usage: scripts/install-deps.sh [--demo]
#   (none)   everything to build, test, fuzz, benchmark and package it
#   --demo   only what building haptic-kiosk and running `explore` needs (scripts/demo.sh)
set -euo pipefail
packages=(
  g++ cmake ninja-build pkg-config ccache
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev libopencv-objdetect-dev libopencv-contrib-dev opencv-data
  libtomlplusplus-dev libcli11-dev libspdlog-dev nlohmann-json3-dev
  libespeak-ng-dev flite1-dev portaudio19-dev libsndfile1-dev libsamplerate0-dev gettext libboost-locale-dev
  libglfw3-dev libimgui-dev libgl-dev
  libpoppler-cpp-dev libqpdf-dev libtesseract-dev libleptonica-dev tesseract-ocr-eng libudev-dev libblkid-dev libcamera-dev libsodium-dev libusb-1.0-0-dev libexiv2-dev libpng-dev zlib1g-dev librsvg2-dev
  liblouis-dev liblouis-data libcairo2-dev libcups2-dev libsystemd-dev libmicrohttpd-dev
)
if [ "${1:-}" != "--demo" ]; then
  packages+=(
    libgtest-dev libgmock-dev libbenchmark-dev libboost-dev libembree-dev
    sox libgl1-mesa-dri xvfb xauth tesseract-ocr tesseract-ocr-deu tesseract-ocr-fra tesseract-ocr-spa
    poppler-utils e2fsprogs util-linux mount qpdf dosfstools mtools cups-daemon cups-client
    dpkg-dev file lintian systemd cage
    clang libclang-rt-14-dev llvm-14 clang-format-14
    prometheus ansible ansible-lint
  )
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  echo "install-deps: installing ${missing[*]}"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
