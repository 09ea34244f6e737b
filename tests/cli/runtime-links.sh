#!/usr/bin/env bash
# docs/architecture.md "Runtime vs bake": the plugin and the program that renders and times the
# bench's frames (treelod_frames) load no baker library, so they fit the GPU bundle
# (bench/gpu-run.sh prepare). Fails naming the library that leaked in.
set -euo pipefail
status=0
for binary in "$@"; do
  [ -e "$binary" ] || { echo "runtime-links: $binary does not exist"; exit 1; }
  libs=$(ldd "$binary") # whole, before grep: grep -q closing the pipe early would fail it under pipefail
  leaked=$(grep -Ei 'libpng|libjpeg|embree|squish|tinygltf' <<< "$libs" || true)
  if [ -n "$leaked" ]; then
    echo "runtime-links: $binary loads bake-only libraries:"; echo "$leaked"; status=1
  fi
  grep -q 'libOgreMain' <<< "$libs" || { echo "runtime-links: $binary does not load OgreMain?"; status=1; }
done
[ $status = 0 ] && echo "runtime-links: $# binaries load OGRE and the runtime only"
exit $status
