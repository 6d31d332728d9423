#!/usr/bin/env bash
# Installs what blmesh's build and tests need on a fresh Debian machine with Rust: TetGen
# (libtet1.5-dev, for the core fill behind the default cargo feature `tetgen`), the CGNS library
# and its tools (libcgns-dev for the cargo feature `cgns`, cgns-convert for cgnscheck and
# cgns_to_vtk in the tests),
# the system libraries the Gmsh Python wheel loads, and a venv with gmsh + meshio (used by the
# interoperability tests that read our files back with other tools) and maturin + pytest (to
# build and test the Python package), and OpenFOAM (checkMesh and
# potentialFoam for tests/foam.rs; its tools find their etc/ through WM_PROJECT_DIR=/usr/share/openfoam,
# which the tests set, so Debian's noisy etc/bashrc need not be sourced). Idempotent.
set -euo pipefail
cd "$(dirname "$0")/.."

SUDO=""
if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi
APT_PACKAGES="libtet1.5-dev libcgns-dev cgns-convert python3-venv libglu1-mesa libgl1 libxcursor1 libxft2 libxinerama1 libxrender1 libxfixes3 libxext6 libx11-6 libfontconfig1 libfreetype6 libgomp1"
missing=""
for p in $APT_PACKAGES; do
  dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"
done
if [ -n "$missing" ]; then
  echo "setup: installing Debian packages:$missing"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $missing >/dev/null
fi
# Without its recommended tutorials (openfoam-examples), which the tests do not use.
if ! dpkg -s openfoam >/dev/null 2>&1; then
  echo "setup: installing Debian package: openfoam"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends openfoam >/dev/null
fi

if [ ! -x .venv/bin/python ]; then
  python3 -m venv .venv
fi
# scipy: ../shared/bench/measure.py (the README's peer metric) needs it.
.venv/bin/python -c "import gmsh, meshio, numpy, scipy, maturin, pytest" 2>/dev/null || \
  .venv/bin/pip install -q gmsh==4.15.2 meshio==5.3.5 numpy scipy "maturin>=1.5,<2" pytest
