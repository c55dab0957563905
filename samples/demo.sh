#!/usr/bin/env bash
# The README's main job on the shipped samples. Usage: bash samples/demo.sh PATH/TO/textile [OUT_DIR]
set -euo pipefail
textile="$(realpath "${1:?usage: demo.sh PATH/TO/textile [OUT_DIR]}")"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
out="${2:-$here/../out/demo}"
mkdir -p "$out"
cd "$here/.."

echo "== 1. The paper's three fabrics: the moment-curvature law (textile law)"
for m in pabst-fig8 pabst-dress pabst-interlining; do
  "$textile" law --material "samples/materials/$m.json" --kappa 0.25 0.5 1 2 --plot "$out/$m.law.png"
  echo
done
echo "Pictures and outputs: $out"
