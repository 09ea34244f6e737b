#!/usr/bin/env bash
# treelod_corpus_study end to end (run by ctest under xvfb-run): two small trees (one with a leaf
# atlas under three leaf materials), two techniques, 128 px. Checks the outputs agree: one CSV row
# per tree, technique and view, finite metrics in range, the Markdown table, a worst-case picture
# per technique; a bad tree spec, option or parameter exits 2 naming it, before any bake.
set -euo pipefail
study=$1; src=$2; out=$3
rm -rf "$out"; mkdir -p "$out"
fail() { echo "corpus study test: $*"; exit 1; }
cd "$src"
"$study" --trees generated:birch:300 generated:oak:400:4:3 --techniques lodf impostor --size 128 \
  --supersample 1 --out "$out/run" > "$out/stdout.txt" 2> "$out/stderr.txt" || fail "exit $? ($(tail -1 "$out/stderr.txt"))"
csv="$out/run/error.csv"
[ "$(head -1 "$csv")" = "tree,technique,view,treePx,flip,rmse,coverage,bytes" ] || fail "CSV header: $(head -1 "$csv")"
[ "$(($(wc -l < "$csv") - 1))" = 16 ] || fail "$csv: $(($(wc -l < "$csv") - 1)) rows, expected 2 trees x 2 techniques x 4 views"
python3 - "$csv" <<'PY' || fail "metrics out of range"
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
for r in rows:
    flip, rmse, cov, px = float(r["flip"]), float(r["rmse"]), float(r["coverage"]), int(r["treePx"])
    assert 0 <= flip <= 1 and 0 <= rmse <= 1 and 0.3 < cov < 2 and px > 0 and int(r["bytes"]) > 1000, r
# The tree is about 90 % of the view near (leaves and perspective add a little) and 30 px far;
# lodf draws every leaf near.
for r in rows:
    if r["view"] == "near": assert abs(int(r["treePx"]) - 115) <= 14, r
    if r["view"] == "far": assert abs(int(r["treePx"]) - 30) <= 4, r
    if r["view"] == "near" and r["technique"] == "lodf": assert float(r["flip"]) < 0.01, r
PY
grep -q "| generated:oak:400:4:3 | impostor |" "$out/run/summary.md" || fail "summary.md lacks the atlas tree's impostor row"
for t in lodf impostor; do
  head -c 8 "$out/run/worst-$t.png" | od -An -tx1 | grep -q "89 50 4e 47" || fail "worst-$t.png is not a PNG"
done
set +e
"$study" --trees generated:nosuchpreset --out "$out/bad" > /dev/null 2> "$out/bad.txt"; rc=$?
set -e
[ $rc = 2 ] || fail "a bad tree spec exited $rc"
grep -q "tree 'generated:nosuchpreset'" "$out/bad.txt" || fail "the error does not name the tree: $(cat "$out/bad.txt")"
# Bad --option / --param: refused before any tree is baked, naming the argument.
for arg in "--option lodf.noSuchOption=1" "--param impostor.x=1" "--param garbage"; do
  set +e
  # shellcheck disable=SC2086
  "$study" --trees generated:birch:300 --techniques lodf $arg --out "$out/badarg" > "$out/badarg.txt" 2>&1; rc=$?
  set -e
  [ $rc = 2 ] || fail "'$arg' exited $rc"
  grep -q -- "${arg%% *}" "$out/badarg.txt" || fail "'$arg': the error does not name it: $(cat "$out/badarg.txt")"
  ! grep -q "baking" "$out/badarg.txt" || fail "'$arg': baked before refusing it"
done
echo "corpus study test: ok"
