#!/usr/bin/env bash
# treelod bake/render --technique lodf end to end (run by ctest under xvfb-run):
# bake a package, see the chunk in `info`, render it at two distances and a fixed leaf
# count, and check that bad input exits 2 and writes nothing.
set -euo pipefail
treelod=$1; src=$2; out=$3
rm -rf "$out"; mkdir -p "$out"
"$treelod" bake "$src/media/oak.glb" --technique lodf -q -o "$out/oak.treelod"
"$treelod" info "$out/oak.treelod" --json > "$out/info.json"
grep -q '"lodf"' "$out/info.json" || { echo "no lodf chunk in info"; exit 1; }
grep -q '"reference"' "$out/info.json" || { echo "no reference chunk in info"; exit 1; }
grep -q '"eq9Words"' "$out/info.json" || { echo "no lodf storage summary in info"; exit 1; }
"$treelod" render "$out/oak.treelod" --technique lodf --camera orbit:30,10,1 --size 128x128 -o "$out/near.png"
"$treelod" render "$out/oak.treelod" --technique lodf --camera orbit:30,10,6 --size 128x128 -o "$out/far.png"
"$treelod" render "$src/media/conifer.glb" --technique lodf --leaves 200 --size 128x128 -o "$out/conifer200.png"
# A 100k-leaf generated tree (32-bit index ranges), baked and rendered from the package.
"$treelod" generate --preset oak --seed 3 --leaves 100000 --texture-size 64 -o "$out/oak100k.glb" > /dev/null
"$treelod" bake "$out/oak100k.glb" --technique lodf -q -o "$out/oak100k.treelod"
"$treelod" render "$out/oak100k.treelod" --technique lodf --camera orbit:30,10,2 --size 128x128 \
  --supersample 1 -o "$out/oak100k.png"
for f in near far conifer200 oak100k; do [ -s "$out/$f.png" ] || { echo "$f.png missing"; exit 1; }; done

# A package without the lodf chunk: exit 2, a message naming the chunk, no output.
"$treelod" bake "$src/media/birch.glb" -q -o "$out/birch-ref.treelod"
set +e
"$treelod" render "$out/birch-ref.treelod" --technique lodf -o "$out/bad.png" 2> "$out/bad.txt"; code=$?
set -e
[ "$code" = 2 ] || { echo "expected exit 2, got $code"; exit 1; }
grep -q "lodf" "$out/bad.txt" || { echo "error does not name the chunk:"; cat "$out/bad.txt"; exit 1; }
[ ! -e "$out/bad.png" ] || { echo "bad.png written"; exit 1; }
set +e
"$treelod" bake "$src/media/birch.glb" --technique nosuch -o "$out/bad.treelod" 2> "$out/bad2.txt"; code=$?
set -e
[ "$code" = 2 ] && [ ! -e "$out/bad.treelod" ] || { echo "unknown technique not refused"; exit 1; }
# Bake options: --option lodf.clusterSize=16 gives more clusters than the default 64 (recorded in the
# package's meta); an undeclared option, a value out of range or a technique not being baked exit 2
# naming the option, and write nothing.
"$treelod" bake "$src/media/oak.glb" --technique lodf --option lodf.clusterSize=16 -q -o "$out/oak16.treelod"
clusters() { "$treelod" info "$1" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["lodf"]["clusters"])'; }
[ "$(clusters "$out/oak16.treelod")" -gt "$(clusters "$out/oak.treelod")" ] \
  || { echo "clusterSize=16 did not give more clusters"; exit 1; }
"$treelod" info "$out/oak16.treelod" --json | grep -q '"clusterSize"' || { echo "options not recorded in meta"; exit 1; }
for bad in lodf.nosuch=1 lodf.clusterSize=0 impostor.resolution=64 lodf.clusterSize; do
  set +e
  "$treelod" bake "$src/media/oak.glb" --technique lodf --option "$bad" -q -o "$out/badopt.treelod" 2> "$out/badopt.txt"
  code=$?
  set -e
  [ "$code" = 2 ] && [ ! -e "$out/badopt.treelod" ] || { echo "--option $bad not refused"; exit 1; }
  grep -q "option" "$out/badopt.txt" || { echo "--option $bad: error does not name the option:"; cat "$out/badopt.txt"; exit 1; }
done
# Render options are the techniques' own (TechniqueRoles::parameters): --level is not lodf's, and
# --leaves takes a number; both exit 2 naming what is wrong, and write nothing.
set +e
"$treelod" render "$out/oak.treelod" --technique lodf --level 1 --size 64x64 -o "$out/badparam.png" 2> "$out/badparam.txt"
code=$?
"$treelod" render "$out/oak.treelod" --technique lodf --leaves many --size 64x64 -o "$out/badleaves.png" 2> "$out/badleaves.txt"
leavesCode=$?
set -e
[ "$code" = 2 ] && [ ! -e "$out/badparam.png" ] || { echo "--level on lodf not refused"; exit 1; }
grep -qF -- "--level: technique 'lodf' has no such parameter (techniques that take it: billboard-cloud" "$out/badparam.txt" \
  || { echo "--level on lodf: error does not say whose it is:"; cat "$out/badparam.txt"; exit 1; }
[ "$leavesCode" = 2 ] && [ ! -e "$out/badleaves.png" ] || { echo "--leaves many not refused"; exit 1; }
grep -qF "parameter 'leaves'" "$out/badleaves.txt" || { echo "--leaves many: error:"; cat "$out/badleaves.txt"; exit 1; }
echo "lodf CLI ok"
