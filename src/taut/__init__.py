"""taut: carrying loads with cables and mobile robots.

Subpackages
-----------
sheet : robot teams holding a deformable sheet (virtual variable cables model, VVCM).
plan  : motion planning for sheet-carrying teams, with obstacle crossing.
cdpr  : cable-driven parallel robots on fixed frames and mobile bases.
io    : scenario and model files.
viz   : figures.
"""

from . import errors
from .errors import TautError

__version__ = "0.1.0"
__all__ = ["errors", "TautError", "__version__"]
