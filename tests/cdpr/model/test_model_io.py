"""Model files, presets and bad input: typed errors naming the field; CLI one-liners."""

import copy
import json

import numpy as np
import pytest
import yaml
from hypothesis import given, settings, strategies as st

from taut.cdpr import Base, check_footprint, distribute_tensions
from taut.cli import main
from taut.errors import (InfeasiblePoseError, InvalidInputError, InvalidModelError,
                         ScenarioError)
from taut.io.cdpr_model import (cdpr_model_from_mapping, load_cdpr_model, preset_path)


@pytest.fixture(scope="module")
def fastkit_map():
    return yaml.safe_load(preset_path("fastkit").read_text())


def test_fastkit_preset_matches_paper(fastkit):
    assert fastkit.m == 8 and fastkit.dof == 6
    assert [b.mobile for b in fastkit.bases] == [True, True]
    assert fastkit.platform.mass == 5.0 and fastkit.payload.mass == 7.0
    assert np.all(fastkit.t_max == 45.0)
    assert fastkit.exits_world[:, 2].max() == pytest.approx(2.4)
    box = np.ptp(fastkit.platform.attach_local, axis=0)
    np.testing.assert_allclose(box, [0.6, 0.36, 0.2])
    dw = fastkit.desired_workspace
    np.testing.assert_allclose(dw[1] - dw[0], [5.0, 0.0, 2.0])
    assert fastkit.n_edges == 8 and np.all(fastkit.edge_weight_moment < 0)


def test_ipanema_preset(ipanema):
    assert ipanema.m == 8 and not ipanema.has_tipping and ipanema.dof == 6


def test_load_by_path_equals_preset(tmp_path, fastkit_map, fastkit):
    p = tmp_path / "m.yaml"
    p.write_text(yaml.safe_dump(fastkit_map))
    robot = load_cdpr_model(p)
    np.testing.assert_array_equal(robot.exits_world, fastkit.exits_world)
    j = tmp_path / "m.json"
    j.write_text(json.dumps(fastkit_map))
    np.testing.assert_array_equal(load_cdpr_model(j).t_max, fastkit.t_max)


def test_unknown_preset():
    with pytest.raises(ScenarioError) as e:
        load_cdpr_model("cogiro")
    assert e.value.field == "model" and "unknown preset" in e.value.problem


def _broken(base_map, edit):
    d = copy.deepcopy(base_map)
    edit(d)
    return d


BAD = {
    "missing exit point": (lambda d: d["cables"][2].update(exit="active.A9"),
                           InvalidModelError, "cables[2].exit"),
    "missing base": (lambda d: d["cables"][0].update(exit="nobody.A1"),
                     InvalidModelError, "cables[0].exit"),
    "malformed exit": (lambda d: d["cables"][0].update(exit="A1"),
                       InvalidModelError, "cables[0].exit"),
    "missing attachment": (lambda d: d["cables"][5].update(attachment="B42"),
                           InvalidModelError, "cables[5].attachment"),
    "min above max": (lambda d: d["cables"][1].update(t_min=50.0),
                      InvalidModelError, "cables[1].t_min"),
    "negative min": (lambda d: d["cables"][1].update(t_min=-1.0),
                     InvalidModelError, "cables[1].t_min"),
    "non-convex footprint": (lambda d: d["bases"][1].update(
        footprint=[[-0.45, -0.6], [0.45, -0.6], [0.0, 0.0], [0.45, 0.6], [-0.45, 0.6]]),
        InvalidModelError, "bases[1].footprint"),
    "collinear footprint": (lambda d: d["bases"][0].update(
        footprint=[[0, 0], [1, 0], [2, 0]]), InvalidModelError, "bases[0].footprint"),
    "repeated footprint point": (lambda d: d["bases"][0].update(
        footprint=[[0, 0], [1, 0], [1, 0], [0, 1]]), InvalidModelError, "bases[0].footprint"),
    "two-point footprint": (lambda d: d["bases"][0].update(footprint=[[0, 0], [1, 0]]),
                            InvalidModelError, "bases[0].footprint"),
    "com outside footprint": (lambda d: d["bases"][0].update(com=[2.0, 0.0, 0.5]),
                              InvalidModelError, "bases[0].com"),
    "NaN": (lambda d: d["platform"].update(mass=float("nan")), ScenarioError,
            "platform.mass"),
    "inf in point": (lambda d: d["bases"][0]["exit_points"].update(A1=[0, float("inf"), 1]),
                     ScenarioError, "bases[0].exit_points.A1[1]"),
    "unknown key": (lambda d: d.update(colour="red"), ScenarioError, "colour"),
    "missing key": (lambda d: d.pop("platform"), ScenarioError, "platform"),
    "negative payload": (lambda d: d["payload"].update(mass=-1.0), InvalidModelError,
                         "payload.mass"),
    "duplicate exit use": (lambda d: d["cables"][1].update(exit="active.A1"),
                           InvalidModelError, "cables[1].exit"),
    "more cables than accepted": (lambda d: _cables(d, 101), InvalidModelError, "cables"),
}


def _cables(d, m):
    """Give the model ``m`` cables from as many new exit points of its first base."""
    base = d["bases"][0]
    base["exit_points"].update({f"X{i}": [0.01 * i, 0.0, 2.0] for i in range(m)})
    d["cables"] = [dict(d["cables"][0], name=f"X{i}", exit=f"{base['name']}.X{i}")
                   for i in range(m)]


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_models_raise_typed_errors(fastkit_map, case):
    edit, exc, field = BAD[case]
    with pytest.raises(exc) as e:
        cdpr_model_from_mapping(_broken(fastkit_map, edit))
    assert e.value.field == field, (e.value.field, e.value.problem)
    assert isinstance(e.value, InvalidInputError)


def test_cable_count_limit(fastkit_map):
    """At most MAX_CABLES cables: that many load, one more is refused naming both counts."""
    from taut._validate import MAX_CABLES
    assert cdpr_model_from_mapping(_broken(fastkit_map, lambda d: _cables(d, MAX_CABLES))
                                   ).m == MAX_CABLES
    with pytest.raises(InvalidModelError) as e:
        cdpr_model_from_mapping(_broken(fastkit_map, lambda d: _cables(d, MAX_CABLES + 1)))
    assert e.value.problem == f"{MAX_CABLES + 1} cables exceed the accepted range " \
                              f"{MAX_CABLES} cables"


@pytest.mark.parametrize("case", ["missing exit point", "min above max", "non-convex footprint",
                                  "NaN", "unknown key", "more cables than accepted"])
def test_cli_reports_bad_model_in_one_line(tmp_path, capsys, fastkit_map, case):
    edit, _, field = BAD[case]
    p = tmp_path / "bad.yaml"
    p.write_text(yaml.safe_dump(_broken(fastkit_map, edit)))
    code = main(["cdpr", "tensions", str(p), "--pose", "0", "0", "1"])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and err.startswith(f"taut: error: {field}: ")
    assert "Traceback" not in err


@pytest.mark.parametrize("argv,field", [
    (["cdpr", "tensions", "nosuch", "--pose", "0", "0", "1"], "model"),
    (["cdpr", "tensions", "fastkit", "--pose", "9", "0", "1"], "pose"),
    (["cdpr", "tensions", "fastkit", "--pose", "0", "0", "-0.5"], "pose"),
    (["cdpr", "tensions", "fastkit", "--pose", "nan", "0", "1"], "pose"),
    (["cdpr", "wrench-set", "fastkit", "--pose", "0", "0", "inf"], "pose"),
    (["cdpr", "tensions", "fastkit", "--pose", "0", "0", "1", "--method", "magic"], "--method"),
    (["cdpr", "workspace", "fastkit", "--grid", "0", "1", "3"], "grid"),
    (["cdpr", "workspace", "fastkit", "--box", "-9", "0", "0", "9", "0", "2"], "pose"),
    (["cdpr", "tensions", "missing.yaml", "--pose", "0", "0", "1"], "missing.yaml"),
])
def test_cli_bad_input_one_line(capsys, argv, field):
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.count("\n") == 1 and err.startswith(f"taut: error: {field}"), err


def test_pose_errors_are_typed(fastkit):
    with pytest.raises(InfeasiblePoseError):
        distribute_tensions(fastkit, [[0, 0, 1], [5, 0, 1]])
    with pytest.raises(InvalidInputError):
        distribute_tensions(fastkit, [0, 0, np.nan])
    with pytest.raises(InvalidInputError):
        distribute_tensions(fastkit, [0, 0, 1, 0])


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(st.floats(-5, 5), st.floats(-5, 5)), min_size=3, max_size=9),
       st.booleans())
def test_footprint_checks_on_random_polygons(pts, flip):
    """Accepted footprints are convex and counter-clockwise; the hull of random points in
    either orientation is accepted and gives the same polygon up to rotation."""
    from scipy.spatial import ConvexHull
    from scipy.spatial import QhullError
    arr = np.array(pts)
    try:
        fp = check_footprint(arr, "f")
    except InvalidModelError:
        fp = None
    if fp is not None:
        e = np.roll(fp, -1, axis=0) - fp
        cr = e[:, 0] * np.roll(e, -1, axis=0)[:, 1] - e[:, 1] * np.roll(e, -1, axis=0)[:, 0]
        assert np.all(cr > 0)
    try:
        hull = ConvexHull(arr)
    except QhullError:
        return
    poly = arr[hull.vertices]                          # counter-clockwise
    edges = np.linalg.norm(np.roll(poly, -1, axis=0) - poly, axis=1)
    span = np.ptp(poly, axis=0).max()
    e = np.roll(poly, -1, axis=0) - poly
    turns = e[:, 0] * np.roll(e, -1, axis=0)[:, 1] - e[:, 1] * np.roll(e, -1, axis=0)[:, 0]
    if hull.volume < 1e-3 or edges.min() < 1e-6 * span or turns.min() < 1e-9 * span ** 2:
        return                      # near-degenerate (tiny area, edge or turn): may be refused
    poly = poly[::-1] if flip else poly
    got = check_footprint(poly, "f")
    assert {tuple(p) for p in got} == {tuple(p) for p in poly}


def test_clockwise_footprint_gives_same_tipping(fastkit):
    fp = fastkit.bases[0].footprint
    b_ccw = Base("b", {"E": (0, 0, 1)}, mobile=True, mass=10, footprint=fp)
    b_cw = Base("b", {"E": (0, 0, 1)}, mobile=True, mass=10, footprint=fp[::-1])
    np.testing.assert_array_equal(b_ccw.support_polygon, b_cw.support_polygon)
