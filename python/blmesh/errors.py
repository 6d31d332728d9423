"""The exceptions of blmesh. Their message is the one `blmesh` on the command line prints."""


class BlmeshError(Exception):
    """Any error of blmesh."""


class InputError(BlmeshError, ValueError):
    """A bad surface or mesh file, setting or configuration, or an output name of no known format."""


class MeshingError(BlmeshError, RuntimeError):
    """The mesher failed on valid input (the core fill, closing the layers, its own check)."""


class OutputError(BlmeshError, OSError):
    """An output could not be written."""
