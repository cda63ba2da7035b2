"""Physics cross-checks of taut's models in MuJoCo (optional extra ``taut[physics]``).

The sheet of a sheet-carrying team as a node mesh with tension-only tendons
(:func:`settle`, :func:`check_equilibria`) and the mobile cable robot with free-standing
bases (:func:`check_tipping`, :func:`check_tipping_grid`). Importing this package needs
no MuJoCo; running a simulation does.
"""

from .cdpr import TippingCheck, TippingGridCheck, check_tipping, check_tipping_grid
from .sheet import (DEFAULT_MESH, EquilibriaCheck, SettleResult, StateCheck,
                    check_equilibria, settle)

__all__ = ["settle", "check_equilibria", "SettleResult", "StateCheck", "EquilibriaCheck",
           "DEFAULT_MESH", "check_tipping", "check_tipping_grid", "TippingCheck",
           "TippingGridCheck"]
