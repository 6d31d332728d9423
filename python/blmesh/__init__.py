"""blmesh: boundary-layer volume meshes for CFD.

    import blmesh
    m = blmesh.mesh("examples/box.stl", first_height=0.001, layers=10)
    m.write("box.vtu")
    print(blmesh.check("box.vtu")["accepted"])

`mesh` takes `blmesh mesh`'s settings as keyword arguments (`first_height`, `growth`, `layers`,
`thickness`, `feature_angle`, `fan_angle`, `peel_rounds`, `no_core`, `no_adapt`,
`no_transition`) on top of `config=`, a TOML file (docs/configuration.md) or a dict of its keys.
"""

import json
import os

from . import _native
from ._mesh import Boundary, Mesh
from ._progress import observer
from .errors import BlmeshError, InputError, MeshingError, OutputError

__version__ = _native.__version__
__all__ = [
    "mesh",
    "check",
    "info",
    "Mesh",
    "Boundary",
    "BlmeshError",
    "InputError",
    "MeshingError",
    "OutputError",
]


def mesh(surface, *, config=None, progress=None, **settings):
    """Mesh a closed triangle surface file (.stl, .obj, .off, .msh, .mesh, .meshb, .tri, .uh3d).

    config: a TOML file's path, or a dict of its keys (``{"layers": {"count": 10}}``);
    settings: `blmesh mesh`'s flags by name, on top of the config (None: not given);
    progress: a callable ``(stage, fraction)``, or True for a bar (tqdm when installed).
    The GIL is released while meshing. Raises InputError or MeshingError.
    """
    settings = {k: v for k, v in settings.items() if v is not None}
    config_path = config_json = None
    if isinstance(config, (str, os.PathLike)):
        config_path = os.fspath(config)
    elif isinstance(config, dict):
        config_json = json.dumps(config)
    elif config is not None:
        raise InputError(f"config must be a TOML file's path or a dict, not {type(config).__name__}")
    with observer(progress) as callback:
        native = _native.mesh(
            os.fspath(surface), json.dumps(settings), config_path, config_json, callback
        )
    return Mesh(native)


def check(path_or_mesh):
    """Check a mesh (a Mesh, or a .msh, .vtu or .cgns file) as `blmesh check` does.

    Returns its report as a dict; ``report["accepted"]`` is True exactly when `blmesh check`
    exits with 0 (a valid mesh a finite-volume solver takes).
    """
    if isinstance(path_or_mesh, Mesh):
        return json.loads(path_or_mesh._native.check())
    return json.loads(_native.check_file(os.fspath(path_or_mesh)))


def info(surface, feature_angle=None):
    """Describe a surface file as `blmesh info --json` does (also an invalid one: `validation`);
    feature_angle in degrees, 30 by default."""
    return json.loads(_native.info(os.fspath(surface), feature_angle))
