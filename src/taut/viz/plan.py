"""Figures of transport plans, after the planning paper's Figs. 8-10: top view with robot
footprints, sheet outlines and the object's path, object height over time against the
obstacles beneath it, entering/exiting side angles during Algorithm 2 crossings (or the
robots' clearance), robot pair distances against their sheet limits; and an animated GIF."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import shapely  # noqa: E402
from matplotlib.animation import FuncAnimation  # noqa: E402
from matplotlib.patches import Circle  # noqa: E402
from matplotlib.patches import Polygon as PolygonPatch  # noqa: E402

from ..plan.checks.profile import plan_profile  # noqa: E402
from ..plan.result import PlanResult  # noqa: E402
from ..plan.world import Scenario  # noqa: E402
from ._save import save_figure, save_animation  # noqa: E402

__all__ = ["plot_plan", "animate_plan", "draw_world"]


def draw_world(ax, scenario: Scenario) -> None:
    """Walls and obstacles (shade by height, labelled with id and height)."""
    fs = scenario.world.free_space
    ax.add_patch(PolygonPatch(fs, closed=True, fill=False, lw=1.5, ec="k"))
    hmax = max([o.height for o in scenario.world.obstacles] + [scenario.team.hold_height])
    for o in scenario.world.obstacles:
        xy = np.asarray(o.geometry.exterior.coords)
        ax.add_patch(PolygonPatch(xy, closed=True, fc=plt.cm.Greys(0.3 + 0.6 * o.height / hmax),
                                  ec="k", lw=0.5))
        ax.annotate(f"{o.id}\n{o.height:.2f} m", o.mec_center, ha="center", va="center",
                    fontsize=7, color="tab:red")
    ax.plot(*scenario.start, "go")
    ax.plot(*scenario.goal, "r*", ms=10)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    pad = 0.2
    ax.set_xlim(fs[:, 0].min() - pad, fs[:, 0].max() + pad)
    ax.set_ylim(fs[:, 1].min() - pad, fs[:, 1].max() + pad)


def _top_view(ax, scenario: Scenario, r: PlanResult) -> None:
    """Walls, obstacles, robot paths, footprints and sheet outlines, the object's path."""
    draw_world(ax, scenario)
    for i in range(r.robots.shape[1]):
        ax.plot(r.robots[:, i, 0], r.robots[:, i, 1], lw=0.6, alpha=0.7, label=f"robot {i + 1}")
    ax.plot(r.object[:, 0], r.object[:, 1], "k-", lw=1.4, label="object")
    step = max(1, len(r.times) // 10)
    for t in [*range(0, len(r.times), step), len(r.times) - 1]:
        hull = shapely.convex_hull(shapely.multipoints(r.robots[t]))
        ax.add_patch(PolygonPatch(np.asarray(hull.exterior.coords), closed=True,
                                  fc="tab:blue", alpha=0.08, ec="tab:blue", lw=0.5))
        for p in r.robots[t]:
            ax.add_patch(Circle(p, scenario.team.robot_radius, fill=False, ec="tab:blue",
                                lw=0.4, alpha=0.6))
    ax.set_title(f"top view: crossed {list(r.crossed)}, {r.duration:.1f} s, "
                 f"{r.path_length:.2f} m")
    ax.legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)


def _sides(ax, r: PlanResult) -> None:
    """Entering/exiting side angles during Algorithm 2 crossings."""
    for c in (c for c in r.crossings if c.kind == "algorithm2"):
        sel = (r.times >= c.times[0]) & (r.times <= c.times[4])
        ent = np.degrees(np.angle(np.exp(1j * (r.heading[sel] + c.entering - c.direction))))
        ext = np.degrees(np.angle(np.exp(1j * (r.heading[sel] + c.exiting - c.direction
                                               - np.pi))))
        ax.plot(r.times[sel], ent, label=f"{c.obstacle}: entering side")
        ax.plot(r.times[sel], ext, "--", label=f"{c.obstacle}: exiting side")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("angle to travel axis [deg]")
    ax.set_title("entering/exiting sides (Algorithm 2 crossings)")
    ax.legend(fontsize=7)


def _clearances(ax, scenario: Scenario, r: PlanResult) -> None:
    """Least robot-centre distance to a wall or an obstacle over time against the rule
    (robot radius + lateral safety) and the robot radius (footprint contact)."""
    world, team = scenario.world, scenario.team
    pts = shapely.points(r.robots.reshape(-1, 2))
    d = shapely.distance(world.geometry.exterior, pts)
    for o in world.obstacles:
        d = np.minimum(d, shapely.distance(o.geometry, pts))
    least = d.reshape(r.robots.shape[:2]).min(axis=1)
    ax.plot(r.times, least, label="least robot clearance")
    ax.axhline(team.clearance, color="k", ls="--", lw=0.8,
               label=f"rule: radius + lateral safety ({team.clearance:.2f} m)")
    ax.axhline(team.robot_radius, color="tab:red", ls=":", lw=0.8,
               label=f"footprint contact ({team.robot_radius:.2f} m)")
    ax.set_ylim(0.0, max(float(least.max()), team.clearance) * 1.1)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("distance to walls and obstacles [m]")
    ax.set_title("robot clearance (least over robots)")
    ax.legend(fontsize=7)


def _distances(ax, scenario: Scenario, r: PlanResult) -> None:
    """Pairwise robot distances against their sheet limits (and the margin); above ten
    pairs the others are grey and only the pair with the least slack is named. Up to ten,
    each pair has its own dash and a thinner line than the one before, so a pair drawn on
    top of an equal one (a rigid formation) still shows, and its label names the pair it
    coincides with."""
    n = r.robots.shape[1]
    V = scenario.team.sheet.vertices
    iu, ju = np.triu_indices(n, 1)
    d = np.linalg.norm(r.robots[:, iu] - r.robots[:, ju], axis=2)
    limit = np.linalg.norm(V[iu] - V[ju], axis=1)
    ratio = d / limit
    tightest = int(np.argmin((limit[None] - d).min(axis=0)))
    names = [f"|r{i + 1} - r{j + 1}|" for i, j in zip(iu, ju)]
    for k in range(len(iu)):
        name = names[k]
        if len(iu) <= 10:
            same = [m for m in range(k) if np.allclose(ratio[:, m], ratio[:, k], atol=1e-3)]
            ax.plot(r.times, ratio[:, k], lw=max(0.8, 2.6 - 0.45 * k),
                    ls=("-", "--", ":", "-.")[k % 4],
                    label=name + (f" (= {names[same[0]]})" if same else ""))
        elif k == tightest:               # many pairs: name only the one nearest its limit
            ax.plot(r.times, ratio[:, k], lw=1.2, color="tab:red",
                    label=f"{name} (least slack)", zorder=3)
        else:
            ax.plot(r.times, ratio[:, k], lw=0.6, color="0.7")
    ax.axhline(1.0, color="k", lw=1.0, label="sheet limit")
    if r.sheet_margin > 0:
        ax.axhline(1.0 - r.sheet_margin / limit.min(), color="k", ls=":", lw=0.8,
                   label=f"margin {r.sheet_margin * 1e3:.0f} mm (shortest pair)")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("robot distance / sheet distance")
    ax.set_title(f"pair distances vs sheet limits (least slack "
                 f"{plan_profile(r).sheet_slack_m.min() * 1e3:.1f} mm)")
    ax.set_ylim(min(0.0, float(ratio.min()) - 0.05), 1.08)
    ax.legend(fontsize=6, ncol=2 if len(iu) <= 10 else 1)


def _headings(ax, tr) -> None:
    """Robot headings of executed trajectories (:func:`taut.plan.robot_trajectories`) as
    arrows at about 12 instants (one robot radius long, in the top view's m)."""
    T = len(tr.times)
    at = np.unique(np.linspace(0, T - 1, min(T, 12)).round().astype(int))
    p = tr.poses[at]
    ax.quiver(p[..., 0], p[..., 1], np.cos(p[..., 2]), np.sin(p[..., 2]), color="tab:red",
              angles="xy", scale_units="xy", scale=8.0, width=0.004,
              label=f"{tr.drive} robot headings")


def plot_plan(scenario: Scenario, result: PlanResult, path: str | Path, *,
              trajectories=None) -> None:
    """Four-panel summary figure of a successful plan (PNG/PDF by extension): top view
    with robot footprints, sheet outlines and the object's path (and, given executed
    ``trajectories``, the robots' headings as arrows); object height against
    the obstacles beneath the sheet; entering/exiting sides of Algorithm 2 crossings
    (plans with such crossings) or else the robots' clearance against its rule;
    pairwise robot distances against their sheet limits."""
    r = result
    fig, axs = plt.subplots(2, 2, figsize=(12, 8))
    if trajectories is not None and trajectories.success:
        _headings(axs[0, 0], trajectories)
    _top_view(axs[0, 0], scenario, r)
    ax = axs[0, 1]
    profile = plan_profile(r)
    ax.plot(profile.times_s, profile.object_height_m, label="object height (model)")
    ax.fill_between(profile.times_s, 0, profile.beneath_height_m, color="0.6", step="mid",
                    label="tallest obstacle beneath the sheet")
    ax.plot(profile.times_s, profile.beneath_height_m + scenario.team.height_safety,
            color="0.3", ls="--", lw=0.7, label="+ height safety")
    ax.axhline(scenario.team.hold_height, color="k", ls=":", lw=0.8, label="hold height")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("height [m]")
    ax.legend(fontsize=7)
    ax.set_title("object height vs obstacles beneath")
    if any(c.kind == "algorithm2" for c in r.crossings):
        _sides(axs[1, 0], r)
    else:
        _clearances(axs[1, 0], scenario, r)
    _distances(axs[1, 1], scenario, r)
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    plt.close(fig)


def animate_plan(scenario: Scenario, result: PlanResult, path: str | Path, *,
                 frames: int = 80, fps: int = 12) -> None:
    """Animated GIF of the transport (top view: sheet, robot footprints, object; the
    title gives the time and the object's height), written with Pillow."""
    r = result
    idx = np.unique(np.linspace(0, len(r.times) - 1, frames).round().astype(int))
    fig, ax = plt.subplots(figsize=(8, 4.5))
    draw_world(ax, scenario)
    sheet = PolygonPatch(r.robots[0], closed=True, fc="tab:blue", alpha=0.25, ec="tab:blue")
    ax.add_patch(sheet)
    bots = [Circle(p, scenario.team.robot_radius, fc="tab:blue", alpha=0.6)
            for p in r.robots[0]]
    for c in bots:
        ax.add_patch(c)
    obj = ax.scatter([r.object[0, 0]], [r.object[0, 1]], s=40, c="tab:orange", zorder=5)
    title = ax.set_title("")

    def update(k: int):
        t = idx[k]
        sheet.set_xy(r.robots[t])
        for c, p in zip(bots, r.robots[t]):
            c.center = tuple(p)
        obj.set_offsets(r.object[t, :2][None])
        title.set_text(f"t = {r.times[t]:.1f} s, object height {r.object[t, 2]:.3f} m")
        return (sheet, *bots, obj, title)

    anim = FuncAnimation(fig, update, frames=len(idx), blit=False)
    save_animation(anim, path, fps=fps)
    plt.close(fig)
