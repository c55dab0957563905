#!/usr/bin/env bash
# One entry point for a fresh Debian 12 machine (as root) or an existing one:
#   bash cmake/setup.sh demo   install what is missing, build, run the demo on samples/
#   bash cmake/setup.sh test   install what is missing, build, run the whole test suite
#   bash cmake/setup.sh build  install what is missing, build only
# Build tree: ${TEXTILE_BUILD_DIR:-build}. Extra CMake flags: ${TEXTILE_CMAKE_ARGS}.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$here"
verb="${1:-demo}"
build="${TEXTILE_BUILD_DIR:-build}"

install_missing() {
  local wanted missing=()
  mapfile -t wanted < <(grep -vE '^\s*(#|$)' cmake/debian-packages.txt)
  for p in "${wanted[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
  done
  if ((${#missing[@]})); then
    echo "setup: installing ${missing[*]}" >&2
    local sudo=""
    [ "$(id -u)" -ne 0 ] && sudo="sudo"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
  fi
}

build_tree() {
  # shellcheck disable=SC2086
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release ${TEXTILE_CMAKE_ARGS:-} >/dev/null
  cmake --build "$build" -j "$(nproc)"
}

case "$verb" in
  build) install_missing; build_tree ;;
  demo) install_missing; build_tree; bash samples/demo.sh "$build/tools/textile" ;;
  test)
    install_missing; build_tree
    ctest --test-dir "$build" --output-on-failure -j "$(nproc)" --timeout 300 ;;
  *) echo "usage: bash cmake/setup.sh demo|test|build" >&2; exit 2 ;;
esac
