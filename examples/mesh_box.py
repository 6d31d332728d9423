"""Mesh the example box from Python: 10 layers from a first height of 1e-3, a progress bar,
the summary `blmesh mesh` prints, a VTU file checked the way `blmesh check` does, and the mesh
as meshio sees it (when meshio is installed).

    python examples/mesh_box.py [OUT.vtu]
"""

import pathlib
import sys

import blmesh

here = pathlib.Path(__file__).resolve().parent
out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "box.vtu")

mesh = blmesh.mesh(here / "box.stl", first_height=0.001, growth=1.2, layers=10, progress=True)
print(mesh)
print({kind: nodes.shape for kind, nodes in mesh.cells.items()})
print("patches:", mesh.boundary.patch_names)

mesh.write(out)
report = blmesh.check(out)
print(f"{out}: {report['cells']}, accepted by a finite-volume solver: {report['accepted']}")

try:
    print(mesh.to_meshio())
except ImportError:
    print("meshio is not installed: pip install meshio")
