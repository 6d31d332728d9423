#!/usr/bin/env python3
"""Interoperability of blmesh's mesh files with meshio and Gmsh (run by tests/interop.rs).

usage:
  interop.py check MESH --expect TYPE=N [--expect ...] --volume V [--groups NAME,NAME,...]
      Load MESH (.msh, .vtu, .su2, .mesh, .meshb) with meshio and, for .msh, with Gmsh (gmsh.open +
      gmsh.model.mesh.getElements); compare the element counts by meshio type name (tetra,
      pyramid, wedge, hexahedron, triangle, quad) and the total cell volume (within 1e-9
      relative) with the expected values, and find every cell's volume positive in the reading
      tool's node order (Gmsh's, which is meshio's); for .msh also the physical group names. Exit 1 on
      any mismatch. SU2 stores prisms in VTK order and meshio's SU2 reader keeps it (meshio's
      wedge is Gmsh's), so the wedges read from .su2 are permuted back before the volume.
  interop.py convert MSH VTU OUTDIR
      Write other tools' files for blmesh to read: meshio's default VTU (zlib), its ASCII and
      uncompressed binary VTU (from VTU), meshio's MSH 2.2 (from MSH), and Gmsh's own MSH 4.1
      binary and MSH 2.2 ASCII (Gmsh opens MSH and saves it again).
"""
import argparse
import os
import sys

import numpy as np

# Outward faces of the meshio (= Gmsh) node orders, as in shared/bench/measure.py.
FACES = {
    "tetra": [(0, 2, 1), (0, 1, 3), (1, 2, 3), (0, 3, 2)],
    "pyramid": [(0, 3, 2, 1), (0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)],
    "wedge": [(0, 2, 1), (3, 4, 5), (0, 1, 4, 3), (1, 2, 5, 4), (2, 0, 3, 5)],
    "hexahedron": [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6),
                   (3, 0, 4, 7)],
}
GMSH_TYPES = {2: "triangle", 3: "quad", 4: "tetra", 5: "hexahedron", 6: "wedge", 7: "pyramid"}


def volume(points, cells):
    """Total volume of cells {type: (m, n) node arrays} (centroid joined to the face triangles)
    and the number of cells whose own volume is not positive."""
    total, nonpositive = 0.0, 0
    for ctype, conn in cells.items():
        if ctype not in FACES or len(conn) == 0:
            continue
        x = points[conn]
        c = x.mean(axis=1)
        per_cell = np.zeros(len(conn))
        for f in FACES[ctype]:
            fx = x[:, list(f)]
            if len(f) == 3:
                parts = [(fx[:, 0], fx[:, 1], fx[:, 2])]
            else:
                m = fx.mean(axis=1)
                parts = [(fx[:, i], fx[:, (i + 1) % 4], m) for i in range(4)]
            for a, b, d in parts:
                per_cell += np.einsum("ij,ij->i", a - c, np.cross(b - c, d - c)) / 6.0
        total += float(per_cell.sum())
        nonpositive += int((per_cell <= 0).sum())
    return total, nonpositive


def compare(label, counts, vol, expect, expected_volume, problems):
    vol, nonpositive = vol
    if nonpositive:
        problems.append(f"{label}: {nonpositive} cells with a volume <= 0")
    for t, n in expect.items():
        if counts.get(t, 0) != n:
            problems.append(f"{label}: {counts.get(t, 0)} {t}, expected {n}")
    extra = {t: n for t, n in counts.items() if t not in expect and n}
    if extra:
        problems.append(f"{label}: unexpected elements {extra}")
    if abs(vol - expected_volume) > 1e-9 * abs(expected_volume):
        problems.append(f"{label}: volume {vol!r}, expected {expected_volume!r}")


def check_meshio(path, expect, expected_volume, problems):
    import meshio
    m = meshio.read(path)
    counts, cells = {}, {}
    for block in m.cells:
        counts[block.type] = counts.get(block.type, 0) + len(block.data)
        cells.setdefault(block.type, []).append(np.asarray(block.data, dtype=np.int64))
    cells = {t: np.vstack(c) for t, c in cells.items()}
    if path.endswith(".su2") and "wedge" in cells:
        cells["wedge"] = cells["wedge"][:, [0, 2, 1, 3, 5, 4]]
    vol = volume(np.asarray(m.points, dtype=float)[:, :3], cells)
    compare("meshio", counts, vol, expect, expected_volume, problems)
    print(f"meshio: {counts}, volume {vol[0]!r}, {vol[1]} cells <= 0")


def check_gmsh(path, expect, expected_volume, groups, problems):
    import gmsh
    gmsh.initialize(["-noenv"], readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(path)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        index = np.zeros(int(tags.max()) + 1, dtype=np.int64)
        index[tags.astype(np.int64)] = np.arange(len(tags))
        points = coords.reshape(-1, 3)
        counts, cells = {}, {}
        types, _, node_tags = gmsh.model.mesh.getElements()
        for t, nodes in zip(types, node_tags):
            name = GMSH_TYPES.get(int(t), f"gmsh type {t}")
            n = gmsh.model.mesh.getElementProperties(t)[3]
            conn = index[np.asarray(nodes, dtype=np.int64)].reshape(-1, n)
            counts[name] = counts.get(name, 0) + len(conn)
            cells[name] = np.vstack([cells[name], conn]) if name in cells else conn
        vol = volume(points, cells)
        compare("gmsh", counts, vol, expect, expected_volume, problems)
        names = sorted(gmsh.model.getPhysicalName(d, t) for d, t in gmsh.model.getPhysicalGroups())
        if groups is not None and names != sorted(groups):
            problems.append(f"gmsh: physical groups {names}, expected {sorted(groups)}")
        print(f"gmsh: {counts}, volume {vol[0]!r}, {vol[1]} cells <= 0, physical groups {names}")
    finally:
        gmsh.finalize()


def convert(msh, vtu, outdir):
    import gmsh
    import meshio
    os.makedirs(outdir, exist_ok=True)
    m = meshio.read(vtu)
    m.write(os.path.join(outdir, "meshio_zlib.vtu"))
    m.write(os.path.join(outdir, "meshio_binary.vtu"), compression=None)
    m.write(os.path.join(outdir, "meshio_ascii.vtu"), binary=False)
    meshio.read(msh).write(os.path.join(outdir, "meshio22.msh"), file_format="gmsh22", binary=False)
    gmsh.initialize(["-noenv"], readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(msh)
        gmsh.option.setNumber("Mesh.Binary", 1)
        gmsh.write(os.path.join(outdir, "gmsh41_binary.msh"))
        gmsh.option.setNumber("Mesh.Binary", 0)
        gmsh.option.setNumber("Mesh.MshFileVersion", 2.2)
        gmsh.write(os.path.join(outdir, "gmsh22.msh"))
    finally:
        gmsh.finalize()
    print("wrote", sorted(os.listdir(outdir)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="command", required=True)
    c = sub.add_parser("check")
    c.add_argument("mesh")
    c.add_argument("--expect", action="append", default=[], help="TYPE=N (meshio type names)")
    c.add_argument("--volume", type=float, required=True)
    c.add_argument("--groups", help="comma-separated physical group names (.msh)")
    v = sub.add_parser("convert")
    v.add_argument("msh")
    v.add_argument("vtu")
    v.add_argument("outdir")
    a = ap.parse_args()
    if a.command == "convert":
        convert(a.msh, a.vtu, a.outdir)
        return 0
    expect = {k: int(n) for k, n in (e.split("=") for e in a.expect)}
    groups = a.groups.split(",") if a.groups else None
    problems = []
    check_meshio(a.mesh, expect, a.volume, problems)
    if a.mesh.endswith(".msh"):
        check_gmsh(a.mesh, expect, a.volume, groups, problems)
    for p in problems:
        print("MISMATCH", p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
