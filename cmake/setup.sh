#!/usr/bin/env bash
# One entry point for a fresh Debian 12 machine (as root) or an existing one:
#   bash cmake/setup.sh demo   install what is missing, build, run the demo on samples/
#   bash cmake/setup.sh test   install what is missing, build, run the whole test suite
#   bash cmake/setup.sh build  install what is missing, build only
#   bash cmake/setup.sh sanitize  install, build with ASan + UBSan (build-asan/), run the whole suite
# Build tree: ${TEXTILE_BUILD_DIR:-build} (sanitize: ${TEXTILE_BUILD_DIR:-build-asan}).
# Extra CMake flags: ${TEXTILE_CMAKE_ARGS}.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$here"
verb="${1:-demo}"
if [ "$verb" = sanitize ]; then
  build="${TEXTILE_BUILD_DIR:-build-asan}"
else
  build="${TEXTILE_BUILD_DIR:-build}"
fi

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
  # ccache, where the machine has it, keeps rebuilds of unchanged files out of a run's time.
  local launcher=""
  command -v ccache >/dev/null 2>&1 && launcher="-DCMAKE_CXX_COMPILER_LAUNCHER=ccache"
  # shellcheck disable=SC2086
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release $launcher ${TEXTILE_CMAKE_ARGS:-} >/dev/null
  cmake --build "$build" -j "$(nproc)"
}

case "$verb" in
  build) install_missing; build_tree ;;
  demo) install_missing; build_tree; bash samples/demo.sh "$build/tools/textile" ;;
  test)
    install_missing; build_tree
    ctest --test-dir "$build" --output-on-failure -j "$(nproc)" --timeout 300 ;;
  sanitize)
    # Every finding fails the run: the build has -fno-sanitize-recover=all, ASan and UBSan halt
    # on the first error, LeakSanitizer reports leaks at exit (the tests set its suppressions,
    # tests/lsan.supp). The tests' child `textile` processes inherit these options.
    install_missing
    TEXTILE_CMAKE_ARGS="-DTEXTILE_SANITIZE=address;undefined ${TEXTILE_CMAKE_ARGS:-}" build_tree
    export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1"
    export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
    ctest --test-dir "$build" --output-on-failure -j "$(nproc)" --timeout 900 ;;
  *) echo "usage: bash cmake/setup.sh demo|test|build|sanitize" >&2; exit 2 ;;
esac
