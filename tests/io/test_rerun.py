"""Rerun recordings: the .rrd is read back with rerun's own chunk reader and its numbers
compared with the result's (3D positions are stored as float32 by Rerun)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from taut.cli import main
from taut.io import load_sheet_scenario, write_rerun
from taut.io.trajectory import load_trajectory
from taut.sheet import simulate

SHEET = Path(__file__).resolve().parents[2] / "examples" / "sheet"


@pytest.fixture(scope="module", autouse=True)
def rc():
    """rerun's chunk reader; every test here skips without rerun. Imported when the tests
    run, not at collection (~0.5 s of CPU in each pytest-xdist worker)."""
    return pytest.importorskip("rerun.chunk")


def columns(path: Path) -> dict[str, dict[str, list]]:
    """entity path -> column name -> values (rows of every chunk, in time order)."""
    import rerun.chunk as rc
    out: dict[str, dict[str, list]] = {}
    for chunk in rc.RrdReader(path).stream():
        batch = chunk.to_record_batch()
        cols = out.setdefault(chunk.entity_path, {})
        for name in batch.schema.names:
            cols.setdefault(name, []).extend(batch.column(name).to_pylist())
    return out


@pytest.fixture(scope="module")
def simulation():
    sc = load_sheet_scenario(SHEET / "trajectories" / "square4.yaml")
    traj = load_trajectory(SHEET / "trajectories" / "square4_jump.csv")
    return sc, traj, simulate(sc.team, traj.formations)


def test_simulation_recording_loads_with_a_blueprint(tmp_path, simulation, rc):
    sc, traj, sim = simulation
    out = write_rerun(sim, tmp_path / "sim.rrd", length_unit=sc.units, times=traj.time)
    reader = rc.RrdReader(out)
    assert len(reader.recordings()) == 1 and len(reader.blueprints()) == 1
    cols = columns(out)
    scale = {"m": 1.0, "mm": 1e-3}[sc.units]
    z = cols["/plots/object_height/z"]
    t = np.array([v.total_seconds() for v in z["time"]])          # durations since 0 s
    order = np.argsort(t)
    assert np.allclose(t[order], traj.time, atol=1e-6)
    heights = np.array([v[0] for v in z["Scalars:scalars"]])[order]
    assert np.allclose(heights, sim.object[:, 2] * scale, atol=1e-12)
    tension = cols["/plots/cable_tensions/cable_1"]["Scalars:scalars"]
    assert len(tension) == len(traj.time)
    robots = cols["/world/robots"]
    assert robots["Points3D:labels"][0] == [f"robot {i + 1}" for i in range(sc.team.n)]
    first = np.array(robots["Points3D:positions"][0])
    assert np.allclose(first[:, :2], traj.formations[0] * scale, rtol=1e-6, atol=1e-6)
    assert np.allclose(first[:, 2], 0.0)


def test_plan_recording_has_the_margins(tmp_path):
    from test_mcap import SMALL_PLAN
    from taut.io import plan_scenario_from_mapping
    from taut.plan import plan, plan_profile
    r = plan(plan_scenario_from_mapping(SMALL_PLAN))
    cols = columns(write_rerun(r, tmp_path / "plan.rrd"))
    slack = np.array([v[0] for v in cols["/plots/margins/sheet_slack"]["Scalars:scalars"]])
    t = np.array([v.total_seconds() for v in cols["/plots/margins/sheet_slack"]["time"]])
    profile = plan_profile(r)
    assert np.allclose(slack[np.argsort(t)], profile.sheet_slack_m, atol=1e-12)
    assert slack.min() >= r.sheet_margin - 1e-12
    walls = cols["/world/static/walls"]["LineStrips3D:strips"][0]
    assert len(walls) == len(SMALL_PLAN["free_space"])           # one segment per wall


def test_cli_rerun_on_simulate(tmp_path, capsys):
    out = tmp_path / "s.rrd"
    assert main(["simulate", str(SHEET / "trajectories" / "square4.yaml"), "--trajectory",
                 str(SHEET / "trajectories" / "square4_jump.csv"), "--rerun", str(out)]) == 0
    assert f"Rerun recording written to {out}" in capsys.readouterr().out
    assert "/world/object" in columns(out)
