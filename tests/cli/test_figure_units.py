"""Every figure type rendered headless (Agg) and inspected: each data panel has a title
(its own or the figure's), axis labels with units (``[m]``, ``(N)``, ...) unless the axis is
categorical (named ticks), and a legend wherever more than one labelled artist is drawn; no
legend or title covers an axis label and no title is cut by the figure's edge (drawn
extents, issue 29.5). The wrench-capacity chart says which direction it plots."""

from __future__ import annotations

import functools
import re
from pathlib import Path

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = Path(__file__).parents[2]
UNIT = re.compile(r"\[[^\]]+\]|\([^)]*(m|N|s|%|deg|rad|mm)[^)]*\)|/")


def _panels(fig):
    """Data panels (colorbars, which only carry a label, are left out)."""
    return [ax for ax in fig.axes if ax.get_label() != "<colorbar>" and ax.has_data()]


def _overlap(a, b) -> bool:
    """Whether two display boxes share area (touching edges do not count)."""
    return (min(a.x1, b.x1) - max(a.x0, b.x0) > 0.5) and (min(a.y1, b.y1) - max(a.y0, b.y0) > 0.5)


def _check_layout(fig):
    """No legend or title covers an axis label; every title lies inside the figure."""
    if not hasattr(fig.canvas, "get_renderer"):       # a figure closed after saving
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        FigureCanvasAgg(fig)
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    labels = [(t.get_text(), t.get_window_extent(r)) for ax in fig.axes
              for t in [ax.xaxis.label, ax.yaxis.label] + ([ax.zaxis.label]
                                                            if hasattr(ax, "zaxis") else [])
              if t.get_text() and t.get_visible()]
    legends = [lg for lg in [ax.get_legend() for ax in fig.axes] + list(fig.legends)
               if lg is not None]
    titles = [t for ax in fig.axes for t in (ax.title, ax._left_title, ax._right_title)
              if t.get_text()] + ([fig._suptitle] if fig._suptitle is not None else [])
    page = fig.bbox
    for lg in legends:
        box = lg.get_window_extent(r)
        for text, lab in labels:
            assert not _overlap(box, lab), f"legend covers the axis label {text!r}"
    for t in titles:
        box = t.get_window_extent(r)
        assert (box.x0 >= page.x0 - 1 and box.x1 <= page.x1 + 1 and box.y0 >= page.y0 - 1
                and box.y1 <= page.y1 + 1), f"title {t.get_text()!r} is cut by the figure edge"
        for text, lab in labels:
            assert not _overlap(box, lab), f"title {t.get_text()!r} covers the label {text!r}"


def _check(fig, *, min_panels: int = 1):
    _check_layout(fig)
    panels = _panels(fig)
    assert len(panels) >= min_panels
    suptitle = fig._suptitle.get_text() if fig._suptitle is not None else ""
    for ax in panels:
        assert ax.get_title() or suptitle, "panel without a title"
        axes = [("x", ax.get_xlabel(), ax.get_xticklabels()),
                ("y", ax.get_ylabel(), ax.get_yticklabels())]
        if hasattr(ax, "get_zlabel"):
            axes.append(("z", ax.get_zlabel(), []))
        for name, label, ticks in axes:
            categorical = name == "x" and any(re.search("[A-Za-z]", t.get_text())
                                               for t in ticks)
            shared = name == "x" and not label and any(     # sharex: labelled at the bottom
                UNIT.search(a.get_xlabel()) for a in ax.get_shared_x_axes().get_siblings(ax))
            assert categorical or shared or UNIT.search(label), \
                f"{name} axis {label!r} has no unit"
        labelled = [h for h in ax.get_legend_handles_labels()[1] if not h.startswith("_")]
        if len(labelled) > 1:
            assert ax.get_legend() is not None or fig.legends, f"no legend for {labelled}"
    plt.close(fig)


def _drawn(draw):
    """The figure ``draw()`` saves (saving is intercepted)."""
    captured = {}
    real = plt.Figure.savefig
    plt.Figure.savefig = lambda self, *a, **k: captured.setdefault("fig", self)
    try:
        draw()
    finally:
        plt.Figure.savefig = real
    return captured["fig"]


def test_fk_figure():
    from taut.io.sheet_scenario import load_sheet_scenario
    from taut.sheet import forward_kinematics
    from taut.viz.sheet import plot_fk
    sc = load_sheet_scenario(ROOT / "examples" / "sheet" / "example1.yaml")
    r = forward_kinematics(sc.team, sc.formation)
    _check(plot_fk(r, units="mm"))


@functools.cache
def _paper_plan(method):
    """The paper corridor and its plan by ``method``: planned once for this file's plan
    figures (~0.8 s of CPU a plan), which only read them."""
    from taut.io import load_plan_scenario
    from taut.plan import plan
    sc = load_plan_scenario(ROOT / "examples" / "plan" / "paper_corridor.yaml")
    return sc, plan(sc, method=method)


def test_plan_top_view_has_metres_on_both_axes(tmp_path):
    from taut.plan import generate_scenario
    from taut.viz.plan import plot_plan
    from taut.viz.plan import draw_world
    fig, ax = plt.subplots()
    draw_world(ax, generate_scenario(0))    # the top view of plot_plan and animate_plan
    assert ax.get_xlabel() == "x [m]" and ax.get_ylabel() == "y [m]"
    plt.close(fig)
    sc, r = _paper_plan("se2")          # crosses both obstacles (test_se2.py: paper plan)
    assert r.success, r.message
    fig = _drawn(lambda: plot_plan(sc, r, tmp_path / "p.png"))
    top = fig.axes[0]
    assert top.get_xlabel() == "x [m]" and top.get_ylabel() == "y [m]"
    _check(fig, min_panels=3)


def test_cdpr_figures():
    from taut.cdpr import (axis_capacities, grid_points, twist_capacities,
                           wrench_feasible_workspace)
    from taut.io import load_cdpr_model
    from taut.viz.cdpr import plot_axis_capacities, plot_workspace
    from taut.viz.cdpr_binding import plot_binding
    from taut.viz.cdpr_motion import plot_capacity_bars
    robot = load_cdpr_model("fastkit")
    pts, shape = grid_points([[-1.0, 0.0, 0.5], [1.0, 0.0, 1.5]], (5, 1, 3))
    ws = wrench_feasible_workspace(robot, pts, shape=shape)
    _check(plot_workspace(ws, robot))
    _check(plot_binding(ws, robot))
    pose = [0.0, 0.0, 1.0]
    fig = plot_axis_capacities(axis_capacities(robot, pose, tipping=False),
                               axis_capacities(robot, pose))
    assert "direction" in fig._suptitle.get_text()
    _check(fig, min_panels=2)
    tc = twist_capacities(robot, pose)
    v = np.minimum(tc.positive, tc.negative)          # one pose: one result (m,)
    _check(plot_capacity_bars({"bases moving": v}, tc.labels,
                              ["m/s"] * 3 + ["rad/s"] * 3, "twist capacity (+ and - min)"))


@pytest.mark.slow
def test_deployment_figure_readable():
    from taut.cdpr import DeploymentOptions, plan_deployment
    from taut.io import load_cdpr_model
    from taut.viz.cdpr_motion import plot_deployment
    robot = load_cdpr_model("fastkit")
    r = plan_deployment(robot, [-0.5, 0.5, -0.05, 0.05, 0.6, 1.2],
                        options=DeploymentOptions(maxiter=1, popsize=2))
    fig = plot_deployment(r)
    w, h = fig.get_size_inches()
    assert w >= 8 and h >= 5
    fig.canvas.draw()
    texts = [t for t in fig.axes[0].texts if t.get_text()]
    boxes = [t.get_window_extent() for t in texts]
    for i in range(len(boxes)):
        for j in range(i + 1, len(boxes)):
            assert not boxes[i].overlaps(boxes[j]), (texts[i].get_text(), texts[j].get_text())
    _check(fig)


def test_sweep_figure(tmp_path):
    from taut.viz.sweep import plot_sweep
    cols = {"scale": np.repeat([0.8, 0.9, 1.0], 2), "stretch": np.tile([1.0, 1.1], 3),
            "count": np.array([1.0, 2, 2, 3, 1, 1])}
    captured = {}
    real = plt.Figure.savefig
    plt.Figure.savefig = lambda self, *a, **k: captured.setdefault("fig", self)
    try:
        plot_sweep(cols, "scale", "count", tmp_path / "s.png", y="stretch",
                   labels={"scale": "scale [-]", "stretch": "stretch [-]",
                           "count": "equilibria"})
    finally:
        plt.Figure.savefig = real
    _check(captured["fig"])


@pytest.mark.parametrize("method", ["se2", "algorithm2"])
def test_plan_figure_shows_sides_only_for_algorithm2_crossings(tmp_path, method):
    from taut.viz.plan import plot_plan
    sc, r = _paper_plan(method)
    assert r.success
    fig = _drawn(lambda: plot_plan(sc, r, tmp_path / "p.png"))
    third = fig.axes[2].get_title()
    if method == "algorithm2":
        assert "entering/exiting" in third
    else:                                 # no Algorithm 2 crossing: the clearance panel
        assert "clearance" in third
        rule = [ln.get_ydata()[0] for ln in fig.axes[2].get_lines()[1:]]
        assert sc.team.clearance in rule and sc.team.robot_radius in rule
    distances = fig.axes[3]
    assert "sheet limit" in [t.get_text() for t in distances.get_legend().get_texts()]
    pairs = [ln for ln in distances.get_lines() if ln.get_label().startswith("|r")]
    looks = {(ln.get_linestyle(), ln.get_linewidth()) for ln in pairs}
    assert len(looks) == len(pairs) == 3          # a pair drawn over an equal one still shows
    for k, ln in enumerate(pairs):                # and a coinciding pair says which it equals
        same = [m for m in pairs[:k] if np.allclose(m.get_ydata(), ln.get_ydata(), atol=1e-3)]
        assert ("(= " in ln.get_label()) == bool(same)
    _check(fig, min_panels=4)


@pytest.mark.slow                     # a 1 s control simulation (about 5 s with set-up)
def test_cable_simulation_figure_and_animation_bases(tmp_path, monkeypatch):
    from taut.cdpr import TorqueController, pick_and_place, simulate, with_stabilisers
    from taut.io import load_cdpr_model
    from taut.io.cdpr_dynamics import load_cdpr_dynamics
    import taut.viz.cdpr_sim as vs
    robot = with_stabilisers(load_cdpr_model("fastkit"))
    ref = pick_and_place(robot, [[-0.2, 0, 0.9], [0.2, 0, 0.9]], dwell=0.1)
    run = simulate(robot, ref, TorqueController(), dynamics=load_cdpr_dynamics("fastkit"))
    fig = vs.plot_control(run, title="torque control: " + "a long message " * 12)
    tipping = fig.axes[2]
    assert tipping.get_legend() is not None                # one entry per support edge
    assert len(tipping.get_legend().get_texts()) == len(run.edge_names) + 1
    _check(fig, min_panels=4)
    captured = {}

    def keep(anim, path, fps):                 # instead of saving: keep it to inspect
        anim._draw_was_started = True          # (matplotlib warns about unsaved animations)
        captured["a"] = anim

    monkeypatch.setattr(vs, "save_animation", keep)
    vs.animate_control(robot, run, tmp_path / "a.gif", frames=2)
    anim = captured["a"]
    anim._func(0)
    ax = anim._fig.axes[0]
    assert "base footprint" in [ln.get_label() for ln in ax.get_lines()]
    drawn = [ln for ln in ax.get_lines() if ln.get_color() == "0.25"]
    assert len(drawn) == sum(b.footprint is not None for b in robot.bases) == 2
    for ln in drawn:                                       # wheel footprints on the ground
        x, y, z = ln.get_data_3d()
        assert len(x) >= 4 and np.allclose(z, 0.0)
    posts = next(ln for ln in ax.get_lines() if ln.get_label() == "base posts")
    assert np.nanmax(posts.get_data_3d()[2]) > 1.0          # up to the exit points


def test_wrench_set_figure_says_infeasible():
    from taut.cdpr import axis_capacities
    from taut.io import load_cdpr_model
    from taut.viz.cdpr import plot_axis_capacities
    robot = load_cdpr_model("fastkit")
    pose = [0.0, 0.0, 1.2]                                  # a mobile base tips here
    tip = axis_capacities(robot, pose)
    assert not tip.feasible.all()
    fig = plot_axis_capacities(axis_capacities(robot, pose, tipping=False), tip)
    assert "with tipping: infeasible" in fig._suptitle.get_text()
    notes = [t.get_text() for ax in fig.axes for t in ax.texts]
    assert notes.count(" 0: infeasible") == 6
    _check(fig, min_panels=2)
