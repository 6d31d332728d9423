"""Shared set-ups of the Python package's tests: the shipped example surfaces, and one mesh of
the example box reused by the tests that only read it."""

import pathlib

import pytest

import blmesh

ROOT = pathlib.Path(__file__).resolve().parents[2]
BOX = ROOT / "examples" / "box.stl"


@pytest.fixture(scope="session")
def box_mesh():
    """The example box at 10 layers of H = 1e-3 D (the defaults but the count)."""
    return blmesh.mesh(BOX, layers=10)
