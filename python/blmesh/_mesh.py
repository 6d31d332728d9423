"""The mesh `blmesh.mesh` returns: numpy arrays of its points, cells and boundary, its report,
and writers for every output format of `blmesh mesh`."""

import dataclasses
import functools
import json
import os

import numpy as np

from . import _native

# Our cell kinds and meshio's names for them (same node orders: Gmsh's).
MESHIO_TYPES = {"tetrahedron": "tetra", "pyramid": "pyramid", "prism": "wedge", "hexahedron": "hexahedron"}


def _array(data, dtype, width=None, as_type=None):
    """A read-only array of the native bytes `data`, rows of `width`, converted to `as_type`."""
    array = np.frombuffer(data, dtype=dtype)
    if as_type is not None:
        array = array.astype(as_type)
        array.flags.writeable = False
    return array.reshape(-1, width) if width else array


@dataclasses.dataclass(frozen=True)
class Boundary:
    """The boundary faces, oriented out of the domain, with the patch (index into
    ``patch_names``) of each."""

    triangles: np.ndarray
    triangle_patches: np.ndarray
    quads: np.ndarray
    quad_patches: np.ndarray
    patch_names: list


class Mesh:
    """A hybrid volume mesh made by `blmesh.mesh` (read-only arrays).

    points: float64 (N, 3); cells: {kind: int64 (n, nodes)} for the kinds "tetrahedron",
    "pyramid", "prism" and "hexahedron" in Gmsh's node orders (meshio's), empty ones included;
    cell_zones: {kind: int32 (n,)} indices into zone_names; boundary: `Boundary`; report: the
    run's report (`blmesh mesh --report`) as a dict.
    """

    def __init__(self, native):
        self._native = native

    @functools.cached_property
    def points(self):
        return _array(self._native.points(), np.float64, 3)

    @functools.cached_property
    def _blocks(self):
        return {
            kind: (_array(nodes, np.uint32, width, np.int64), _array(zones, np.uint32, None, np.int32))
            for kind, width, nodes, zones in self._native.cells()
        }

    @property
    def cells(self):
        return {kind: nodes for kind, (nodes, _) in self._blocks.items()}

    @property
    def cell_zones(self):
        return {kind: zones for kind, (_, zones) in self._blocks.items()}

    @property
    def zone_names(self):
        return self._native.zone_names()

    @functools.cached_property
    def boundary(self):
        triangles, triangle_patches, quads, quad_patches = self._native.boundary()
        return Boundary(
            triangles=_array(triangles, np.uint32, 3, np.int64),
            triangle_patches=_array(triangle_patches, np.uint32, None, np.int32),
            quads=_array(quads, np.uint32, 4, np.int64),
            quad_patches=_array(quad_patches, np.uint32, None, np.int32),
            patch_names=self._native.patch_names(),
        )

    @functools.cached_property
    def report(self):
        return json.loads(self._native.report_json())

    def write(self, path, ascii=False):
        """Write the mesh; the format follows the name as for `blmesh mesh -o`: .msh (binary
        unless ascii), .vtu, .su2, .mesh, .meshb, .cgns, .ugrid/.b8.ugrid/.lb8.ugrid, or an
        OpenFOAM case's .../constant/polyMesh directory."""
        self._native.write(os.fspath(path), ascii)

    def write_report(self, path):
        """Write the report as JSON (`blmesh mesh --report`)."""
        self._native.write_report(os.fspath(path))

    def write_pictures(self, directory):
        """Write PNG cuts and histograms into a directory (`blmesh mesh --pictures`)."""
        self._native.write_pictures(os.fspath(directory))

    def to_meshio(self):
        """A meshio.Mesh of the volume cells, with their zone as cell data "zone"."""
        import meshio

        blocks = [(kind, nodes, zones) for kind, (nodes, zones) in self._blocks.items() if len(nodes)]
        return meshio.Mesh(
            self.points,
            [(MESHIO_TYPES[kind], nodes) for kind, nodes, _ in blocks],
            cell_data={"zone": [zones for _, _, zones in blocks]},
        )

    def to_pyvista(self):
        """A pyvista.UnstructuredGrid of the volume cells, with cell data "zone".

        The cells go in our (Gmsh's) node orders, prisms too: VTK's implementation takes a
        wedge whose (0, 1, 2) normal points to the top (VTK 9.7's cell sizes and cell validator
        find those positive and valid, the permuted ones of VTK's documentation inverted).
        """
        import pyvista

        vtk_types = {
            "tetrahedron": pyvista.CellType.TETRA,
            "pyramid": pyvista.CellType.PYRAMID,
            "prism": pyvista.CellType.WEDGE,
            "hexahedron": pyvista.CellType.HEXAHEDRON,
        }
        blocks = [(kind, nodes, zones) for kind, (nodes, zones) in self._blocks.items() if len(nodes)]
        grid = pyvista.UnstructuredGrid({vtk_types[kind]: nodes for kind, nodes, _ in blocks}, np.array(self.points))
        zones = [zones for _, _, zones in blocks]
        grid.cell_data["zone"] = np.concatenate(zones) if zones else np.zeros(0, np.int32)
        return grid

    def __repr__(self):
        counts = ", ".join(f"{len(nodes)} {kind}" for kind, nodes in self.cells.items() if len(nodes))
        return f"<blmesh.Mesh: {len(self.points)} points; {counts}>"

    def __str__(self):
        return self._native.summary()
