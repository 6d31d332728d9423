#!/usr/bin/env bash
# The test command (README, and .ci/run): set up, build in release, run every test.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
export BLMESH_PYTHON="$PWD/.venv/bin/python"
# Everything with the optional CGNS writer too; then the io tests once without it (the clear
# error a `.cgns` output gives in a default build).
cargo test --release --all-targets --features cgns
cargo test --release --lib io::
# The Python package, built into the venv with the venv's maturin (sharing target/ with the
# builds above), then its tests, which also run the README's commands.
PATH="$PWD/.venv/bin:$PATH" .venv/bin/pip install -q --no-build-isolation .
.venv/bin/python -m pytest -q python/tests
