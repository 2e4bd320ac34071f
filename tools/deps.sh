#!/usr/bin/env bash
# Installs the Debian packages the tests and examples need, only when missing.
# Usage: tools/deps.sh test|demo|run|web
#   web: emscripten (emcc with its system libraries prebuilt) and chromium for make web / the browser test
# FOGVOL_NO_INSTALL=1 turns installing off (provide the packages yourself, e.g. on a non-Debian system).
set -euo pipefail
what=${1:-test}
pkgs_test="gcc g++ clang make libosmesa6-dev libstb-dev glslang-tools libcmocka-dev libclang-rt-14-dev valgrind libegl-dev libgles-dev libegl-mesa0 libopengl-dev libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers spirv-tools spirv-cross glslc libshaderc-dev glslang-dev"
pkgs_demo="gcc make libosmesa6-dev libstb-dev"
pkgs_run="gcc make libglfw3-dev libgl-dev xvfb xauth cmake pkg-config libosmesa6-dev libstb-dev"
pkgs_web="make emscripten chromium libstb-dev"
case "$what" in
  test) pkgs="$pkgs_test" ;;
  demo) pkgs="$pkgs_demo" ;;
  run) pkgs="$pkgs_run" ;;
  web) pkgs="$pkgs_web" ;;
  *) echo "usage: $0 test|demo|run|web" >&2; exit 2 ;;
esac
# FOGVOL_NO_INSTALL=1: never install anything (the dependencies are yours to provide)
if [ "${FOGVOL_NO_INSTALL:-0}" = 1 ]; then
  exit 0
fi
if ! command -v dpkg-query >/dev/null 2>&1 || ! command -v apt-get >/dev/null 2>&1; then
  cat >&2 <<EOF2
deps: this is not a Debian-like system (no dpkg-query/apt-get), so nothing is installed.
deps: '$what' needs these Debian packages or their equivalents: $pkgs
deps:   (OSMesa: mesa's libOSMesa + headers; Mesa's EGL with the surfaceless platform + GLES headers; cmocka;
deps:    stb_image_write.h under <stb/>; glslangValidator; GLFW 3 and Xvfb for the windowed demo; cmake and
deps:    pkg-config for the packaging tests; emscripten and chromium for the browser build and its test;
deps:    the Vulkan loader and headers, Mesa's lavapipe, the Khronos validation layers, glslc and shaderc
deps:    (with glslang's static libraries), spirv-val and spirv-cross for the Vulkan example and shaders)
deps: install them, then run again with FOGVOL_NO_INSTALL=1.
EOF2
  exit 1
fi
missing=()
for p in $pkgs; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "deps: installing ${missing[*]}"
sudo=""
if [ "$(id -u)" != 0 ]; then
  if command -v sudo >/dev/null 2>&1; then sudo="sudo"; else
    echo "deps: missing packages ${missing[*]}; run as root or install them with apt-get" >&2; exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
