#!/usr/bin/env bash
# The third-party test corpus: ez-tree presets written as .glb into media/third-party/ (git-ignored;
# media/third-party/LICENSES.md). Needs node 20 or later and `npm ci --prefix tools/ez-tree` first.
#   tools/ez-tree/corpus.sh            # from the repository root
# Each preset with its own seed; the same package-lock gives the same bytes.
set -euo pipefail
cd "$(dirname "$0")/../.."
mkdir -p media/third-party
for entry in "Aspen Medium:aspen" "Oak Medium:oak" "Ash Medium:ash" "Bush 1:bush" "Pine Medium:pine"; do
  preset="${entry%%:*}"
  name="${entry##*:}"
  echo "ez-tree ${preset} -> media/third-party/ez-tree-${name}.glb"
  node tools/ez-tree/generate.mjs --preset "${preset}" -o "media/third-party/ez-tree-${name}.glb"
done
