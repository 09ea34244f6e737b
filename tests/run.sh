#!/usr/bin/env bash
# Build and run every test, once each (a failure is a failure: nothing is retried):
#  1. the Release tree (clang): unit, headless Ogre, golden-image, CLI and browser tests (under Xvfb);
#  2. a clang tree with ASan + UBSan: every gtest binary (core and Ogre);
#  3. a clang tree with TSan: TreeLod's own threads (bake cache, async baker), on one CPU while
#     each libFuzzer target of stage 2's tree runs for a few seconds on another.
# A test process that dies leaves its core dump and backtrace in <tree>/test-out/cores/.
# CI (.ci/run) calls exactly this. TREELOD_SANITIZE=0 runs stage 1 only.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${TREELOD_BUILD_DIR:-$root/build}
asan=${TREELOD_ASAN_BUILD_DIR:-$root/build-asan}
tsan=${TREELOD_TSAN_BUILD_DIR:-$root/build-tsan}
jobs=$(nproc)
"$root/.ci/deps.sh" --with-fuzzers
# step NAME: the time since the start, then NAME (the stages' times in the log).
step() { echo "==== ${SECONDS} s: $1"; }

# Core dumps of crashing tests: kept where the kernel writes them into the test's folder.
ulimit -c unlimited 2>/dev/null || true
pattern=$(cat /proc/sys/kernel/core_pattern 2>/dev/null || echo core)
[[ $pattern == \|* ]] && echo "note: core dumps go to '$pattern', not to the test folders"

# collect_cores TREE: move core files under TREE to TREE/test-out/cores with a backtrace each.
collect_cores() {
  local tree=$1 core exe
  while IFS= read -r core; do
    mkdir -p "$tree/test-out/cores"
    exe=$(file -b "$core" | sed -n "s/.*execfn: '\([^']*\)'.*/\1/p")
    local kept=$tree/test-out/cores/$(basename "$core").$(date +%s%N)
    mv "$core" "$kept"
    core=$kept
    echo "core dump: $core (${exe:-unknown executable})"
    if [ -n "$exe" ] && command -v gdb >/dev/null; then
      gdb -batch -ex "thread apply all bt 30" "$exe" "$core" 2>/dev/null | tee "$core.backtrace.txt" | head -n 60
    fi
  done < <(find "$tree" -path "$tree/test-out/cores" -prune -o -type f \( -name core -o -name 'core.[0-9]*' \) -print)
}

# run_ctest TREE [ctest arguments]: every test once under Xvfb (through $launch, when set); cores
# collected on failure.
run_ctest() {
  local tree=$1; shift
  local rc=0
  (cd "$tree" && XDG_CACHE_HOME=$tree/test-cache ${launch:-} xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" \
    ctest --output-on-failure -j"$jobs" --timeout 300 "$@") || rc=$?
  collect_cores "$tree"
  return $rc
}

# Mesa's shader cache, shared by the Release and ASan trees' tests (the same shaders, the same
# driver): each tree's test-cache/ still holds its own baked packages.
export MESA_SHADER_CACHE_DIR=$build/test-cache/mesa-shaders

# configure TREE CMAKE_ARGS...: a tree made with Ninja, which unlike make compiles a target's
# sources while the libraries it links are still building (both cores busy through the unity
# builds' few large sources), and linked by lld (the ASan tree's links: 13 s against about 60 s
# with GNU ld). A tree made before with another generator keeps it.
configure() {
  local tree=$1 generator
  shift
  generator=$(sed -n 's/^CMAKE_GENERATOR:INTERNAL=//p' "$tree/CMakeCache.txt" 2>/dev/null || true)
  cmake -S "$root" -B "$tree" -G "${generator:-Ninja}" -DCMAKE_EXE_LINKER_FLAGS=-fuse-ld=lld \
    -DCMAKE_SHARED_LINKER_FLAGS=-fuse-ld=lld -DCMAKE_MODULE_LINKER_FLAGS=-fuse-ld=lld "$@" >/dev/null
}

# ---- 1. Release ------------------------------------------------------------------------
# Compiled by clang, as the sanitizer trees are: with its precompiled headers this tree's jobs sum
# 532 s against 759 to 973 s with GCC, and its tests run as fast (docs/testing.md). CXX=g++
# tests/run.sh makes a new tree with GCC, the compiler samples/browser.sh builds with.
step "Release: build"
CXX=${CXX:-clang++} configure "$build" -DCMAKE_BUILD_TYPE=Release -DTREELOD_BUILD_TESTS=ON
cmake --build "$build" -j"$jobs"
step "Release: tests"
run_ctest "$build"
[ "${TREELOD_SANITIZE:-1}" = 0 ] && { echo "all tests passed (sanitizer trees skipped)"; exit 0; }

# ---- 2. ASan + UBSan, fuzzers ------------------------------------------------------------
# LeakSanitizer checks every core binary at exit (the Ogre binaries opt out: OgreTestMain.cpp).
# The fuzzers' coverage instrumentation is on the code that reads their input only (CMakeLists.txt):
# on everything, it made these tests 1.5 times slower.
# alloc_dealloc_mismatch=0: OGRE's Codec_STBI hands Ogre::Image a malloc'd buffer that Image frees
# with delete[] (inside OGRE, on every texture load).
# The Ogre tests' baked packages (OgreTestSupport.h, cachedPackage) are stage 1's, baked from these
# sources a moment ago: this stage's Ogre tests check the Ogre halves under ASan, and the bakers run
# under ASan in the core tests.
export TREELOD_TEST_PACKAGES=$build/test-out
export ASAN_OPTIONS=abort_on_error=1:alloc_dealloc_mismatch=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
step "ASan: build"
CXX=clang++ configure "$asan" -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1" \
  -DTREELOD_SANITIZERS=address,undefined -DTREELOD_BUILD_FUZZERS=ON -DTREELOD_BUILD_TESTS=ON \
  -DTREELOD_BUILD_BENCHMARKS=OFF -DTREELOD_BUILD_SAMPLES=OFF
# Every gtest binary, a suite per process: the core ones (label "core") and the Ogre ones (label
# "ogre"); TREELOD_ASAN_OGRE=0 leaves the Ogre ones out. Left out here, for CI time, and run
# in stage 1: the tools' scripts, the shader validation, the other render systems' runs of
# test_ogre, and five tests whose size alone makes them take 50 to 270 s under ASan (three
# 200k-leaf bakes: two billboard clouds and the ellipsoids, whose bake runs here in the other
# EllipsoidTreeBake tests; the 50k-leaf golden; the cache-hit-under-renames loop, which stage 3
# runs under TSan); 200k-leaf trees stay under ASan in the LoDF tests. Also left out: the five
# Forest tests that measure error curves and calibrate through Ogre (each measures the oak's
# curves, CPU ray tracing and FLIP); the chunk, selection, cost file, table replacement and
# hysteresis code they drive runs under ASan in the core tests and the package fuzzer. And five
# EllipsoidLineBake tests (each bakes its oak's lines again; the bake runs under ASan in the other
# line tests) and the EllipsoidTree test that bakes a 0.5 m and a 500 m oak of its own (the other
# EllipsoidTree tests share one bake in their suite's process). And the two bakers' determinism
# tests (each bakes its tree three to five times, with one and two threads: 49 and 29 s here; the
# bakes' code runs under ASan in the suites' other tests, and stage 1 compares the bytes), and the
# ellipsoids' scale test (the same bake at 0.5 m and 500 m: 18 s). And five tests of 18 to 32 s under
# ASan whose code the suites' other tests run there: the billboard cloud's package glue and
# layered-cloud comparison (the layered bake runs in its other tests), the
# ellipsoids' bake far from the origin and its level divisor (the same EM on other trees), and the
# technique descriptors' inspection of every baker's output (each baker runs in its own suite).
# The scripts are left out by ctest name (asan_skip); the gtests by gtest pattern (TREELOD_GTEST_SKIP,
# read by tests/core/TestMain.cpp and tests/ogre/OgreTestMain.cpp), since ctest runs the gtest
# binaries a suite per process and sees their suites only.
asan_skip='^(install|cli|bench|shaders|rendersystem)\.'
export TREELOD_GTEST_SKIP='BillboardCloudBaker.twoHundredThousandLeaves*:EllipsoidTreeBake.twoHundredThousandLeaves:BakeCacheProcesses.HitsWhilePackagesAreReplacedAreNotDiscarded:EllipsoidLineBake.scaleFree:EllipsoidLineBake.deterministicForSeedAndThreads:EllipsoidLineBake.levelCountsWeightsAndTargets:EllipsoidLineBake.registeredAndErrorsNamed:EllipsoidLineBake.extractedSkeletonFollowsTheGenerator:BillboardCloudTree.goldenFiftyThousandLeaves:Forest.errorCurvesRankTheLevelsAgainstTheCpuReference:Forest.errorCurvesOfVersionOneAreReadAndMeasuredAgain:Forest.calibrationTimesEveryLevelAndIsCachedPerRenderer:Forest.anErrorBudgetChoosesTheCheapestLevelWithinIt:Forest.budgetedSpeciesReplanInPlaceForAnErrorAFrameAndAShadowBudget:EllipsoidTree.halfAMetreAndFiveHundredMetresLookTheSame:BillboardCloudBaker.chunkRoundTripsAndIsDeterministicForAnyThreadCount:EllipsoidTreeBake.deterministicForSeedAndThreads:EllipsoidTreeBake.scaleFree:BillboardCloudBaker.packageGlueAddsReferenceAndCloudChunks:BillboardCloudBaker.layeredCloudMatchesThePolygonalTreeAndKeepsDetailCloseUp:EllipsoidTreeBake.farFromTheOriginTheSameEllipsoids:EllipsoidTreeBake.levelCountsFollowTheDivisor:TechniqueDescriptor.inspectReadsWhatEachBakerWrote'
if [ "${TREELOD_ASAN_OGRE:-1}" = 1 ]; then
  cmake --build "$asan" -j"$jobs" --target treelod_tests treelod_fuzzers
  step "ASan: tests"
  run_ctest "$asan" -E "$asan_skip"
else
  cmake --build "$asan" -j"$jobs" --target treelod_core_tests treelod_fuzzers
  step "ASan: tests"
  run_ctest "$asan" -L core -E "$asan_skip"
fi

# ---- 3. TSan, and the ASan tree's fuzzers beside its tests ----------------------------------
unset TREELOD_TEST_PACKAGES
step "TSan: build"
CXX=clang++ configure "$tsan" -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1" \
  -DTREELOD_SANITIZERS=thread \
  -DTREELOD_BUILD_TESTS=ON -DTREELOD_BUILD_BENCHMARKS=OFF -DTREELOD_BUILD_SAMPLES=OFF
cmake --build "$tsan" -j"$jobs" --target test_bakecache test_async_bake

fuzzers=(FuzzGltfImporter:gltf FuzzPackageReader:package FuzzSceneScript:scene FuzzInstanceFile:instances FuzzOgreMeshImport:ogremesh)
# fuzz BINARY:CORPUS: one fuzzer (under $fuzz_launch) on a copy of its corpus; its last lines, or
# its whole report when it fails (a crash, a leak, a timeout).
fuzz() {
  local bin=${1%%:*} corpus=$root/tests/fuzz/corpus/${1#*:} work rc=0
  work=$(mktemp -d)
  cp -r "$corpus"/. "$work"/ 2>/dev/null || true
  ${fuzz_launch:-} "$asan/bin/$bin" -max_total_time="${TREELOD_FUZZ_SECONDS:-10}" -max_len=65536 -rss_limit_mb=2048 \
    "$work" > "$work.log" 2>&1 || rc=$?
  echo "fuzzed $bin for ${TREELOD_FUZZ_SECONDS:-10} s: exit $rc"
  if [ $rc = 0 ]; then tail -n 3 "$work.log"; else tail -n 200 "$work.log"; fi
  rm -rf "$work" "$work.log"
  return $rc
}
# The fuzzers one after another on the last CPU, in the background, while the TSan tests run on
# the first (they take one CPU, below); their reports are printed when both are done.
step "ASan: fuzzers (CPU $((jobs - 1))), TSan: tests (CPU 0)"
fuzz_launch="taskset -c $((jobs - 1))"
reports=$(mktemp -d)
(
  failed=0
  for target in "${fuzzers[@]}"; do fuzz "$target" > "$reports/${target%%:*}.txt" || failed=1; done
  exit $failed
) &
fuzz_pid=$!

# The bake cache's tests of two processes baking, and of a full disk, are left out: they test no
# thread of TreeLod's.
export TREELOD_GTEST_SKIP='BakeCacheProcesses.TwoProcesses*:BakeCacheProcesses.DiskFull*:BakeCacheProcesses.NoSpace*'
# TreeLod's own threads: the bake cache's concurrent requests and renames, the async baker.
# Debian's TBB and Mesa are not instrumented, so their synchronisation is invisible to TSan and
# every parallel_for or llvmpipe barrier reports races: on one CPU (taskset) TBB starts no worker
# threads, and LP_NUM_THREADS=0 keeps llvmpipe on the calling thread.
export TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1:suppressions=$root/tests/sanitizers/tsan.supp
export LP_NUM_THREADS=0
# Mesa's shader disk cache writes from threads of its own, whose barriers TSan cannot see in the
# uninstrumented driver (a race report at teardown on a cold cache): off here.
export MESA_SHADER_CACHE_DISABLE=true
tsan_rc=0
launch="taskset -c 0" run_ctest "$tsan" -R '^(BakeCache|BakeCacheProcesses|TreeAssetManager|ForestScene)\.' || tsan_rc=$?
fuzz_rc=0
wait "$fuzz_pid" || fuzz_rc=$?
cat "$reports"/*.txt
rm -rf "$reports"
[ $fuzz_rc = 0 ] || { echo "a fuzzer failed (its report is above)"; exit 1; }
[ $tsan_rc = 0 ] || exit $tsan_rc
step "all tests passed"
