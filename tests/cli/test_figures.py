"""Figures a reviewer accepts: legends, units, every equilibrium drawn or counted, a height
axis on which a 15 mm jump is visible."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")

from taut.io.sheet_scenario import load_sheet_scenario  # noqa: E402
from taut.io.trajectory import load_trajectory  # noqa: E402
from taut.sheet import forward_kinematics  # noqa: E402
from taut.sheet import simulate  # noqa: E402

ROOT = Path(__file__).parents[2]


def _fk(name):
    sc = load_sheet_scenario(ROOT / "examples" / "sheet" / name)
    return sc, forward_kinematics(sc.team, sc.formation)


def test_fk_figure_has_legend_units_and_counts_left_out_states():
    from taut.viz.sheet import plot_fk
    sc, res = _fk("example2_r2_r4_353mm.yaml")
    assert len(res.equilibria) == 6
    fig = plot_fk(res, units="mm", max_panels=2)
    labels = [t.get_text() for leg in fig.legends for t in leg.get_texts()]
    assert {"taut cable", "slack cable", "object: stable", "object: not equilibrium"} <= set(labels)
    assert "2 of 6 equilibria drawn (4 left out" in fig._suptitle.get_text()
    axes = fig.axes
    assert len(axes) == 2 and "stable" in axes[0].get_title()       # stable ones first
    for ax in axes:
        assert ax.get_xlabel() == "x [mm]" and ax.get_zlabel() == "z [mm]"
    fig_all = plot_fk(res, units="mm")
    assert fig_all._suptitle is None and len(fig_all.axes) == 6      # nothing left out
    matplotlib.pyplot.close("all")


def test_simulation_height_axis_shows_a_15_mm_jump():
    from taut.viz.motion import plot_simulation
    tdir = ROOT / "examples" / "sheet" / "trajectories"
    sc = load_sheet_scenario(tdir / "square4.yaml")
    traj = load_trajectory(tdir / "square4_jump.csv")
    res = simulate(sc.team, traj.formations)
    drop = res.jumps[0].drop
    assert 0.01 < drop < 0.02                                     # the 15 mm jump (m)
    fig = plot_simulation(res, time=traj.time, units=sc.units)
    ax_h = fig.axes[0]
    lo, hi = ax_h.get_ylim()
    assert drop / (hi - lo) > 0.3                                  # a third of the axis
    assert ax_h.get_xlabel() == "time [s]" and ax_h.get_ylabel().endswith("[m]")
    z = sc.team.hold_height
    assert str(z) in ax_h.get_title() or f"{z:g}" in ax_h.get_title()
    matplotlib.pyplot.close("all")
