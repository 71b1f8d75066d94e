"""polyscrew: coordinate-free smoothing of rigid-body motions (the ScrewBender core).

Poses are float64 arrays of shape (4, 4) or (N, 4, 4) in Blender's layout (translation in
the last column). Every function checks its input and raises ``ValueError`` naming the bad
index and the reason. See ``__init__.pyi`` for the signatures.
"""

from ._polyscrew import *  # noqa: F401,F403
from ._polyscrew import MAX_LEVELS, Screw  # noqa: F401

__all__ = [name for name in dir() if not name.startswith("_")]
