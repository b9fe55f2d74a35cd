"""edgefem: edge-based StVK tetrahedral FEM (meshes, scenes, simulator, kernels).

The compiled extension is edgefem._edgefem; this package re-exports it, and
ships its type stubs (__init__.pyi, py.typed: PEP 561)."""
from ._edgefem import *  # noqa: F401,F403
from ._edgefem import __doc__, __version__  # noqa: F401
