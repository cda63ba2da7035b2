"""taut.physics benchmark and accuracy study: MuJoCo vs taut's sheet forward kinematics.

Usage::

    python bench/bench_physics.py [--teams 20] [--seed 0] [--json OUT]

Measures, in one process on this machine:

* per mesh spacing (``mesh`` = spacings across the sheet's widest vertex pair) on the FK
  paper's Example 1 (4 robots) and Example 2 (8 robots): nodes, tendons (with the corner
  tendons), time to mesh and compile one state's model, wall time of
  ``replay_equilibria`` over every state, and the largest height / lateral differences
  physics vs taut (tied point load and released ball); the spacings are interleaved and
  repeated, medians and ranges quoted;
* on random teams (``taut.sheet.random_hanging_team``, 3-8 robots, sheets 500-1000 mm
  across, hold heights 0.8-1.5 sheet radii: issue 31's sample), failed simulations, the
  distribution of the differences, the sheet's sideways pull
  at stable and at non-equilibrium states, how often physics holds a state taut does not
  call stable and vice versa, and the wall time per team.

Numbers depend on the machine's load (it is shared); quote them with that caveat.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from taut.io import load_sheet_scenario
from taut.physics import replay_equilibria
from taut.physics._mesh import sheet_mesh
from taut.physics._sheet_model import build_sheet_sim
from taut.sheet import forward_kinematics
from taut.sheet import random_hanging_team

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = {"Example 1": ROOT / "examples/sheet/example1.yaml",
            "Example 2": ROOT / "examples/sheet/example2_r2_r4_353mm.yaml"}


def _lateral(d: np.ndarray) -> float:
    return float(np.hypot(d[0], d[1]))


def _build_time(sc, mesh: int) -> tuple[float, int]:
    """Seconds to mesh and compile the model of the first state; its tendon count."""
    team = sc.team
    eq = forward_kinematics(team, sc.formation).equilibria[0]
    D = float(np.max(team.sheet.side_lengths()))
    t0 = time.perf_counter()
    m = sheet_mesh(team.sheet.vertices, mesh, contact=eq.contact)
    sim = build_sheet_sim(m, team.sheet.vertices, sc.formation, team.hold_height,
                          ball_radius=0.05 * D / mesh, ball_start=None, tie=True,
                          corner_tendons=True)
    return time.perf_counter() - t0, int(sim.model.ntendon)


def spacing_table(meshes: list[int], repeats: int) -> list[dict]:
    rows: dict[tuple[str, int], list] = {}
    builds: dict[tuple[str, int], list] = {}
    for rep in range(repeats):
        for name, path in EXAMPLES.items():
            sc = load_sheet_scenario(path)
            for mesh in meshes:
                builds.setdefault((name, mesh), []).append(_build_time(sc, mesh))
                t0 = time.perf_counter()
                r = replay_equilibria(sc.team, sc.formation, mesh=mesh)
                wall = time.perf_counter() - t0
                rows.setdefault((name, mesh), []).append((wall, r))
    out = []
    for (name, mesh), runs in rows.items():
        sc = load_sheet_scenario(EXAMPLES[name])
        m = sheet_mesh(sc.team.sheet.vertices, mesh)
        walls = np.array([w for w, _ in runs])
        r = runs[-1][1]
        stable = [s for s in r.states if s.kind == "stable" and s.success]
        out.append({
            "example": name, "mesh": mesh, "spacing": m.spacing, "nodes": len(m.nodes),
            "tendons": builds[(name, mesh)][0][1],
            "build_median_s": float(np.median([b for b, _ in builds[(name, mesh)]])),
            "states": len(r.states), "wall_median_s": float(np.median(walls)),
            "wall_min_s": float(walls.min()), "wall_max_s": float(walls.max()),
            "tied_dz_max": max(abs(s.tied_difference[2]) for s in stable),
            "tied_lateral_max": max(_lateral(s.tied_difference) for s in stable),
            "released_dz_max": max(abs(s.difference[2]) for s in stable),
            "released_lateral_max": max(_lateral(s.difference) for s in stable),
            "agree": bool(r.success), "failed": sum(not s.success for s in r.states),
        })
    return out


def random_study(teams: int, seed: int, examples: bool = True) -> dict:
    """The issue-31 sample: N = 3-8, sheets 500-1000 mm across (longest side), hold heights
    0.8-1.5 sheet radii (largest vertex distance from the vertices' centroid); teams with
    no rest state (taut: infeasible) are redrawn. With ``examples``, the FK paper's
    Examples 1 and 2 are checked the same way after them."""
    rng = np.random.default_rng(seed)
    runs = [(str(k), *random_hanging_team(rng)) for k in range(teams)]
    if examples:
        for name, path in EXAMPLES.items():
            sc = load_sheet_scenario(path)
            assert sc.formation is not None
            runs.append((name, sc.team, sc.formation))
    states, walls = [], []
    for name, team, R in runs:
        n = team.n
        width = float(np.max(team.sheet.side_lengths()))
        t0 = time.perf_counter()
        r = replay_equilibria(team, R)
        walls.append((n, time.perf_counter() - t0, len(r.states)))
        lowest = min(float(st.predicted[2]) for st in r.states)
        for st in r.states:
            states.append({"team": name, "n": n, "kind": st.kind, "held": st.held,
                           "agrees": st.agrees, "resolved": st.resolved,
                           "sliding": st.sliding, "predicted_sliding": st.predicted_sliding,
                           "status": st.status, "message": st.message,
                           "reached": st.reached, "basin_mm": st.basin,
                           "tied": (st.tied_difference / width).tolist(),
                           "released": (st.difference / width).tolist(),
                           "released_dz_mm": float(st.difference[2]),
                           "below_lowest_mm": float(lowest - st.settled[2])})
    return {"states": states, "walls": walls}


def _report_random(study: dict) -> None:
    st = study["states"]
    runs = [s for s in st if s["status"] in ("ok", "not_strict")]
    stable = [s for s in runs if s["kind"] == "stable"]
    noneq = [s for s in st if s["kind"] == "not_equilibrium"]
    failed = [s for s in st if s["status"] not in ("ok", "not_strict")]
    marginal = [s for s in st if s["status"] == "not_strict"]
    print(f"\nteams: {len({s['team'] for s in st})}, states: {len(st)} "
          f"({sum(s['kind'] == 'stable' for s in st)} stable, {len(noneq)} not an "
          f"equilibrium, {sum(s['kind'] == 'saddle' for s in st)} saddle)")
    print(f"failed simulations: {len(failed)}" + "".join(f"\n  {s['team']}: {s['message']}"
                                                         for s in failed))
    print(f"held verdict agrees with taut: {sum(s['agrees'] for s in st)} of {len(st)}; "
          f"not resolved (taut's own pull <= the hold tolerance): "
          f"{sum(not s['resolved'] for s in st)} (held in physics: "
          f"{sum(s['held'] and not s['resolved'] for s in st)})")
    print(f"stable held: {sum(s['held'] for s in stable)} of {len(stable)}; resolved "
          f"non-equilibria held: {sum(s['held'] and s['resolved'] for s in noneq)} of "
          f"{sum(s['resolved'] for s in noneq)}")
    fin = [abs(s["sliding"] - s["predicted_sliding"]) for s in st
           if np.isfinite(s["predicted_sliding"])]
    print(f"|pull - taut's pull| / mg: median {np.median(fin):.3f}, max {max(fin):.3f} "
          f"({len(fin)} states)")
    print(f"stable states released within 5 mm in height: "
          f"{sum(abs(s['released_dz_mm']) <= 5 for s in stable)} of {len(stable)}; "
          f"marginal (left over a basin shallower than the ball's reach): {len(marginal)}"
          + "".join(f"\n  {s['team']}: {s['message']}" for s in marginal))
    print(f"released objects below the team's lowest rest state by more than 5 mm: "
          f"{sum(s['below_lowest_mm'] > 5 for s in runs)} of {len(runs)} (largest "
          f"{max(s['below_lowest_mm'] for s in runs):+.2f} mm)")
    print("differences at stable states, per mille of the sheet's width (x1000):")
    print("  tied |dz|       :", _pct([abs(s["tied"][2]) for s in stable]))
    print("  tied lateral    :", _pct([np.hypot(*s["tied"][:2]) for s in stable]))
    print("  released |dz|   :", _pct([abs(s["released"][2]) for s in stable]))
    w = np.array([(n, t, k) for n, t, k in study["walls"]])
    for lo, hi in ((3, 5), (6, 8), (5, 7)):
        sel = (w[:, 0] >= lo) & (w[:, 0] <= hi)
        if sel.any():
            print(f"wall per team, {lo}-{hi} robots: median {np.median(w[sel, 1]):.2f} s, "
                  f"max {w[sel, 1].max():.2f} s ({int(sel.sum())} teams, "
                  f"{w[sel, 2].mean():.1f} states on average)")


def _pct(x: list[float]) -> str:
    a = np.asarray(x) * 1000
    return (f"median {np.median(a):.2f}, 90% {np.percentile(a, 90):.2f}, "
            f"max {a.max():.2f}")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--teams", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--meshes", default="7,10,13", help="'' to skip the spacing table")
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--json", type=Path)
    a = ap.parse_args()
    table = (spacing_table([int(m) for m in a.meshes.split(",")], a.repeats)
             if a.meshes else [])
    print("| example | mesh | spacing | nodes | tendons | build s | states "
          "| check wall s (median [min, max]) | tied max dz / lateral "
          "| released max dz / lateral | agrees |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in table:
        print(f"| {r['example']} | {r['mesh']} | {r['spacing']:.0f} | {r['nodes']} | "
              f"{r['tendons']} | {r['build_median_s']:.2f} | {r['states']} | "
              f"{r['wall_median_s']:.2f} "
              f"[{r['wall_min_s']:.2f}, {r['wall_max_s']:.2f}] | {r['tied_dz_max']:.1f} / "
              f"{r['tied_lateral_max']:.1f} | {r['released_dz_max']:.1f} / "
              f"{r['released_lateral_max']:.1f} | {r['agree']} |")
    study = random_study(a.teams, a.seed)
    _report_random(study)
    if a.json:
        a.json.write_text(json.dumps({"spacing": table, "random": study}, indent=1))


if __name__ == "__main__":
    main()
