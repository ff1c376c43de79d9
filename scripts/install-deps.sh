#!/usr/bin/env bash
# Installs every Debian 12 package haptic-kiosk needs to build and test. Safe to run again.
set -euo pipefail
packages=(
  g++ cmake ninja-build pkg-config
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev libopencv-contrib-dev
  libtomlplusplus-dev libcli11-dev libspdlog-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev libboost-dev libembree-dev
  libespeak-ng-dev portaudio19-dev libsndfile1-dev libsamplerate0-dev sox
  libglfw3-dev libimgui-dev libgl-dev libgl1-mesa-dri xvfb xauth
  libpoppler-cpp-dev libtesseract-dev tesseract-ocr-eng tesseract-ocr-deu libudev-dev libblkid-dev libcamera-dev libsodium-dev libusb-1.0-0-dev libexiv2-dev libpng-dev
  poppler-utils e2fsprogs util-linux mount qpdf dosfstools mtools
  dpkg-dev file lintian systemd cage
  clang libclang-rt-14-dev llvm-14
)
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
