#!/usr/bin/env bash
# The bench's GPU runs in three steps, for a session lent the device (../shared/gpu/README.md).
# The device gives 15 minutes in all (start-up included) and 10 minutes a command, so everything
# that can run here does: baking, bundling, the image metrics and the plots.
#
#   bench/gpu-run.sh prepare     here: bake both scenes (treelod bench --bake-only) into .gpu/,
#                                bundle treelod_frames (OGRE + the runtime only) with the shared
#                                bundle.sh, copy OGRE's ShadowVolume media, check the carry size
#   device call (one `run`, carry [".gpu/bundle.tar.xz", ".gpu/on-device.sh", ".gpu/payload.tar.xz"]):
#       bash .gpu/on-device.sh .gpu/bundle.tar.xz bash bench/gpu-run.sh device
#                                there: renders and times every scene's runs (reference, the three
#                                floors, TECHNIQUES) into $OUT/SCENE, plus an RSS-only run of
#                                flythrough-10k; packs them into $OUT/results.tar.xz (the device
#                                returns at most 8 files)
#   bench/gpu-run.sh finish DIR  here: DIR = the run's files_at; FLIP, RMSE, temporal noise, plots
#                                and summary.json into out/gpu/SCENE (treelod bench --frames-from)
#
# Settings (environment; prepare writes them to .gpu/settings.env and the other steps read them):
#   SCENES="flythrough-10k forest-100k" TECHNIQUES=auto FRAMES=240 SIZE=1920x1080 SCALE=1 SAMPLES=6
#   DEVICE_SAMPLES=$SAMPLES: images saved on the device; 0 = timings only (1920x1080 PNGs are ~3 MB
#   each and the device returns 64 MiB at most)
#   REFERENCE_BUDGET=3e8 (triangles of a timed reference frame) SCENE_TIMEOUT=200 (s a scene, on the device)
#   SHADOW_LOD_BIAS_TRY=0.25 (forest-100k's auto once more with coarser casters, timings only; "" skips)
# Trying the device step here (llvmpipe), small:
#   SCALE=0.01 FRAMES=6 SIZE=320x180 SAMPLES=1 bench/gpu-run.sh prepare
#   __GLX_VENDOR_LIBRARY_NAME=mesa OUT=/tmp/gpu-out bash .gpu/on-device.sh .gpu/bundle.tar.xz \
#       bash bench/gpu-run.sh device
#   bench/gpu-run.sh finish /tmp/gpu-out
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
gpu=.gpu
step=${1:-}

fail() { echo "gpu-run: $*" >&2; exit 2; }

case $step in
prepare)
  : "${SCENES:=flythrough-10k forest-100k}" "${TECHNIQUES:=auto}" "${FRAMES:=240}" "${SIZE:=1920x1080}" "${SCALE:=1}" "${SAMPLES:=6}"
  : "${DEVICE_SAMPLES:=$SAMPLES}" "${REFERENCE_BUDGET:=3e8}" "${SCENE_TIMEOUT:=200}" "${SHADOW_LOD_BIAS_TRY=0.25}"
  build=${TREELOD_BUILD_DIR:-$root/build}
  for b in treelod treelod_frames; do
    [ -x "$build/bin/$b" ] || fail "$build/bin/$b is missing: build first (tests/run.sh or cmake --build build)"
  done
  "$root/.ci/deps.sh" --with-gpu-bundle
  shared=${TREELOD_SHARED_DIR:-$root/../shared}
  [ -x "$shared/gpu/bundle.sh" ] || fail "$shared/gpu/bundle.sh is missing (set TREELOD_SHARED_DIR)"
  mkdir -p "$gpu/runs"
  rm -rf "$gpu/runs"/*
  for s in $SCENES; do
    [ -f "samples/scenes/$s.json" ] || fail "samples/scenes/$s.json: no such scene"
    mkdir -p "$gpu/runs/$s"
    echo "gpu-run: baking $s"
    # The bench bakes into .gpu/cache and prints the treelod_frames command of this very run.
    "$build/bin/treelod" bench "samples/scenes/$s.json" -o "$gpu/runs/$s" --cache "$gpu/cache" --bake-only \
      --techniques "$TECHNIQUES" --lod-bias 1 --frames "$FRAMES" --size "$SIZE" --scale "$SCALE" --samples "$SAMPLES" \
      --reference-budget "$REFERENCE_BUDGET" >"$gpu/runs/$s/command.txt"
  done
  cat >"$gpu/settings.env" <<EOF
SCENES="$SCENES" TECHNIQUES=$TECHNIQUES FRAMES=$FRAMES SIZE=$SIZE SCALE=$SCALE SAMPLES=$SAMPLES DEVICE_SAMPLES=$DEVICE_SAMPLES REFERENCE_BUDGET=$REFERENCE_BUDGET SCENE_TIMEOUT=$SCENE_TIMEOUT SHADOW_LOD_BIAS_TRY=$SHADOW_LOD_BIAS_TRY
EOF
  # Texture shadows need OGRE's ShadowVolume programs; the bundle holds no OGRE media.
  rm -rf "$gpu/ogre-media"; mkdir -p "$gpu/ogre-media"
  cp -r /usr/share/OGRE/Media/ShadowVolume "$gpu/ogre-media/"
  # TreeLod's media as the build tree merges them (materials/ and every technique's media/).
  rm -rf "$gpu/media"; cp -rL "$build/share/TreeLod/media" "$gpu/media"
  stale=0
  for f in "$build/bin/treelod_frames" "$build"/lib/*.so; do
    if [ "$f" -nt "$gpu/bundle.tar.xz" ]; then stale=1; fi
  done
  if [ ! -f "$gpu/bundle.tar.xz" ] || [ $stale = 1 ]; then
    echo "gpu-run: bundling treelod_frames (~2.5 min)"
    "$shared/gpu/bundle.sh" "$gpu" "$build/bin/treelod_frames" >/dev/null
    # ICU's data (libicudata, 7.5 MB packed) is in the closure only through LLVM's libxml2 (Mesa's
    # swrast for Xvfb's GLX) and is never read there: nothing converts text encodings. A stub
    # with its one symbol keeps the device call under 64 MiB; ICU reports missing data if used.
    stage=$(mktemp -d)
    tar -C "$stage" -xJf "$gpu/bundle.tar.xz"
    for icu in "$stage"/lib/libicudata.so.*; do
      [ -f "$icu" ] || continue
      sym=$(nm -D --defined-only "$icu" | awk '/_dat$/ {print $3}')
      echo "const char $sym[16] = {0};" >"$stage/icu-stub.c"
      cc -shared -o "$icu" "$stage/icu-stub.c" -Wl,-soname,"$(basename "$icu")"
      rm "$stage/icu-stub.c"
      echo "gpu-run: $(basename "$icu") replaced by a stub exporting $sym (~2.5 min to pack again)"
      XZ_OPT=-9T0 tar -C "$stage" -cJf "$gpu/bundle.tar.xz" .
    done
    rm -rf "$stage"
  fi
  # What travels: the tracked tree, the bundle and one compressed payload (the package lists, the
  # packages they name, TreeLod's and OGRE's media, the settings); the device takes 64 MiB in all.
  payload=$(python3 - "$gpu" <<'EOF'
import json, os, sys
gpu = sys.argv[1]
files = {"settings.env", "ogre-media", "media"}
for s in sorted(os.listdir(os.path.join(gpu, "runs"))):
    base = os.path.join(gpu, "runs", s)
    files.update(os.path.relpath(os.path.join(base, f), gpu) for f in ("packages.json", "command.txt"))
    for e in json.load(open(os.path.join(base, "packages.json")))["packages"]:
        files.add(os.path.relpath(os.path.normpath(os.path.join(base, e["path"])), gpu))
print("\n".join(sorted(files)))
EOF
)
  # shellcheck disable=SC2086 # one path a line, none with spaces (cache names are hashes)
  tar -C "$gpu" -cJf "$gpu/payload.tar.xz.tmp" $payload && mv "$gpu/payload.tar.xz.tmp" "$gpu/payload.tar.xz"
  tracked=$(git ls-files -z | xargs -0 du -cb 2>/dev/null | tail -n 1 | cut -f1)
  carried=$(du -cb "$gpu/bundle.tar.xz" "$gpu/on-device.sh" "$gpu/payload.tar.xz" | tail -n 1 | cut -f1)
  total=$(( (tracked + carried + 1048575) / 1048576 ))
  echo "gpu-run: payload of $(echo "$payload" | grep -c '\.treelod$') packages; tracked files $((tracked / 1048576)) MiB" \
       "+ bundle and payload $((carried / 1048576)) MiB = $total MiB (limit 64)"
  [ "$total" -le 64 ] || fail "the device call would carry $total MiB, over 64 MiB"
  echo "gpu-run: ready. Device call (timeout_s 600):"
  echo "  run command: bash .gpu/on-device.sh .gpu/bundle.tar.xz bash bench/gpu-run.sh device"
  echo "  carry: [\".gpu/bundle.tar.xz\", \".gpu/on-device.sh\", \".gpu/payload.tar.xz\"]"
  ;;

device)
  # The payload unpacks over .gpu (package lists, packages, TreeLod's and OGRE's media, the settings).
  [ -f "$gpu/payload.tar.xz" ] && tar -C "$gpu" -xJf "$gpu/payload.tar.xz"
  [ -f "$gpu/settings.env" ] || fail "$gpu/settings.env is missing: run bench/gpu-run.sh prepare here, carry .gpu/payload.tar.xz"
  eval "$(cat "$gpu/settings.env")"
  : "${GB:?run through .gpu/on-device.sh (GB is the unpacked bundle)}" "${OUT:?OUT is the folder that comes back}"
  export TREELOD_MATERIALS_DIR=$root/$gpu/media TREELOD_OGRE_MEDIA_DIR=$root/$gpu/ogre-media
  mkdir -p "$OUT"
  { "$GB/bin/glxinfo" -B 2>&1 | grep -E "OpenGL (renderer|version)" || true; nproc; } | tee "$OUT/device.txt"
  # The command the prepare step printed, with this machine's paths: the bundle's binary and
  # the output under $OUT; set_arg replaces an option's value.
  load_command() {
    eval "args=($(cat "$gpu/runs/$1/command.txt"))"
    args[0]=$GB/bin/treelod_frames
    set_arg -o "$OUT/$2"
  }
  set_arg() {
    local i
    for i in "${!args[@]}"; do
      if [ "${args[$i]}" = "$1" ]; then args[$((i + 1))]=$2; fi
    done
  }
  for s in $SCENES; do
    load_command "$s" "$s"
    set_arg --samples "${DEVICE_SAMPLES:-$SAMPLES}"
    start=$(date +%s)
    echo "gpu-run: $s: ${args[*]:1}"
    code=0
    timeout "$SCENE_TIMEOUT" "${args[@]}" -q >"$OUT/$s.log" 2>&1 || code=$?
    echo "gpu-run: $s: exit $code after $(( $(date +%s) - start )) s" | tee -a "$OUT/device.txt"
    tail -n 5 "$OUT/$s.log"
  done
  # Resident memory of the 10k scene alone (no reference, no floors in the process).
  if [[ " $SCENES " == *" flythrough-10k "* ]]; then
    load_command flythrough-10k rss-flythrough-10k
    set_arg --samples 1
    code=0
    timeout 60 "${args[@]}" -q --skip-comparisons >"$OUT/rss.log" 2>&1 || code=$?
    echo "gpu-run: rss-flythrough-10k: exit $code" | tee -a "$OUT/device.txt"
  fi
  # The worst frames under LiSPSM are the shadow texture's fill by the trees nearest the viewer:
  # the same path with coarser casters (Forest::setShadowLodBias).
  if [ -n "${SHADOW_LOD_BIAS_TRY:-}" ] && [[ " $SCENES " == *" forest-100k "* ]]; then
    load_command forest-100k "shadow-lod-bias-forest-100k"
    set_arg --samples 1
    set_arg --shadow-lod-bias "$SHADOW_LOD_BIAS_TRY"
    code=0
    timeout 90 "${args[@]}" -q --skip-comparisons >"$OUT/shadow-lod-bias.log" 2>&1 ||
      code=$?
    echo "gpu-run: shadow-lod-bias-forest-100k ($SHADOW_LOD_BIAS_TRY): exit $code" | tee -a "$OUT/device.txt"
  fi
  # One archive of everything but device.txt (the device returns at most 8 files).
  (cd "$OUT" && find . -mindepth 1 -maxdepth 1 ! -name device.txt -printf '%P\n' | tar -cJf results.tar.xz -T - &&
    find . -mindepth 1 -maxdepth 1 ! -name device.txt ! -name results.tar.xz -exec rm -rf {} +)
  ls -l "$OUT"
  ;;

finish)
  from=${2:-}
  [ -n "$from" ] && [ -d "$from" ] || fail "usage: bench/gpu-run.sh finish DIR (the device run's files_at)"
  [ -f "$gpu/settings.env" ] || fail "$gpu/settings.env is missing: the prepare step's settings"
  eval "$(cat "$gpu/settings.env")"
  build=${TREELOD_BUILD_DIR:-$root/build}
  cat "$from/device.txt" 2>/dev/null || true
  if [ -f "$from/results.tar.xz" ]; then
    mkdir -p out/gpu/device && tar -C out/gpu/device -xJf "$from/results.tar.xz"
    from=out/gpu/device
  fi
  for s in $SCENES; do
    [ -f "$from/$s/timings.json" ] || { echo "gpu-run: $s: no timings.json in $from/$s (see $from/$s.log)"; continue; }
    mkdir -p "out/gpu/$s"
    "$build/bin/treelod" bench "samples/scenes/$s.json" -o "out/gpu/$s" --cache "$gpu/cache" --frames-from "$from/$s" \
      --techniques "$TECHNIQUES" --lod-bias 1 --frames "$FRAMES" --size "$SIZE" --scale "$SCALE" --samples "$SAMPLES" \
      --reference-budget "$REFERENCE_BUDGET" -q
    echo "gpu-run: $s: out/gpu/$s/summary.json"
    python3 - "out/gpu/$s/summary.json" <<'EOF'
import json, sys
s = json.load(open(sys.argv[1]))
print(f"{s['scene']} {s['resolution'][0]}x{s['resolution'][1]}, {s['frames']} frames")
floor_names = sorted({name for r in s["results"] for name in r.get("ratioToFloors", {})})
print(" | ".join(["run", "trees", "median ms", "p95/median", "worst ms"] + ["x " + n for n in floor_names]
                 + ["FLIP", "RSS MiB"]))
for r in s["results"]:
    ms, floors, flip = r.get("frameMs", {}), r.get("ratioToFloors", {}), r.get("flip", {})
    f = lambda v, d=2: "-" if v is None else f"{v:.{d}f}"
    print(" | ".join([r["technique"], str(r["trees"]), f(ms.get("median")), f(r.get("p95OverMedian")),
                      f(r.get("worstFrame", {}).get("frameMs"))] + [f(floors.get(n)) for n in floor_names]
                     + [f(flip.get("mean"), 4), f(r.get("rssMiB"), 0)]))
EOF
  done
  if [ -f "$from/rss-flythrough-10k/timings.json" ]; then
    python3 -c 'import json,sys; [print("resident memory of flythrough-10k alone,", r["technique"], r["trees"], "trees:",
      round(r["rssMiB"]), "MiB, peak", round(r["peakRssMiB"]), "MiB") for r in json.load(open(sys.argv[1]))["runs"]]' \
      "$from/rss-flythrough-10k/timings.json"
  fi
  if [ -f "$from/shadow-lod-bias-forest-100k/timings.json" ]; then
    python3 - "$from/shadow-lod-bias-forest-100k/timings.json" <<'EOF'
import json, math, statistics, sys
t = json.load(open(sys.argv[1]))
for r in t["runs"]:
    ms = sorted(f["frameMs"] for f in r["frames"] if "frameMs" in f)
    med, p95 = statistics.median(ms), ms[min(len(ms), math.ceil(0.95 * len(ms))) - 1]  # as treelod bench
    print(f"forest-100k {r['technique']} with shadow LoD bias {t.get('shadowLodBias')}: median {med:.2f} ms, "
          f"p95/median {p95 / med:.2f}, worst {ms[-1]:.2f} ms")
EOF
  fi
  ;;

*)
  sed -n 2,25p "$0"
  exit 2
  ;;
esac
