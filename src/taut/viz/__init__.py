"""Figures (matplotlib). Only the CLI and users import this package; solvers never do.

Sheet-carrying teams
    :func:`plot_fk` draws the rest states of a forward-kinematics result,
    :func:`draw_equilibrium` one of them on given axes (colours by status in
    :data:`KIND_COLOURS`); :func:`plot_simulation` a quasi-static transport simulation.
Transport plans
    :func:`plot_plan` and :func:`animate_plan` a plan, :func:`draw_world` its world.
Cable-driven parallel robots
    :func:`plot_workspace`, :func:`plot_binding` and :func:`plot_workspace_comparison` the
    wrench-feasible workspace, :func:`draw_robot_outline` a robot's frame on given axes,
    :func:`plot_axis_capacities` and :func:`plot_capacity_bars` wrench and twist
    capacities, :func:`plot_deployment` a deployment, :func:`plot_control`,
    :func:`plot_comparison` and :func:`animate_control` control simulations,
    :func:`plot_mission` and :func:`animate_mission` a warehouse mission (:func:`draw_floor`
    its floor plan on given axes).
Physics replays
    :func:`plot_equilibria_check` the settled sheets of a :func:`taut.physics.replay_equilibria`
    beside taut's states, :func:`animate_settle` a drop.
Sweeps
    :func:`plot_sweep` a heat map or a curve of a results column.

The names are imported on first use (PEP 562), so drawing one figure does not import the
modules of every family.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import lazy_names

if TYPE_CHECKING:                   # the real names, for type checkers
    from .cdpr import draw_robot_outline, plot_axis_capacities, plot_workspace
    from .cdpr_binding import plot_binding
    from .cdpr_compare import plot_workspace_comparison
    from .cdpr_motion import plot_capacity_bars, plot_deployment
    from .cdpr_sim import animate_control, plot_comparison, plot_control
    from .cdpr_mission import animate_mission, draw_floor, plot_mission
    from .motion import plot_simulation
    from .physics import animate_settle, plot_equilibria_check
    from .plan import animate_plan, draw_world, plot_plan
    from .sheet import KIND_COLOURS, draw_equilibrium, plot_fk
    from .sweep import plot_sweep

__all__ = [
    # sheet-carrying teams
    "plot_fk", "draw_equilibrium", "KIND_COLOURS", "plot_simulation",
    # transport plans
    "plot_plan", "animate_plan", "draw_world",
    # cable-driven parallel robots
    "plot_workspace", "plot_binding", "plot_workspace_comparison", "draw_robot_outline",
    "plot_axis_capacities", "plot_capacity_bars", "plot_deployment", "plot_control",
    "plot_comparison", "animate_control", "plot_mission", "animate_mission", "draw_floor",
    # physics replays
    "plot_equilibria_check", "animate_settle",
    # sweeps
    "plot_sweep",
]

#: Module of each public name.
_HOME = {
    "plot_fk": "sheet", "draw_equilibrium": "sheet", "KIND_COLOURS": "sheet",
    "plot_simulation": "motion",
    "plot_plan": "plan", "animate_plan": "plan", "draw_world": "plan",
    "plot_workspace": "cdpr", "draw_robot_outline": "cdpr", "plot_axis_capacities": "cdpr",
    "plot_binding": "cdpr_binding", "plot_workspace_comparison": "cdpr_compare",
    "plot_capacity_bars": "cdpr_motion", "plot_deployment": "cdpr_motion",
    "plot_control": "cdpr_sim", "plot_comparison": "cdpr_sim", "animate_control": "cdpr_sim",
    "plot_mission": "cdpr_mission", "animate_mission": "cdpr_mission",
    "draw_floor": "cdpr_mission",
    "plot_equilibria_check": "physics", "animate_settle": "physics",
    "plot_sweep": "sweep",
}


__getattr__, __dir__ = lazy_names(__name__, _HOME, globals())
