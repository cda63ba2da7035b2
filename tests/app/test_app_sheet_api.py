"""Sheet explorer endpoints (no web server needed): every number the page shows comes
from the library, errors are the CLI's lines, the YAML download reads back."""

from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given, settings, strategies as st

from taut.app.catalog import Catalog, regular_team
from taut.app.sheet_api import SheetAPI
from taut.cli import main
from taut.errors import InfeasibleFormationError, TautError
from taut.io import load_sheet_scenario
from taut.io.trajectory import load_trajectory
from taut.sheet import forward_kinematics
from taut.sheet import simulate
from taut.sheet import SheetTeam

ROOT = Path(__file__).parents[2]
EX2 = ROOT / "examples" / "sheet" / "example2_r2_r4_353mm.yaml"


@pytest.fixture(scope="module")
def api():
    return SheetAPI(Catalog(ROOT / "examples"))


@pytest.fixture(scope="module")
def ex2(api):
    return api.load({"example": EX2.name})["scenario"]


def fk_body(sc, formation, mass=1.0):
    return {"sheet": sc["sheet"], "hold_height": sc["hold_height"], "mass": mass,
            "formation": np.asarray(formation).tolist()}


def assert_same_equilibria(got, res):
    assert got["feasible"] is True
    assert [tuple(e["taut"]) for e in got["equilibria"]] == [e.taut for e in res.equilibria]
    for g, e in zip(got["equilibria"], res.equilibria):
        assert g["kind"] == e.kind
        np.testing.assert_allclose(g["object"], e.object, rtol=0, atol=1e-9)
        np.testing.assert_allclose(g["contact"], e.contact, rtol=0, atol=1e-9)
        if e.tensions is None:
            assert g["tensions"] is None
        else:
            np.testing.assert_allclose(g["tensions"], e.tensions, rtol=1e-12)
    low = res.lowest
    assert got["lowest"] == (None if low is None else res.equilibria.index(low))


def test_example2_loads_as_the_cli_reads_it(ex2):
    sc = load_sheet_scenario(EX2)
    np.testing.assert_array_equal(ex2["formation"], sc.formation)
    np.testing.assert_array_equal(ex2["sheet"], sc.team.sheet.vertices)
    assert ex2["hold_height"] == sc.team.hold_height and ex2["mass"] == sc.team.mass


def test_fk_of_example2_is_table_iii(api, ex2):
    got = api.fk(fk_body(ex2, ex2["formation"]))
    sc = load_sheet_scenario(EX2)
    assert_same_equilibria(got, forward_kinematics(sc.team, sc.formation))      # mass 1 kg
    stable = [e for e in got["equilibria"] if e["kind"] == "stable"]
    assert [e["taut"] for e in stable] == [[3, 4, 7]]         # Table III: {4, 5, 8}
    assert abs(stable[0]["object"][2] - 261.81) < 0.01


@settings(max_examples=25, deadline=None)
@given(dx=st.floats(-300, 300), dy=st.floats(-300, 300))
def test_dragging_robot_2_gives_the_library_answer(api, ex2, dx, dy):
    """Any drag of robot 2: the same equilibria as forward_kinematics, or the same
    infeasible pair."""
    sc = load_sheet_scenario(EX2)
    f = sc.formation.copy()
    f[1] += (dx, dy)
    got = api.fk(fk_body(ex2, f))
    try:
        res = forward_kinematics(sc.team, f)
    except InfeasibleFormationError as exc:
        assert got["feasible"] is False and tuple(got["pair"]) == exc.pair
        assert got["message"] == str(exc)
        return
    assert_same_equilibria(got, res)


@pytest.mark.parametrize("text, name", [
    ("hold_height: [1\n", "bad.yaml"),
    ("hold_height: 1000\nsheet: [[0, 0], [1, 0], [0, 1]]\nformation: [[0, 0], [5, 0], [0, 1]]\n",
     "torn.yaml"),
    ("hold_height: -3\nsheet: [[0, 0], [1, 0], [0, 1]]\n", "neg.yaml"),
    ("hold_height: 1\nsheet: [[0, 0], [1, 0], [0, 1]]\ncolour: red\n", "extra.yaml"),
    ('{"hold_height": 1,', "broken.json"),
])
def test_bad_upload_is_the_cli_line(api, tmp_path, capsys, text, name):
    path = tmp_path / name
    path.write_text(text)
    code = main(["fk", str(path)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and err.startswith("taut: error: ")
    with pytest.raises(TautError) as info:
        api.load({"text": text, "filename": name})
    assert str(info.value) == err.removeprefix("taut: error: ").replace(str(path), name)
    assert "\n" not in str(info.value)


def test_yaml_download_reads_back_and_runs(api, ex2, tmp_path, capsys):
    moved = np.asarray(ex2["formation"], dtype=float)
    moved[1] += (20.0, -15.0)
    scen = dict(ex2, formation=moved.tolist(), mass=2.5)
    out = api.yaml({"scenario": scen})
    path = tmp_path / out["filename"]
    path.write_text(out["yaml"])
    back = load_sheet_scenario(path)
    np.testing.assert_array_equal(back.formation, moved)
    assert back.team.mass == 2.5 and back.units == "mm"
    assert main(["fk", str(path), "--json"]) == 0
    assert yaml.safe_load(out["yaml"])["formation"] == moved.tolist()


def test_ik_formation_rests_the_object_at_the_target(api, ex2):
    target = [30.0, -20.0, 450.0]
    ik = api.ik(dict(fk_body(ex2, ex2["formation"]), target=target,
                     reference=ex2["formation"]))["ik"]
    got = api.fk(fk_body(ex2, ik["formation"]))
    stable = [e for e in got["equilibria"] if e["kind"] == "stable"]
    assert any(np.allclose(e["object"], target, atol=1e-6) for e in stable)


def test_simulate_marks_the_jump_of_the_square_example(api):
    base = ROOT / "examples" / "sheet" / "trajectories"
    sc = api.load({"text": (base / "square4.yaml").read_text(), "filename": "square4.yaml"})
    sc = sc["scenario"]
    traj = load_trajectory(base / "square4_jump.csv")
    got = api.simulate(dict(fk_body(sc, sc["formation"]), formations=traj.formations.tolist()))
    square = load_sheet_scenario(base / "square4.yaml").team.sheet
    want = simulate(SheetTeam(square, 1.5, mass=1.0), traj.formations)
    kinds = [e["kind"] for e in got["simulation"]["events"]]
    assert kinds == [e.kind for e in want.events] and "jump" in kinds
    jump = next(e for e in got["simulation"]["events"] if e["kind"] == "jump")
    assert jump["drop"] > 0


@pytest.mark.parametrize("n", [3, 4, 8, 20])
def test_generated_teams_start_in_a_stable_state(api, n):
    sc = api.load({"regular": n})["scenario"]
    assert len(sc["formation"]) == n
    got = api.fk(fk_body(sc, sc["formation"]))
    assert got["stable_count"] >= 1
    assert regular_team(n)["formation"] == sc["formation"]


def test_scenario_without_formation_gets_a_stable_one(api):
    text = (ROOT / "examples" / "sheet" / "trajectories" / "square4.yaml").read_text()
    sc = api.load({"text": text, "filename": "square4.yaml"})["scenario"]
    got = api.fk(fk_body(sc, sc["formation"]))
    assert got["stable_count"] >= 1


SHEET_EXAMPLES = sorted((ROOT / "examples" / "sheet").glob("*.yaml"))


@pytest.mark.parametrize("path", SHEET_EXAMPLES, ids=[p.stem for p in SHEET_EXAMPLES])
def test_cli_app_and_library_give_the_same_states(api, capsys, path):
    """On every shipped sheet example, `taut fk --json`, the app's FK endpoint and
    `forward_kinematics` report the same states (taut sets, kinds, positions, tensions)."""
    import json

    sc = load_sheet_scenario(path)
    res = forward_kinematics(sc.team, sc.formation)
    assert main(["fk", str(path), "--json"]) == (0 if res.success else 1)
    cli = json.loads(capsys.readouterr().out)
    loaded = api.load({"example": path.name})["scenario"]
    app = api.fk(fk_body(loaded, sc.formation, mass=sc.team.mass))
    assert_same_equilibria(app, res)
    assert [tuple(e["taut"]) for e in cli["equilibria"]] == [e.taut for e in res.equilibria]
    for c, e in zip(cli["equilibria"], res.equilibria):
        assert c["kind"] == e.kind
        np.testing.assert_allclose(c["object"], e.object, rtol=1e-12, atol=1e-9)
