"""Every number in every JSON document says its unit (issue 29.4, docs/conventions.md).

Each ``--json`` command (and the JSON files ``taut plan --out/--trajectories`` and ``taut
cdpr simulate --out`` write) is run on a small example and its document walked: a number
must sit under a key with a unit suffix (``duration_s``), under a path its document's
``"units"`` object names (``"equilibria.tensions": "N"``), or under a key of the one
documented list of unitless keys (:data:`taut.io._json_units.UNITLESS`). A ``units``
entry must name a key the document has, so a renamed field cannot leave a stale unit.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from taut.io._json_units import DOCUMENTS, SHEET, UNITLESS, has_unit_suffix, units_of
from cli_calls import run

EX = Path(__file__).resolve().parents[2] / "examples"
SHEET1 = str(EX / "sheet/example1.yaml")
SQUARE = str(EX / "sheet/trajectories/square4.yaml")
POSE = ["--pose", "0.3", "0", "1.0"]

FAST = {
    "fk": ["fk", SHEET1, "--json"],
    "fk exhaustive": ["fk", SHEET1, "--json", "--method", "exhaustive"],
    "ik": ["ik", SHEET1, "--object", "0", "0", "300", "--json"],
    "simulate": ["simulate", SQUARE, "--trajectory",
                 str(EX / "sheet/trajectories/square4_jump.csv"), "--json"],
    "cdpr tensions": ["cdpr", "tensions", "fastkit", *POSE, "--json"],
    "cdpr wrench-set": ["cdpr", "wrench-set", "fastkit", *POSE, "--json"],
    "cdpr workspace": ["cdpr", "workspace", "fastkit", "--grid", "5", "1", "3", "--json"],
    "cdpr twist-set": ["cdpr", "twist-set", "fastkit", *POSE, "--json"],
}
SLOW = {
    "plan": ["plan", str(EX / "plan/paper_corridor.yaml"), "--json", "--robustness", "0.01",
             "--trials", "4"],
    "cdpr simulate": ["cdpr", "simulate", "fastkit", "--stabilisers", "--waypoints",
                      "-0.2,0,1.0; 0.2,0,1.0", "--json"],
    "cdpr mission": ["cdpr", "mission", str(EX / "cdpr/warehouse.yaml"), "--json"],
    "physics": ["physics", SHEET1, "--json", "--mesh", "6"],
}


DEPLOY = ["cdpr", "deploy", "fastkit", "--workspace", "-0.5", "0.5", "-0.05", "0.05", "0.4",
          "0.9", "--stabilisers", "--maxiter", "1", "--json"]


def _placement(robot, box, **kwargs):
    """Stands in for the deployment search (seconds to minutes): the bases 6.8 m apart,
    verified on a 2 x 2 x 2 grid, so the serializer sees every field of a success."""
    import numpy as np

    from taut.cdpr import DeploymentResult, grid_points, lift_bound, place_bases

    poses = {"active": np.array([-3.4, 0.0, 0.0]), "passive": np.array([3.4, 0.0, np.pi])}
    pts, _ = grid_points(box, (2, 2, 2))
    return DeploymentResult(True, "ok", "verified", poses, place_bases(robot, poses), 1.5, 0.9,
                            pts, np.full(len(pts), 1.5), np.ones(len(pts), bool),
                            np.asarray(box), 7, lift_bound(robot, box))


def _leaves(obj, path=()):
    """``(path, value)`` of every leaf; list positions are not part of a path."""
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield from _leaves(v, path + (k,))
    elif isinstance(obj, list):
        for v in obj:
            yield from _leaves(v, path)
    else:
        yield path, obj


def _units_objects(doc, path=()):
    """``(path, units object)`` of every ``"units"`` object in ``doc``."""
    if isinstance(doc, dict):
        if isinstance(doc.get("units"), dict):
            yield path, doc["units"]
        for k, v in doc.items():
            if k != "units":
                yield from _units_objects(v, path + (k,))
    elif isinstance(doc, list):
        for v in doc:
            yield from _units_objects(v, path)


def unitless_numbers(doc) -> list[str]:
    """Dotted paths of the numbers in ``doc`` whose unit is said nowhere."""
    said = [(at, tuple(key.split("."))) for at, units in _units_objects(doc) for key in units]
    bad = set()
    for path, value in _leaves(doc):
        if not isinstance(value, (int, float)) or isinstance(value, bool) or "units" in path:
            continue
        if path[-1] in UNITLESS or any(has_unit_suffix(k) for k in path):
            continue
        if any(path[:len(at) + len(key)] == at + key for at, key in said):
            continue
        bad.add(".".join(path))
    return sorted(bad)


def stale_units(doc) -> list[str]:
    """``units`` entries whose first key is not in the dict that holds them."""
    out = []
    for at, units in _units_objects(doc):
        holder = doc
        for k in at:
            holder = holder[k] if isinstance(holder, dict) else holder[0][k]
        holder = holder[0] if isinstance(holder, list) else holder
        out += [".".join(at + (key,)) for key in units if key.split(".")[0] not in holder]
    return out


def _document(capsys, args):
    code, out, err = run(capsys, *args)
    assert code in (0, 1), err
    return json.loads(out)


def _check(doc, name):
    assert not unitless_numbers(doc), f"{name}: numbers without a unit: {unitless_numbers(doc)}"
    assert not stale_units(doc), f"{name}: units of missing keys: {stale_units(doc)}"


@pytest.mark.parametrize("name", sorted(FAST))
def test_every_number_says_its_unit(capsys, name):
    _check(_document(capsys, FAST[name]), name)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(SLOW))
def test_every_number_says_its_unit_slow(capsys, name):
    if name == "physics":
        pytest.importorskip("mujoco")
    _check(_document(capsys, SLOW[name]), name)


@pytest.mark.slow
def test_written_json_files_say_their_units(capsys, tmp_path):
    plan, traj, run_ = tmp_path / "plan.json", tmp_path / "traj.json", tmp_path / "run.json"
    code, _, err = run(capsys, "plan", EX / "plan/paper_corridor.yaml", "--out", plan,
                       "--trajectories", traj, "--max-speed", "0.2", "--max-accel",
                       "0.5", "--max-yaw-rate", "1")
    assert code == 0, err
    code, _, err = run(capsys, "cdpr", "simulate", "fastkit", "--stabilisers", "--waypoints",
                       "-0.2,0,1.0; 0.2,0,1.0", "--dwell", "0.1", "--out", run_)
    assert code == 0, err
    for path in (plan, traj, run_):
        _check(json.loads(path.read_text()), path.name)


def test_sheet_documents_name_the_scenario_unit(capsys):
    """example1.yaml says ``units: mm``: the sheet lengths are said to be mm, tensions N."""
    doc = _document(capsys, FAST["fk"])
    assert doc["units"]["equilibria.object"] == "mm"
    assert doc["units"]["equilibria.tensions"] == "N"
    assert units_of("ik")["curvature"] == "1/sheet units"


def test_deployment_says_its_units(capsys, monkeypatch):
    monkeypatch.setattr("taut.cdpr.plan_deployment", _placement)
    _check(_document(capsys, DEPLOY), "cdpr deploy")


def test_the_check_can_fail():
    assert unitless_numbers({"speed": 1.0}) == ["speed"]
    assert unitless_numbers({"speed_mps": 1.0, "n": [{"taut": [1, 2]}]}) == []
    assert unitless_numbers({"a": {"b": [2.0]}, "units": {"a.b": "m"}}) == []
    assert unitless_numbers({"a": {"b": [2.0], "c": 3}, "units": {"a.b": "m"}}) == ["a.c"]
    assert stale_units({"a": 1, "units": {"gone": "m"}}) == ["gone"]


def test_unit_tables_are_well_formed():
    """Every unit is a non-empty string; the sheet placeholder only in sheet documents."""
    sheet_kinds = {"fk", "ik", "simulation", "physics"}
    for kind, table in DOCUMENTS.items():
        assert all(isinstance(u, str) and u for u in table.values()), kind
        assert (kind in sheet_kinds) == any(SHEET in u for u in table.values()), kind
    assert not set(UNITLESS) & {k.split(".")[-1] for t in DOCUMENTS.values() for k in t}


def test_unitless_keys_are_documented():
    """docs/conventions.md lists every key of :data:`UNITLESS` (wildcards ``coverage*``,
    ``*_probability``) and no other."""
    import re

    text = (Path(__file__).resolve().parents[2] / "docs/conventions.md").read_text()
    block = text[text.index("3. the keys that have no unit"):text.index("tests/io/test_json_units")]
    listed = set(re.findall(r"`([\w*]+)`", block))
    patterns = [re.compile("^" + w.replace("*", r"\w*") + "$") for w in listed]
    assert all(any(p.match(k) for p in patterns) for k in UNITLESS), \
        sorted(k for k in UNITLESS if not any(p.match(k) for p in patterns))
    assert all(any(p.match(k) for k in UNITLESS) for p in patterns), "a documented key is gone"


def test_monte_carlo_document_says_its_units():
    """``monte_carlo_to_dict`` has no command: checked on a stand-in with its fields."""
    from types import SimpleNamespace

    import numpy as np

    from taut.io.serialize import monte_carlo_to_dict

    fields = {k: np.zeros(2) for k in DOCUMENTS["monte_carlo"]}
    r = SimpleNamespace(controller="velocity", message="", success=np.ones(2, bool),
                        status=np.array(["ok", "ok"]), **fields)
    _check(json.loads(json.dumps(monte_carlo_to_dict(r))), "monte carlo")
