#!/usr/bin/env python3
"""Check a legacy ASCII VTK file made by CGNS's own `cgns_to_vtk -a` from a blmesh .cgns file
(run by tests/cgns.rs): meshio reads it, the cell counts by meshio type are the expected ones, and
every cell is positive in the CGNS (= Gmsh) node orders (the tetrahedra from its centroid to its
outward face triangles all have positive volume). cgns_to_vtk copies the CGNS connectivity
unpermuted, also PENTA_6 into VTK wedges, and meshio's VTK reader permutes wedges from VTK's order
to its own (Gmsh's): the wedges are permuted back here to get the CGNS order. cgns_to_vtk writes
points with 6 significant digits, so the total volume is compared within 1e-4 relative.

usage: cgns_vtk.py FILE.vtk --expect TYPE=N [--expect ...] --volume V
"""
import argparse
import os
import sys

import meshio
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from interop import FACES  # noqa: E402  (outward faces of the Gmsh = meshio = CGNS orders)


def sub_volumes(x, faces):
    """Signed volumes (cells x sub-tetrahedra) of the centroid-to-face decomposition."""
    c = x.mean(axis=1)
    parts = []
    for f in faces:
        fx = x[:, list(f)]
        if len(f) == 3:
            tris = [(fx[:, 0], fx[:, 1], fx[:, 2])]
        else:
            m = fx.mean(axis=1)
            tris = [(fx[:, i], fx[:, (i + 1) % 4], m) for i in range(4)]
        for a, b, d in tris:
            parts.append(np.einsum("ij,ij->i", a - c, np.cross(b - c, d - c)) / 6.0)
    return np.stack(parts, axis=1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("path")
    ap.add_argument("--expect", action="append", default=[])
    ap.add_argument("--volume", type=float, required=True)
    args = ap.parse_args()
    m = meshio.read(args.path)
    points = np.asarray(m.points, dtype=float)[:, :3]
    counts, total, problems = {}, 0.0, []
    for block in m.cells:
        counts[block.type] = counts.get(block.type, 0) + len(block.data)
        if block.type not in FACES:
            continue
        conn = np.asarray(block.data)
        if block.type == "wedge":
            conn = conn[:, [0, 2, 1, 3, 5, 4]]
        v = sub_volumes(points[conn], FACES[block.type])
        bad = int((v <= 0).any(axis=1).sum())
        if bad:
            problems.append(f"{bad} of {len(v)} {block.type} cells are not positive")
        total += float(v.sum())
    for item in args.expect:
        t, n = item.split("=")
        if counts.get(t, 0) != int(n):
            problems.append(f"{counts.get(t, 0)} {t}, expected {n}")
    if abs(total - args.volume) > 1e-4 * abs(args.volume):
        problems.append(f"volume {total!r}, expected {args.volume!r}")
    print(f"cgns_to_vtk + meshio: {counts}, volume {total!r}")
    if problems:
        print("\n".join(problems), file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
