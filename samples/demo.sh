#!/usr/bin/env bash
# The main job: install what is missing, build, and render the bundled trees headless
# through the Ogre plugin (the polygonal reference and LoDF) and through the CPU reference
# renderer into PNGs.
# Also billboard clouds with multi-layered indirect texturing (García et al. 2007) close up and far,
# and the classic billboard cloud at the same memory.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${TREELOD_BUILD_DIR:-$root/build}
out=${TREELOD_DEMO_OUT:-$root/out/demo}
"$root/.ci/deps.sh"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DTREELOD_BUILD_TESTS=OFF -DTREELOD_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build" -j"$(nproc)" --target treelod
mkdir -p "$out"
export XDG_CACHE_HOME=${XDG_CACHE_HOME:-$build/cache}
run() { xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" "$@"; }
for tree in "$root"/media/*.glb; do
  name=$(basename "$tree" .glb)
  for view in "front:orbit:0,8,1.0" "side:orbit:90,20,1.0"; do
    label=${view%%:*}; camera=${view#*:}
    run "$build/bin/treelod" render "$tree" --technique mesh --camera "$camera" --size 512x512 \
      -o "$out/$name-$label-ogre.png"
  done
  "$build/bin/treelod" render "$tree" --renderer cpu --camera "orbit:0,8,1.0" --size 512x512 \
    -o "$out/$name-front-cpu.png"
  # LoDF (Rebollo et al. 2006): the full tree close up, and a quarter of the leaves with shadows.
  run "$build/bin/treelod" render "$tree" --technique lodf --camera "orbit:0,8,1.0" --size 512x512 \
    -o "$out/$name-front-lodf.png"
  leaves=$("$build/bin/treelod" info "$tree" --json | sed -n 's/.*"leaves": \([0-9]*\).*/\1/p' | head -n 1)
  run "$build/bin/treelod" render "$tree" --technique lodf --leaves $((leaves / 4)) --shadows \
    --camera "orbit:0,8,1.0" --size 512x512 -o "$out/$name-front-lodf-quarter-shadows.png"
  # Billboard clouds (García et al. 2007): bake both clouds once, render close up, far, and the
  # classic one.
  "$build/bin/treelod" bake "$tree" --technique billboard-cloud --technique classic-billboard-cloud -q \
    -o "$out/$name.treelod"
  run "$build/bin/treelod" render "$out/$name.treelod" --technique billboard-cloud --camera "orbit:0,8,1.0" \
    --size 512x512 -o "$out/$name-front-billboard-cloud.png"
  run "$build/bin/treelod" render "$out/$name.treelod" --technique billboard-cloud --camera "orbit:0,8,6.0" \
    --size 512x512 -o "$out/$name-far-billboard-cloud.png"
  run "$build/bin/treelod" render "$out/$name.treelod" --technique classic-billboard-cloud \
    --camera "orbit:0,8,1.0" --size 512x512 -o "$out/$name-front-classic-billboard-cloud.png"
done
echo
echo "Rendered the bundled trees into $out:"
ls -1 "$out"/*.png
