"""Physics replays of taut's models in MuJoCo (optional extra ``taut[physics]``).

Each replay builds a MuJoCo model of a state taut computed, simulates it and compares the
outcome with taut's verdict. Importing this package needs no MuJoCo; running a simulation
does.

Sheet-carrying teams (the sheet as a node mesh with tension-only tendons)
    :func:`settle` drops the object on the sheet and returns a :class:`SettleResult`;
    :func:`replay_equilibria` ties the object at each rest state taut reports, releases it
    and returns an :class:`EquilibriaCheck` of one :class:`StateCheck` per state;
    :data:`DEFAULT_MESH` is the default mesh resolution.
Mobile cable robots (free-standing bases on a frictional floor)
    :func:`replay_tipping` simulates one pose under given tensions
    (:class:`TippingCheck`); :func:`replay_tipping_grid` a batch of poses
    (:class:`TippingGridCheck`).
"""

from .cdpr import TippingCheck, TippingGridCheck, replay_tipping, replay_tipping_grid
from .sheet import (DEFAULT_MESH, EquilibriaCheck, SettleResult, StateCheck,
                    replay_equilibria, settle)

__all__ = [
    # sheet-carrying teams
    "settle", "SettleResult", "replay_equilibria", "EquilibriaCheck", "StateCheck",
    "DEFAULT_MESH",
    # mobile cable robots
    "replay_tipping", "TippingCheck", "replay_tipping_grid", "TippingGridCheck",
]
