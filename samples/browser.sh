#!/usr/bin/env bash
# The sample browser on the default scene (samples/scenes/single-tree.json): install what is
# missing (apt), build treelod_browser (and treelod, which measures the trade first), then run it
# in a window when $DISPLAY is set, else headless under xvfb-run, writing its screenshots into
# out/browser. Extra arguments go to the browser
# (treelod_browser --help), e.g. `samples/browser.sh --scene samples/scenes/plaza-290.json`.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${TREELOD_BUILD_DIR:-$root/build}
out=${TREELOD_BROWSER_OUT:-$root/out/browser}
"$root/.ci/deps.sh"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DTREELOD_BUILD_TESTS=OFF -DTREELOD_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build" -j"$(nproc)" --target treelod_browser treelod treelod_frames
export XDG_CACHE_HOME=${XDG_CACHE_HOME:-$build/cache}
args=("$@")
[[ " $* " == *" --scene "* ]] || args+=(--scene "$root/samples/scenes/single-tree.json")
# Budgeted auto needs the trees' error curves and this machine's level costs: a one-frame
# `treelod bench` of the scene measures both into the cache the browser reads (once per scene,
# again when the scene or treelod changed or a package it baked is gone from the cache;
# TREELOD_BROWSER_PREPARE=0 skips it, and auto then draws its fixed bands).
scene=""
for ((i = 0; i + 1 < ${#args[@]}; ++i)); do [ "${args[i]}" = --scene ] && scene=${args[i + 1]}; done
prepared="$out/prepare/$(basename "$scene" .json)"
needs_prepare() {
  local summary="$prepared/summary.json" package
  [ -s "$summary" ] && [ "$summary" -nt "$scene" ] && [ "$summary" -nt "$build/bin/treelod" ] || return 0
  # The bench's "bake" lines end "-> PACKAGE" (the cached package it baked or reused).
  while read -r package; do [ -s "$package" ] || return 0; done < <(grep -o -- '-> [^"]*' "$summary" | cut -c4-)
  return 1
}
if [ "${TREELOD_BROWSER_PREPARE:-1}" = 1 ] && needs_prepare; then
  echo "Measuring the trade on this machine (error curves, level costs) for $scene, once ..."
  run_bench=("$build/bin/treelod" bench "$scene" -o "$prepared" --frames 1 --samples 1 --size 160x90 --techniques auto -q)
  if [ -n "${DISPLAY:-}" ]; then "${run_bench[@]}"; else xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" "${run_bench[@]}"; fi
fi
if [ -n "${DISPLAY:-}" ]; then
  exec "$build/bin/treelod_browser" "${args[@]}"
fi
xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" "$build/bin/treelod_browser" --headless --screenshots "$out" "${args[@]}"
echo
echo "No display: ran the browser headless; its screenshots are in $out:"
ls -1 "$out"/*.png
