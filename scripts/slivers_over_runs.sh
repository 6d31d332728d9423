#!/bin/bash
# Core tetrahedra below 10 deg, near-concave coverage (%) and size jump within [1/r, r] (%) on
# the shared surfaces, for growth 1.1999, 1.2 and 1.2001 (H = 1e-3 D, 10 layers). Sliver counts
# swing by a factor of two between such runs (ONERA M6: 40 to 137), so compare builds over all
# three. Usage: scripts/slivers_over_runs.sh [BINARY] (default target/release/blmesh).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bin=${1:-$here/target/release/blmesh}
shared=$here/../shared/geometries
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for name in fandisk.obj flange.stl arrow_cape.stl building_wtc2.obj mech_test_gapdetection.obj spot.obj onera_m6_gmsh_coarse.stl; do
  surface=$shared/$name
  diagonal=$("$bin" info "$surface" --json | python3 -c "import json, sys; print(json.load(sys.stdin)['diagonal'])")
  height=$(python3 -c "print($diagonal * 1e-3)")
  line="$name"
  for growth in 1.1999 1.2 1.2001; do
    "$bin" mesh "$surface" -o "$tmp/mesh.vtu" --first-height "$height" --growth "$growth" --layers 10 \
      --report "$tmp/report.json" -q
    line="$line $(python3 -c "
import json
d = json.load(open('$tmp/report.json'))
core, layers = d['core'], d['layers']
print('%d/%.2f/%.1f' % (core['quality']['slivers']['count'], 100 * layers['near_concave_coverage'],
                        100 * core['size_jump']['stats']['within_band']))")"
  done
  echo "$line"
done
