"""footfall: footstep planning for legged robots.

Subpackages: ``models`` (LIP, ALIP), ``planning`` (LIP walk, footstep planners), ``terrain``,
``solvers``, ``control``, ``quadruped``, ``sim``, ``viz``. The ``footfall`` command is in ``cli``.
"""

from footfall.errors import (
    FootfallError,
    InfeasibleError,
    InputError,
    SceneError,
    SolverUnavailableError,
)

__version__ = "0.1.0"

__all__ = [
    "FootfallError",
    "InfeasibleError",
    "InputError",
    "SceneError",
    "SolverUnavailableError",
    "__version__",
]
