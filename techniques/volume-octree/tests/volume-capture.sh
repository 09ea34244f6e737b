#!/usr/bin/env bash
# treelod bake on a capture folder (cameras.json and RGBA photographs) end to end (run by ctest under
# xvfb-run): a small folder bakes to a volume-octree package that `info` describes and that renders
# through the plugin; a broken cameras.json, a missing photograph, another technique and the
# synthesis-only options exit 2 naming what is wrong and write nothing; the mesh technique and the
# CPU renderer refuse the package, saying that it was baked from photographs.
set -euo pipefail
treelod=$1; src=$2; out=$3; capture=$4
rm -rf "$out"; mkdir -p "$out"
photos="$out/birch-photos"
"$capture" write "$src/media/birch.glb" "$photos" 6 64
"$treelod" bake "$photos" --option volume-octree.levels=3 -q -o "$out/photos.treelod" > "$out/bake.txt"
grep -q "no polygons" "$out/bake.txt" || { echo "bake summary:"; cat "$out/bake.txt"; exit 1; }
"$treelod" info "$out/photos.treelod" --json > "$out/info.json"
python3 - "$out/info.json" "$photos/cameras.json" <<'EOF'
import json, sys
info = json.load(open(sys.argv[1]))
cameras = json.load(open(sys.argv[2]))
assert [c["technique"] for c in info["chunks"]] == ["meta", "reference", "volume-octree"], info["chunks"]
model = info["model"]
assert model["polygons"] is False and model["barkTriangles"] == 0 and model["leaves"] == 0, model
for key in ("min", "max"):
    for got, want in zip(model["bounds"][key], cameras["volume"][key]):
        assert abs(got - want) < 1e-5, (key, model["bounds"], cameras["volume"])
meta = info["meta"]
assert meta["source"] == "birch-photos", meta
assert meta["sourceHash"].startswith("fnv1a64:"), meta
assert meta["options"] == {"volume-octree": {"levels": "3"}}, meta
assert meta["techniques"] == ["reference", "volume-octree"], meta
octree = info["volume-octree"]
assert octree["levelCount"] == 3 and octree["cameraCount"] == 6, octree
EOF
"$treelod" info "$out/photos.treelod" | grep -q "no polygons: baked from photographs" \
  || { echo "info does not say the tree was baked from photographs"; exit 1; }
# The same folder, named with a trailing slash, gives the same bytes.
"$treelod" bake "$photos/" --technique volume-octree --option volume-octree.levels=3 -q -o "$out/again.treelod" \
  > /dev/null
cmp -s "$out/photos.treelod" "$out/again.treelod" || { echo "a second bake differs"; exit 1; }

# Rendered through the plugin: the tree covers part of the image.
"$treelod" render "$out/photos.treelod" --technique volume-octree --camera orbit:30,10,1 --size 128x128 \
  -o "$out/photos.png" > /dev/null
covered=$("$capture" coverage "$out/photos.png")
awk -v c="$covered" 'BEGIN { exit !(c > 0.03 && c < 0.95) }' \
  || { echo "photos.png: $covered of the pixels differ from the background"; exit 1; }

# expectRefused NAME NEEDLE... -- COMMAND...: exit 2, every needle in stderr, $out/NAME not written.
expectRefused() {
  local name=$1; shift
  local needles=()
  while [ "$1" != "--" ]; do needles+=("$1"); shift; done
  shift
  set +e
  "$@" 2> "$out/$name.err" > /dev/null; local code=$?
  set -e
  [ "$code" = 2 ] || { echo "$name: expected exit 2, got $code"; cat "$out/$name.err"; exit 1; }
  [ ! -e "$out/$name" ] || { echo "$name: written although refused"; exit 1; }
  for n in "${needles[@]}"; do
    grep -qF -- "$n" "$out/$name.err" || { echo "$name: error does not say '$n':"; cat "$out/$name.err"; exit 1; }
  done
}
expectRefused mesh.treelod "$photos: option --technique: 'mesh'" "can only bake volume-octree" -- \
  "$treelod" bake "$photos" --technique mesh -o "$out/mesh.treelod"
expectRefused reference.treelod "'reference'" "can only bake volume-octree" -- \
  "$treelod" bake "$photos" --technique reference -o "$out/reference.treelod"
expectRefused lodf.treelod "can only bake volume-octree" -- \
  "$treelod" bake "$photos" --technique volume-octree --technique lodf -o "$out/lodf.treelod"
for option in cameras=8 resolution=32 samplesPerPixel=4; do
  expectRefused option.treelod "option 'volume-octree.${option%%=*}'" "capture folder" -- \
    "$treelod" bake "$photos" --option "volume-octree.$option" -o "$out/option.treelod"
done
expectRefused curves.treelod "--error-curves" -- "$treelod" bake "$photos" --error-curves -o "$out/curves.treelod"

# A photograph missing: the file and its camera named.
second=$(python3 -c 'import json,sys; c=json.load(open(sys.argv[1]))["cameras"][1]; print(c["name"], c["image"])' \
  "$photos/cameras.json")
name=${second% *}; image=${second#* }
cp -r "$photos" "$out/missing"; rm "$out/missing/$image"
expectRefused missing.treelod "$out/missing/$image" "camera '$name'" "does not exist" -- \
  "$treelod" bake "$out/missing" -o "$out/missing.treelod"
# A camera with a negative focal length, and cameras.json cut short: the file (and camera) named.
cp -r "$photos" "$out/badfx"
python3 - "$out/badfx/cameras.json" <<'EOF'
import json, sys
j = json.load(open(sys.argv[1]))
j["cameras"][1]["fx"] = -5.0
json.dump(j, open(sys.argv[1], "w"))
EOF
expectRefused badfx.treelod "$out/badfx/cameras.json" "camera '$name'" "focal lengths" -- \
  "$treelod" bake "$out/badfx" -o "$out/badfx.treelod"
cp -r "$photos" "$out/cut"
head -c 200 "$photos/cameras.json" > "$out/cut/cameras.json"
expectRefused cut.treelod "$out/cut/cameras.json" "not valid JSON" -- "$treelod" bake "$out/cut" -o "$out/cut.treelod"
mkdir "$out/empty"
expectRefused empty.treelod "$out/empty/cameras.json" "does not exist" -- \
  "$treelod" bake "$out/empty" -o "$out/empty.treelod"

# What needs polygons refuses the package, naming it and saying why.
expectRefused mesh.png "photos.treelod" "baked from photographs" "technique 'mesh'" -- \
  "$treelod" render "$out/photos.treelod" --technique mesh --size 64x64 -o "$out/mesh.png"
expectRefused cpu.png "photos.treelod" "baked from photographs" -- \
  "$treelod" render "$out/photos.treelod" --renderer cpu --size 64x64 -o "$out/cpu.png"
echo "volume-octree capture CLI ok"
