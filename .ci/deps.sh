#!/usr/bin/env bash
# Install TreeLod's build and test dependencies from Debian 12's archive (only what is missing).
set -euo pipefail
packages=(cmake g++ make ninja-build lld pkg-config
  libogre-1.12-dev libglm-dev libtinygltf-dev libpng-dev libjpeg-dev libeigen3-dev libembree-dev
  libsquish-dev libtbb-dev nlohmann-json3-dev libcli11-dev libgtest-dev googletest libbenchmark-dev
  xvfb xauth libgl1-mesa-dri file gdb python3 python3-matplotlib glslang-tools)
for flag in "$@"; do
  case $flag in
    --with-fuzzers) packages+=(clang libclang-rt-14-dev) ;;
    --with-gpu-bundle) packages+=(mesa-utils x11-xkb-utils xz-utils) ;; # the GPU bundle (bench/gpu-run.sh) packs glxinfo, xkbcomp
    *) echo "deps.sh: unknown flag $flag (known: --with-fuzzers, --with-gpu-bundle)" >&2; exit 2 ;;
  esac
done
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "installing: ${missing[*]}"
  sudo=""; [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
