#!/usr/bin/env bash
# Meniscus developer entry point: installs what is missing, builds incrementally, then
#   ./dev.sh run [SCENE.json] [meniscus run options]   runs a scene (default: the README's), frames in out/
#   ./dev.sh test                                       runs the whole test suite through ctest
#   ./dev.sh build                                      only sets up and builds
# Idempotent: with everything installed and built it only checks and runs.
set -euo pipefail
cd "$(dirname "$0")"

DEFAULT_SCENE=scenes/drop_merge.json
BUILD_DIR=${MENISCUS_BUILD_DIR:-build}
PACKAGES=(cmake ninja-build g++ ccache libeigen3-dev libtbb-dev libopenvdb-dev libboost-iostreams-dev
          nlohmann-json3-dev libgtest-dev libbenchmark-dev libgmp-dev python3-matplotlib python3-numpy
          blender python3-openvdb python3-meshio python3-pil)

install_missing() {
  local missing=()
  for p in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "dev.sh: installing ${missing[*]}" >&2
  local sudo=()
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "dev.sh: need root (or sudo) to install: ${missing[*]}" >&2; exit 2; }
    sudo=(sudo)
  fi
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

build() {
  if [ ! -f "$BUILD_DIR/build.ninja" ]; then
    cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release
  fi
  cmake --build "$BUILD_DIR" -j "$(nproc)"
}

cmd=${1:-run}
shift || true
install_missing
build
case "$cmd" in
  run)
    scene=$DEFAULT_SCENE
    if [ $# -gt 0 ] && [[ "$1" != -* ]]; then scene=$1; shift; fi
    exec "$BUILD_DIR/app/meniscus" run "$scene" --out out "$@"
    ;;
  test)
    cd "$BUILD_DIR"
    exec ctest --output-on-failure -j "$(nproc)" --timeout 900
    ;;
  build) ;;
  *) echo "usage: ./dev.sh [run [SCENE.json] [options] | test | build]" >&2; exit 2 ;;
esac
