#!/usr/bin/env bash
# treelod bench end to end (run by ctest under xvfb-run): single-tree.json on a short path and
# table2.json scaled down with two tree counts. Checks that the outputs exist and agree with each
# other (row counts, techniques, biases, tree counts, the plots' CSV data; PNG plots only where
# python3 has matplotlib to draw them), not the timings. A bad script exits 2 naming file, line
# and column, and writes nothing.
set -euo pipefail
treelod=$1; src=$2; out=$3
rm -rf "$out"; mkdir -p "$out"
# The oak's package: the tree's test cache, where ctest's browser test (which runs first) has baked
# it; without one, a cache in $out.
shared=${XDG_CACHE_HOME:-$out}/treelod
# A cache that starts empty, for what the bake cache reports it built.
cache="$out/cache"

fail() { echo "bench test: $*"; exit 1; }
png() { [ -s "$1" ] && head -c 8 "$1" | od -An -tx1 | grep -q "89 50 4e 47" || fail "$1 is not a PNG"; }
# The plots' data: a CSV with a header and `want` rows, listed in plots.json; its PNG when drawn.
plotted=0; python3 -c 'import matplotlib' 2>/dev/null && plotted=1
plot() {
  local dir=$1 name=$2 want=$3
  [ -s "$dir/$name.csv" ] || fail "$dir/$name.csv missing"
  local rows=$(($(wc -l < "$dir/$name.csv") - 1))
  [ "$rows" = "$want" ] || fail "$name.csv has $rows rows, expected $want"
  grep -q "\"$name.csv\"" "$dir/plots.json" || fail "plots.json does not list $name.csv"
  if [ $plotted = 1 ]; then png "$dir/$name.png"; fi
}
# The number of results in a summary.json.
results() { python3 -c 'import json, sys; print(len(json.load(open(sys.argv[1]))["results"]))' "$1"; }
# The Pareto front of DIR/summary.json recomputed from its results' trade points, per tree count:
# onParetoFront on every result with both numbers, the front sorted by time and dominated by no
# result, autoOnFront and dominatedBy as the results say, the trade CSVs' on_front the same. The
# checker is checked too: a copy where one result dominates the fastest front member must fail.
# With REPORT (the bench's stdout), its "Pareto front" lines name the same fronts.
pareto() {
  python3 - "$@" <<'EOF'
import copy, csv, json, os, sys

def point(r):
    t = r.get("trade") or {}
    return t.get("medianFrameMs"), t.get("meanFlip")

def dominates(a, b):
    return a[0] <= b[0] and a[1] <= b[1] and (a[0] < b[0] or a[1] < b[1])

def key(r):
    return r["technique"], r["lodBias"]

def problems(summary):
    out = []
    pareto = {p["trees"]: p for p in summary.get("pareto", [])}
    for trees in sorted({r["trees"] for r in summary["results"]}):
        rs = [r for r in summary["results"] if r["trees"] == trees]
        measured = [r for r in rs if None not in point(r)]
        if trees not in pareto:
            out.append(f"{trees} trees: no pareto object")
            continue
        p = pareto[trees]
        for r in rs:
            want = not any(dominates(point(o), point(r)) for o in measured) if r in measured else None
            if r.get("onParetoFront", "missing") != want:
                out.append(f"{trees} trees: {key(r)} onParetoFront {r.get('onParetoFront', 'missing')}, recomputed {want}")
        front = p["front"]
        times = [f["medianFrameMs"] for f in front]
        if not front:
            out.append(f"{trees} trees: empty front")
        if times != sorted(times):
            out.append(f"{trees} trees: front not sorted by time: {times}")
        byKey = {key(r): r for r in rs}
        for f in front:
            r = byKey.get(key(f))
            if r is None or point(r) != (f["medianFrameMs"], f["meanFlip"]):
                out.append(f"{trees} trees: front member {key(f)} is not a result's trade point")
                continue
            for o in measured:
                if dominates(point(o), point(r)):
                    out.append(f"{trees} trees: front member {key(f)} dominated by {key(o)}")
        if sorted(key(f) for f in front) != sorted(key(r) for r in rs if r.get("onParetoFront")):
            out.append(f"{trees} trees: front and onParetoFront disagree")
        autos = [r for r in measured if r["technique"].startswith("auto")]
        want = any(r.get("onParetoFront") for r in autos) if autos else None
        if p.get("autoOnFront", "missing") != want:
            out.append(f"{trees} trees: autoOnFront {p.get('autoOnFront', 'missing')}, results say {want}")
        if sorted(key(d) for d in p["dominatedBy"]) != sorted(key(r) for r in autos if r.get("onParetoFront") is False):
            out.append(f"{trees} trees: dominatedBy does not list the auto runs off the front")
        for d in p["dominatedBy"]:
            mine = point(byKey[key(d)]) if key(d) in byKey else (None, None)
            by = [point(byKey[key(b)]) for b in d["by"] if key(b) in byKey]
            if not by or len(by) != len(d["by"]) or not all(None not in mine and dominates(b, mine) for b in by):
                out.append(f"{trees} trees: {key(d)} dominatedBy lists a run that does not dominate it")
    return out

directory = sys.argv[1]
summary = json.load(open(os.path.join(directory, "summary.json")))
fail = problems(summary)
counts = sorted({r["trees"] for r in summary["results"]})
for p in summary.get("pareto", []):
    trees = p["trees"]
    name = f"trade-{trees}.csv" if len(counts) > 1 else "trade.csv"
    front = {key(f) for f in p["front"]}
    for row in csv.DictReader(open(os.path.join(directory, name), newline="")):
        want = "1" if (row["series"], float(row["lod_bias"])) in front else "0"
        if row.get("on_front") != want:
            fail.append(f"{name}: {row['series']} at {row['lod_bias']}: on_front {row.get('on_front')}, expected {want}")
    if p["front"]:
        broken = copy.deepcopy(summary)
        first = p["front"][0]
        other = next((r for r in broken["results"] if r["trees"] == trees and key(r) != key(first)), None)
        if other is not None:
            other["trade"] = {"medianFrameMs": first["medianFrameMs"], "meanFlip": first["meanFlip"] - 1.0}
            if not problems(broken):
                fail.append(f"{trees} trees: the check passes a front member dominated by {key(other)}")
if len(sys.argv) > 2:
    lines = [l.strip() for l in open(sys.argv[2]) if l.startswith("Pareto front (")]
    if len(lines) != len(summary.get("pareto", [])):
        fail.append(f"{len(lines)} Pareto lines printed, expected {len(summary.get('pareto', []))}")
    for line, p in zip(lines, summary.get("pareto", [])):
        names = [e.split(" ")[0] for e in line.split(": ", 1)[1].split(";")[0].split(", ")]
        want = [f["technique"] + ("" if f["lodBias"] == 1 else "@%g" % f["lodBias"]) for f in p["front"]]
        if names != want:
            fail.append(f"printed front {names}, summary's {want}: {line}")
        if (p["autoOnFront"] is True) != line.endswith("; auto on the front") or \
           (p["autoOnFront"] is False) != ("is dominated by" in line):
            fail.append(f"printed line disagrees with autoOnFront {p['autoOnFront']}: {line}")
for f in fail:
    print(f"{directory}: {f}")
sys.exit(1 if fail else 0)
EOF
}

# 1. One tree: reference, the four floors and auto at two biases over 6 frames.
"$treelod" bench "$src/samples/scenes/single-tree.json" -o "$out/single" --frames 6 --size 160x90 \
  --techniques auto --lod-bias 1,0.5 --samples 2 --upload-budget 1 --cache "$shared" -q
for f in frames.csv summary.json plots.json; do [ -s "$out/single/$f" ] || fail "single/$f missing"; done
# frame time: the reference, 4 floors and auto at bias 1, 6 frames each; trade: 5 points + auto at 2 biases.
plot "$out/single" frame-time 36; plot "$out/single" trade 7
# Every comparison run is a marked point in the trade plot (the column before on_front); only
# auto's two biases form a curve.
n=$(awk -F, 'NR > 1 && $(NF - 1) == ""' "$out/single/trade.csv" | wc -l)
[ "$n" = 2 ] || fail "trade.csv has $n unmarked rows, expected auto's 2"
rows=$(($(wc -l < "$out/single/frames.csv") - 1))
[ "$rows" = 42 ] || fail "frames.csv has $rows rows, expected (mesh + 4 floors + auto x 2 biases) x 6 = 42"
for t in mesh impostor entities merged-quads billboard-set auto; do
  n=$(awk -F, -v t=$t 'NR > 1 && $2 == t' "$out/single/frames.csv" | wc -l)
  want=6; [ $t = auto ] && want=12
  [ "$n" = "$want" ] || fail "technique $t has $n rows, expected $want"
done
# Every frame of one tree is timed (the reference fits the budget) and draws at least one batch.
awk -F, 'NR > 1 && ($6 != 1 || $9 < 1 || $8 <= 0) { bad = 1; print } END { exit bad }' "$out/single/frames.csv" \
  || fail "untimed or empty frames above"
# Sampled frames carry FLIP for every technique; the floor's error is larger than auto's at bias 1.
n=$(awk -F, 'NR > 1 && $13 != ""' "$out/single/frames.csv" | wc -l)
[ "$n" = 14 ] || fail "$n frames with FLIP, expected 2 samples x 7 runs = 14"
python3 - "$out/single/summary.json" <<'EOF' || fail "the floor's error is not above auto's"
import json, sys
flip = {(r["technique"], r["lodBias"]): r["trade"]["meanFlip"] for r in json.load(open(sys.argv[1]))["results"]}
floor, auto = flip[("impostor", 1)], flip[("auto", 1)]
print(f"mean FLIP: one-quad floor {floor:.4f}, auto {auto:.4f}")
sys.exit(0 if floor > 2 * auto else 1)  # measured 0.199 against 0.043
EOF
# Motion frames (every frame by default, but the last, whose next frame is past the path's end):
# a temporal FLIP on each; a pop FLIP and level switches for the runs the Forest draws (the
# reference, the one-quad floor, auto), not for the floors drawn without it.
awk -F, 'NR > 1 && $6 == 1 && ($4 < 5) != ($16 ~ /^[0-9.e-]+$/) { bad = 1; print } END { exit bad }' \
  "$out/single/frames.csv" || fail "a temporal FLIP missing on frames 0 to 4, or on the last frame (above)"
awk -F, 'NR > 1 && $4 < 5 && ($2 == "mesh" || $2 == "impostor" || $2 == "auto") && ($17 !~ /^[0-9.e-]+$/ ||
  $18 !~ /^[0-9]+$/) { bad = 1; print } END { exit bad }' "$out/single/frames.csv" \
  || fail "Forest runs' frames without pops or switches above"
awk -F, 'NR > 1 && ($2 == "entities" || $2 == "merged-quads" || $2 == "billboard-set") && ($17 != "" || $18 != "") {
  bad = 1; print } END { exit bad }' "$out/single/frames.csv" || fail "pops counted for a floor that is no Forest (above)"
# GPU memory: every run's peak, each timed frame's bytes; the Forest's runs their resident levels and,
# for auto, the planned bytes and the budget that binds (the error budget: no memory budget here).
python3 - "$out/single/summary.json" "$out/single/frames.csv" <<'EOF' || fail "GPU memory figures above"
import csv, json, sys
summary = json.load(open(sys.argv[1]))
bad = []
for r in summary["results"]:
    key, gpu = (r["technique"], r["lodBias"]), r["gpu"]
    if not gpu["peakBytes"] > 0:
        bad.append(f"{key}: peak GPU bytes {gpu['peakBytes']}")
    forest = key[0] in ("mesh", "impostor", "auto", "auto@0.5")
    if forest != (gpu["residentLevels"] is not None) or (forest and gpu["residentLevels"] < 1):
        bad.append(f"{key}: resident levels {gpu['residentLevels']}")
    auto = key[0].startswith("auto")
    if auto != (gpu["binding"] == "error") or (auto and not gpu["plannedBytes"] > 0):
        bad.append(f"{key}: binding {gpu['binding']}, planned {gpu['plannedBytes']}")
if summary["peakGpuBytes"] != max(r["gpu"]["peakBytes"] for r in summary["results"]):
    bad.append(f"scene peak {summary['peakGpuBytes']}")
for row in csv.DictReader(open(sys.argv[2])):
    if row["timed"] == "1" and not int(row["gpu_bytes"]) > 0:
        bad.append(f"frame {row['technique']} {row['frame']}: gpu_bytes {row['gpu_bytes']}")
print("\n".join(bad[:10]))
sys.exit(1 if bad else 0)
EOF
# The error used: each run's FLIP over the mesh's own on the same sampled frames, against the margin;
# the budget and occlusion of the Forest's budgeted runs.
python3 - "$out/single/summary.json" "$out/single/frames.csv" <<'EOF' || fail "error used above"
import csv, json, sys
summary = json.load(open(sys.argv[1]))
flips = {}
for row in csv.DictReader(open(sys.argv[2])):
    if row["flip"]:
        flips.setdefault((row["technique"], float(row["lod_bias"])), {})[row["frame"]] = float(row["flip"])
mesh = flips[("mesh", 1.0)]
bad = []
for r in summary["results"]:
    key, scene = (r["technique"], float(r["lodBias"])), r["sceneError"]
    if abs(scene["allowed"] - 0.02) > 1e-9:
        bad.append(f"{key}: allowed {scene['allowed']}")
    if key == ("mesh", 1.0):
        if scene["used"] is not None or scene["frames"] != 0:
            bad.append(f"the mesh against itself: {scene}")
        continue
    used = [flips[key][f] - mesh[f] for f in flips[key] if f in mesh]
    if scene["frames"] != len(used) or not used or abs(scene["used"] - sum(used) / len(used)) > 1e-5:
        bad.append(f"{key}: error used {scene}, the frames' FLIP give {used}")
    auto = key[0].startswith("auto")
    if auto != (r["errorBudget"] is not None) or (auto and not r["occlusion"]):
        bad.append(f"{key}: error budget {r['errorBudget']}, occlusion {r['occlusion']}")
# The calibration step: the largest tried budget whose error used is within the margin.
for c in summary["budgetCalibration"]:
    within = [t["errorBudget"] for t in c["tried"] if t["used"] <= c["allowed"]]
    if len(c["tried"]) != 2 or c["largestWithinMargin"] != (max(within) if within else None):
        bad.append(f"budget calibration {c}")
if len(summary["budgetCalibration"]) != 1:
    bad.append(f"budget calibrations: {summary['budgetCalibration']}")
auto = [r for r in summary["results"] if r["technique"] == "auto" and r["lodBias"] == 1][0]
print(f"error used by auto: {auto['sceneError']['used']:.4f} of {auto['sceneError']['allowed']} "
      f"(per-tree budget {auto['errorBudget']}), trees hidden per frame {auto['occludedTrees']}")
print("\n".join(bad))
sys.exit(1 if bad else 0)
EOF
plot "$out/single" motion 30 # the frame-time plot's runs, 5 motion frames each
plot "$out/single" pops 15   # the Forest's among them
python3 - "$out/single/summary.json" <<'EOF' || fail "motion figures above"
import json, sys
results = {(r["technique"], r["lodBias"]): r["motion"] for r in json.load(open(sys.argv[1]))["results"]}
bad = []
for key, m in results.items():
    if m["temporalFlip"]["frames"] != 5 or m["reference"]["frames"] != 5:
        bad.append(f"{key}: {m['temporalFlip']['frames']} motion frames, {m['reference']['frames']} with the reference's")
    if not (m["temporalFlip"]["mean"] > 0 and m["temporalFlip"]["max"] >= m["temporalFlip"]["mean"]):
        bad.append(f"{key}: temporal FLIP {m['temporalFlip']} (the camera moves on every frame)")
    forest = key[0] in ("mesh", "impostor", "auto")
    if forest != (m["switchesPerTreePerSecond"] is not None):
        bad.append(f"{key}: switchesPerTreePerSecond {m['switchesPerTreePerSecond']}")
    if m["popFlip"]["frames"] != (5 if forest else 0) or m["referencePopFlip"]["frames"] != (5 if forest else 0):
        bad.append(f"{key}: pops on {m['popFlip']['frames']} frames, {m['referencePopFlip']['frames']} with the reference's")
    if forest and not 0 <= m["popFlip"]["mean"] <= m["popFlip"]["max"]:
        bad.append(f"{key}: pop FLIP {m['popFlip']}")
    if forest and m["levelSwitches"] == 0 and m["popFlip"]["max"] != 0:
        bad.append(f"{key}: no level switched, yet the held levels differ from the next frame: {m['popFlip']}")
mesh = results[("mesh", 1)]
if abs(mesh["meanOverReference"] - 1) > 1e-9 or abs(mesh["worstOverReference"] - 1) > 1e-9:
    bad.append(f"the reference against itself: {mesh}")
auto = results[("auto", 1)]
print(f"temporal FLIP: mesh {mesh['temporalFlip']['mean']:.4f} (worst {mesh['temporalFlip']['max']:.4f}), "
      f"auto {auto['temporalFlip']['mean']:.4f} (worst {auto['temporalFlip']['max']:.4f}); pop FLIP: mesh "
      f"{mesh['popFlip']['max']:.4f}, auto {auto['popFlip']['max']:.4f} (worst); auto's switches per tree per "
      f"second {auto['switchesPerTreePerSecond']}")
print("\n".join(bad))
sys.exit(1 if bad else 0)
EOF
grep -q '"technique": "auto"' "$out/single/summary.json" || fail "summary lacks auto"
grep -q '"speedupVsReference": [0-9]' "$out/single/summary.json" || fail "summary has no measured speedup"
grep -q '"ratioToFloor": [0-9]' "$out/single/summary.json" || fail "summary has no ratio to the floor"
[ "$(results "$out/single/summary.json")" = 7 ] || fail "summary should have 7 results"
# Every run of one tree has a frame time and a FLIP, so each says whether it is on the Pareto front.
[ "$(grep -Ec '"onParetoFront": (true|false)' "$out/single/summary.json")" = 7 ] \
  || fail "summary should say for all 7 results whether they are on the Pareto front"
pareto "$out/single" || fail "single: Pareto front above"
# The frames came from treelod_frames (which links no baker) through the package list.
for f in packages.json timings.json; do [ -s "$out/single/$f" ] || fail "single/$f missing"; done
grep -q '"format": "treelod-package-list"' "$out/single/packages.json" || fail "packages.json is not a package list"
for floor in impostor entities merged-quads billboard-set; do
  grep -q "\"$floor\": [0-9]" "$out/single/summary.json" || fail "summary has no ratio to the $floor floor"
done
grep -q '"worstFrame": {' "$out/single/summary.json" || fail "summary does not record the worst frame"
# Levels are built when first seen, one per frame under a 1-byte budget: some timed frame of the
# mesh (its levels split where the bark mesh's LoD switches; frame 2 needs one the warm-up frames
# 0, 1, 3 and 5 did not) uploads, and every timed frame says how much. Not auto's: its levels
# follow this machine's calibrated costs, so which frames need a new one is not fixed.
awk -F, 'NR > 1 && $6 == 1 && $NF !~ /^[0-9]+$/ { bad = 1; print } END { exit bad }' "$out/single/frames.csv" \
  || fail "timed frames without uploaded bytes above"
awk -F, 'NR > 1 && $2 == "mesh" && $NF > 0 { n++ } END { exit !(n > 0) }' "$out/single/frames.csv" \
  || fail "the mesh built no level during the timed frames"
# treelod_frames --preload builds every level first: no timed frame uploads.
"$(dirname "$treelod")/treelod_frames" "$src/samples/scenes/single-tree.json" --packages "$out/single/packages.json" \
  -o "$out/preload" --skip-comparisons --techniques auto --lod-bias 1 --frames 6 --size 160x90 --samples 1 --preload -q
grep -q '"uploadedBytes": 0' "$out/preload/timings.json" || fail "preloaded frames record no uploaded bytes"
! grep -Eq '"uploadedBytes": [1-9]' "$out/preload/timings.json" || fail "a preloaded frame uploaded"
# timings.json is rewritten after every run: a timer cut short (the GPU machine's time limit)
# leaves "complete": false and the runs it finished, which --frames-from reports with a warning.
grep -q '"complete": true' "$out/single/timings.json" || fail "finished timings are not marked complete"
mkdir -p "$out/cut"; cp -r "$out/single/images" "$out/cut/"
python3 - "$out/single/timings.json" "$out/cut/timings.json" <<'EOF'
import json, sys
t = json.load(open(sys.argv[1])); t["runs"] = t["runs"][:2]; t["complete"] = False
json.dump(t, open(sys.argv[2], "w"))
EOF
"$treelod" bench "$src/samples/scenes/single-tree.json" -o "$out/cut-report" --frames 6 --size 160x90 \
  --techniques auto --lod-bias 1,0.5 --samples 2 --cache "$shared" --frames-from "$out/cut" -q 2> "$out/cut.txt"
grep -q "incomplete (the frame timer stopped after 2 runs)" "$out/cut.txt" || { cat "$out/cut.txt"; fail "no warning"; }
[ "$(results "$out/cut-report/summary.json")" = 2 ] || fail "a cut-short timer's 2 runs not reported"
# Without -q the bench prints the Pareto front; on the same frames (--frames-from) it is the same front.
"$treelod" bench "$src/samples/scenes/single-tree.json" -o "$out/single-report" --frames 6 --size 160x90 \
  --techniques auto --lod-bias 1,0.5 --samples 2 --cache "$shared" --frames-from "$out/single" \
  > "$out/report.txt" 2> "$out/report-progress.txt"
grep -q '^Pareto front (1 tree): ' "$out/report.txt" || { cat "$out/report.txt"; fail "no Pareto front printed"; }
grep -q '^Pareto front (1 tree): .* ms [0-9.e-]* [0-9.e-]* MB (motion [0-9.e-]* pops [0-9.e-]*)' "$out/report.txt" \
  || { cat "$out/report.txt"; fail "the printed front lacks the temporal FLIP"; }
pareto "$out/single-report" "$out/report.txt" || fail "single-report: Pareto front above"
python3 -c 'import json, sys; a, b = (json.load(open(f))["pareto"] for f in sys.argv[1:]); sys.exit(a != b)' \
  "$out/single/summary.json" "$out/single-report/summary.json" || fail "the same frames gave another Pareto front"
grep -Eq '"oak.glb: (baked|reused) ' "$out/single/summary.json" || fail "single: no bake report"

# 2. García et al. 2007 Table 2 scaled down: two tree counts (1 and 1 + 49 x 0.1), a trees plot.
"$treelod" bench "$src/samples/scenes/table2.json" -o "$out/table2" --scale 0.1 --counts 1,50 --frames 3 \
  --size 128x96 --techniques billboard-cloud --lod-bias 1 --samples 1 --cache "$cache" -q
for f in frames.csv summary.json plots.json; do [ -s "$out/table2/$f" ] || fail "table2/$f missing"; done
plot "$out/table2" trees 12 # 6 runs at bias 1 x 2 counts
counts=$(awk -F, 'NR > 1 { print $1 }' "$out/table2/frames.csv" | sort -n | uniq)
[ "$(echo $counts)" = "1 6" ] || fail "tree counts '$(echo $counts)', expected '1 6'"
for c in $counts; do
  n=$(awk -F, -v c=$c 'NR > 1 && $1 == c' "$out/table2/frames.csv" | wc -l)
  [ "$n" = 18 ] || fail "$c trees: $n rows, expected 6 runs x 3 frames"
  plot "$out/table2" trade-$c 6; plot "$out/table2" frame-time-$c 18
  grep -Eq "\"trees\": $c,?\$" "$out/table2/summary.json" || fail "summary lacks $c trees"
done
# The bake cache reported what it built in the empty cache; a second run reuses everything.
grep -q '"oak.glb: baked billboard-cloud, impostor, reference' "$out/table2/summary.json" || fail "table2 baked nothing?"
"$treelod" bench "$src/samples/scenes/table2.json" -o "$out/table2-again" --scale 0.1 --counts 1 --frames 1 \
  --size 64x48 --techniques billboard-cloud --lod-bias 1 --samples 1 --cache "$cache" -q
grep -q '"bake"' "$out/table2-again/summary.json" && ! grep -q ': baked' "$out/table2-again/summary.json" \
  || fail "second run rebaked"
# A Pareto front per tree count; without auto runs, autoOnFront is null.
pareto "$out/table2" || fail "table2: Pareto front above"
[ "$(grep -c '"autoOnFront": null' "$out/table2/summary.json")" = 2 ] || fail "table2: autoOnFront should be null twice"

# A pop, measured: one oak drawn by the mesh within 30 m and by the one-quad impostor beyond, the
# camera from 20 m to 45 m in one step of the script's frame rate (3 frames in 2 s), then to 46 m.
# Frame 0's next frame switches the tree; frame 1's switches nothing (pop FLIP 0); frame 2 has no
# next frame.
cat > "$out/pop.json" <<EOF
{
  "name": "pop",
  "ground": {"kind": "plane", "size": 200},
  "species": [{"name": "oak", "source": "$src/media/oak.glb",
               "techniques": [{"technique": "mesh", "maxDistance": 30}, {"technique": "impostor"}]}],
  "placements": [{"species": "oak", "positions": [[0, 0, 0]]}],
  "camera": {"keyframes": [{"time": 0, "position": [0, 6, 20], "target": [0, 6, 0]},
                           {"time": 1, "position": [0, 6, 45], "target": [0, 6, 0]},
                           {"time": 2, "position": [0, 6, 46], "target": [0, 6, 0]}]},
  "resolution": [96, 64],
  "frames": 3
}
EOF
"$treelod" bench "$out/pop.json" -o "$out/pop" --techniques auto --lod-bias 1 --samples 1 --cache "$shared" -q
python3 - "$out/pop/frames.csv" <<'EOF' || fail "the pop above"
import csv, sys
rows = {(r["technique"], r["frame"]): r for r in csv.DictReader(open(sys.argv[1]))}
switch, still, last = rows[("auto", "0")], rows[("auto", "1")], rows[("auto", "2")]
print(f"a pop: {switch['level_switches']} switch, pop FLIP {switch['pop_flip']}; without a switch {still['pop_flip']}")
ok = switch["level_switches"] == "1" and float(switch["pop_flip"]) > 0.05 and still["level_switches"] == "0" \
    and float(still["pop_flip"]) == 0 and last["pop_flip"] == "" and last["temporal_flip"] == ""
sys.exit(0 if ok else 1)
EOF

# 3. A bad script: exit 2, file:line:column named, nothing written.
printf '{\n  "name": "bad",\n  "frames": -3\n}\n' > "$out/bad.json"
set +e
"$treelod" bench "$out/bad.json" -o "$out/bad" -q 2> "$out/bad.txt"; code=$?
set -e
[ "$code" = 2 ] || fail "bad script: exit $code, expected 2"
grep -q "bad.json: line" "$out/bad.txt" || { cat "$out/bad.txt"; fail "error does not name file and line"; }
[ ! -e "$out/bad" ] || fail "bad script created its output directory"
# --shadow-size: 0 turns the script's shadows off (recorded), a size that is no power of two is
# refused before anything is written.
"$treelod" bench "$src/samples/scenes/single-tree.json" -o "$out/noshadow" --frames 2 --size 64x36 \
  --techniques lodf --lod-bias 1 --samples 1 --cache "$shared" --shadow-size 0 --shadow-lod-bias 0.5 --wind 0.5 -q
grep -q '"shadowMap": 0' "$out/noshadow/summary.json" || fail "--shadow-size 0 not recorded"
grep -q '"windStrength": 0.5' "$out/noshadow/summary.json" || fail "--wind 0.5 not recorded"
grep -q '"windStrength": 0.5' "$out/noshadow/timings.json" || fail "--wind did not reach treelod_frames"
grep -q '"windStrength": 0' "$out/single/summary.json" || fail "the script's calm not recorded"
grep -q '"shadowLodBias": 0.5' "$out/noshadow/summary.json" || fail "--shadow-lod-bias 0.5 not recorded"
grep -q '"shadowLodBias": 0.5' "$out/noshadow/timings.json" || fail "--shadow-lod-bias did not reach treelod_frames"
grep -Eq '"shadowMap": [1-9]' "$out/single/summary.json" || fail "the script's shadow map not recorded"
set +e
"$treelod" bench "$src/samples/scenes/single-tree.json" -o "$out/badshadow" --shadow-size 300 -q 2> "$out/badshadow.txt"
code=$?
set -e
[ "$code" = 2 ] || fail "--shadow-size 300: exit $code, expected 2"
grep -q -- "--shadow-size: 300 is not" "$out/badshadow.txt" || { cat "$out/badshadow.txt"; fail "no reason given"; }
[ ! -e "$out/badshadow" ] || fail "a bad --shadow-size created its output directory"
set +e
"$treelod" bench "$src/samples/scenes/single-tree.json" -o "$out/badbias" --shadow-lod-bias -1 -q 2> "$out/badbias.txt"
code=$?
set -e
[ "$code" = 2 ] && grep -q -- "--shadow-lod-bias" "$out/badbias.txt" || { cat "$out/badbias.txt"; fail "--shadow-lod-bias -1 accepted"; }
[ ! -e "$out/badbias" ] || fail "a bad --shadow-lod-bias created its output directory"
set +e
"$treelod" bench "$src/samples/scenes/single-tree.json" -o "$out/badmotion" --motion-frames -1 -q 2> "$out/badmotion.txt"
code=$?
set -e
[ "$code" = 2 ] && grep -q -- "--motion-frames: '-1' is not" "$out/badmotion.txt" \
  || { cat "$out/badmotion.txt"; fail "--motion-frames -1 accepted"; }
[ ! -e "$out/badmotion" ] || fail "a bad --motion-frames created its output directory"
set +e
"$treelod" bench "$src/samples/scenes/single-tree.json" -o "$out/badwind" --wind 200 -q 2> "$out/badwind.txt"
code=$?
set -e
[ "$code" = 2 ] && grep -q -- "--wind: 200" "$out/badwind.txt" || { cat "$out/badwind.txt"; fail "--wind 200 accepted"; }
[ ! -e "$out/badwind" ] || fail "a bad --wind created its output directory"
echo "bench test passed"
