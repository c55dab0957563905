#!/usr/bin/env bash
# The README's main job on the shipped samples. Usage: bash samples/demo.sh PATH/TO/textile [OUT_DIR]
set -euo pipefail
textile="$(realpath "${1:?usage: demo.sh PATH/TO/textile [OUT_DIR]}")"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cd "$here/.."
out="${2:-out/demo}"
mkdir -p "$out"

echo "== 1. The paper's three fabrics: their moment-curvature laws (textile law)"
for m in pabst-fig8 pabst-dress pabst-interlining; do
  "$textile" law --material "samples/materials/$m.json" --kappa 0.25 0.5 1 2 --plot "$out/$m.law.png"
  echo
done

echo "== 2. Profiles of a strip at three overhangs -> the law (textile fit)"
echo "   samples/profiles/: the Fig. 8 fabric at 40, 60 and 80 mm, 0.1 mm of noise, mid-line 0.2 mm up"
"$textile" fit samples/profiles/pabst-fig8_L0{40,60,80}mm.profile.csv --gsm 200 \
  -o "$out/pabst-fig8.fitted.json" --plot "$out/pabst-fig8.fit.png"
echo
echo "   The paper's method (Clapp et al. 1990) on the same profiles:"
"$textile" fit samples/profiles/pabst-fig8_L0{40,60,80}mm.profile.csv --gsm 200 --method clapp \
  -o "$out/pabst-fig8.clapp.json" --plot "$out/pabst-fig8.clapp.png"
echo

echo "== 3. The fitted law against the truth it was made from (textile law)"
for f in samples/materials/pabst-fig8.json "$out/pabst-fig8.fitted.json" "$out/pabst-fig8.clapp.json"; do
  printf '%-36s' "$f:"
  # The law's table: column 1 is κ [1/cm], column 3 is M [gf·cm/cm].
  "$textile" law --material "$f" --kappa 0.5 1 1.5 |
    awk '$1 ~ /^[0-9.]+$/ && NF >= 6 { printf "  M(%s/cm) = %.5f", $1, $3 } END { print "  gf·cm/cm" }'
done
echo
echo "== 4. Photos -> the law: calibrate the camera on its chessboard, fit the photos (textile calibrate, fit)"
echo "   samples/photos/: rendered photos of the Fig. 8 fabric at 40, 60 and 80 mm, their board and truth"
"$textile" calibrate samples/photos/pabst-fig8.board.jpg --board 9x6 --square-mm 8.5 \
  -o "$out/pabst-fig8.rig.json"
"$textile" fit samples/photos/pabst-fig8_L0{40,60,80}mm.jpg --rig "$out/pabst-fig8.rig.json" --gsm 200 \
  -o "$out/pabst-fig8.photos.fitted.json" --plot "$out/pabst-fig8.photos.fit.png"
"$textile" extract samples/photos/pabst-fig8_L060mm.jpg --rig "$out/pabst-fig8.rig.json" \
  -o "$out/photos" --overlay-px 1000 > /dev/null
for f in samples/materials/pabst-fig8.json "$out/pabst-fig8.photos.fitted.json"; do
  printf '%-36s' "$f:"
  "$textile" law --material "$f" --kappa 0.5 1 1.5 |
    awk '$1 ~ /^[0-9.]+$/ && NF >= 6 { printf "  M(%s/cm) = %.5f", $1, $3 } END { print "  gf·cm/cm" }'
done
echo "   (overlay of the 60 mm photo: $out/photos/pabst-fig8_L060mm.overlay.png)"
echo
echo "== 5. The fitted law on the virtual ACPM200 and the Cusick drapemeter (textile acpm, drape)"
"$textile" acpm --material "$out/pabst-fig8.photos.fitted.json" -o "$out/acpm.json" --png "$out/acpm.png" |
  sed -n '4,6p;$p'
"$textile" drape --material "$out/pabst-fig8.photos.fitted.json" --seams weft \
  -o "$out/drape.json" --png "$out/drape.png" 2>/dev/null | grep -E '^(scene|drape coefficient|nodes):'
echo
echo "== 6. Closing the loop: photos -> fit -> the same cantilevers simulated -> compared (textile validate)"
"$textile" validate samples/photos/pabst-fig8_L0{40,60,80}mm.jpg --rig "$out/pabst-fig8.rig.json" \
  --gsm 200 -o "$out/validate" 2>/dev/null
echo
echo "== 7. A specimen series: warp, weft, face, back -> statistics, a lab report (textile batch, report)"
echo "   samples/series/manifest.csv: two fabrics, seven specimens (six of profiles, one photo)"
"$textile" batch samples/series/manifest.csv -o "$out/series" --jobs 2 2>/dev/null
awk -F, '{ printf "   %-12s %-9s %-3s %-13s %-13s %-13s %-13s %s\n", $1, $2, $3, $5, $6, $17, $20, $26 }' \
  "$out/series/summary.csv"
"$textile" report "$out/series" -o "$out/series/report.html"
echo
echo "Pictures and outputs: $out"
