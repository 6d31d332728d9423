#!/usr/bin/env bash
# The test command (README, and .ci/run): set up, build once in release, run every test.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
export BLMESH_PYTHON="$PWD/.venv/bin/python"
cargo test --release --all-targets
