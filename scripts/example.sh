#!/usr/bin/env bash
# The main job on the shipped examples: a box (fans at its convex edges and corners) and a
# sphere, each with 15 layers and a tetrahedral core out to a box farfield; every output is
# checked by `blmesh check`, and pictures of cuts go to out/*_pictures/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
cargo build --release --quiet
mkdir -p out
for name in box sphere; do
  target/release/blmesh mesh "examples/$name.stl" -o "out/$name.msh" --config examples/example.toml \
    --report "out/$name.json" --pictures "out/${name}_pictures"
  target/release/blmesh check "out/$name.msh"
done
