"""Reprs of results and models are one line or a few (shapes, success, status), like scipy's
results, never dozens of lines of arrays (issue 29.6); they share taut._repr.CompactRepr."""

from __future__ import annotations

import dataclasses
import importlib
import inspect

import numpy as np
import pytest

from taut._repr import CompactRepr, compact_repr

FAMILIES = ["taut.sheet", "taut.plan", "taut.cdpr", "taut.io", "taut.physics", "taut.sweep"]
#: Public dataclasses with array fields that keep a hand-written repr of their own (each
#: already one line).
OWN_REPR = {"Equilibrium", "Sheet"}
#: Modules whose classes are being written in this round by other hands: to be given the
#: mixin when they land, then removed from here.
PENDING = {"taut.cdpr.mission", "taut.plan.execution", "taut.plan.control",
           "taut.plan.checks.feedback"}
MAX_LINES = 8
MAX_CHARS = 700


def _public_array_dataclasses():
    for fam in FAMILIES:
        try:
            mod = importlib.import_module(fam)
        except ModuleNotFoundError:          # an extra that is not installed
            continue
        for name in getattr(mod, "__all__", ()):
            obj = getattr(mod, name, None)
            if not (inspect.isclass(obj) and dataclasses.is_dataclass(obj)):
                continue
            if any(obj.__module__.startswith(p) for p in PENDING):
                continue
            if any("ndarray" in str(f.type) for f in dataclasses.fields(obj)):
                yield f"{fam}.{name}", obj


CLASSES = sorted(set(_public_array_dataclasses()), key=lambda t: t[0])


@pytest.mark.parametrize("name, cls", CLASSES, ids=[n for n, _ in CLASSES])
def test_array_dataclasses_use_the_shared_compact_repr(name, cls):
    if cls.__name__ in OWN_REPR:
        assert "__repr__" in cls.__dict__
        return
    assert cls.__repr__ is CompactRepr.__repr__, f"{name}: declare repr=False, inherit CompactRepr"


def _check(obj):
    text = repr(obj)
    assert len(text.splitlines()) <= MAX_LINES and len(text) <= MAX_CHARS, text
    assert text.startswith(type(obj).__name__ + "(")
    if hasattr(obj, "status"):
        assert "status=" in text and "success=" in text
    return text


def test_compact_repr_shows_shapes_not_values():
    @dataclasses.dataclass(frozen=True, repr=False)
    class R(CompactRepr):
        tensions: np.ndarray
        status: str
        success: bool
        message: str

    r = R(np.arange(1000.0).reshape(100, 10), "ok", True, "x" * 500)
    text = compact_repr(r)
    assert text.startswith("R(success=True, status='ok',")   # the outcome first
    assert "tensions=<(100, 10)>" in text and "999" not in text
    assert len(text) < 200 and "..." in text                            # long message cut
    assert "pos=[1, 2.5, -3]" in compact_repr(_Pos(np.array([1.0, 2.5, -3.0])))


@dataclasses.dataclass(frozen=True, repr=False)
class _Pos(CompactRepr):
    pos: np.ndarray


def test_sheet_results_short():
    from taut.sheet import (Sheet, SheetTeam, forward_kinematics, forward_kinematics_batch,
                            inverse_kinematics, simulate)
    team = SheetTeam(Sheet.regular(4, 1000.0), hold_height=1000.0, mass=1.0)
    ik = inverse_kinematics(team, (0, 0, 300))
    assert "formation=<(4, 2)>" in _check(ik)
    path = ik.formation + np.linspace(0, 200, 11)[:, None, None] * [1.0, 0.0]
    assert "object=<(11, 3)>" in _check(simulate(team, path))
    _check(forward_kinematics_batch(team, path))
    e = forward_kinematics(team, ik.formation).lowest
    assert str(tuple(int(i) for i in e.taut)) in repr(e)    # 0-based, as the attribute
    assert "1-based" not in repr(e)


def test_cdpr_results_short():
    from taut.cdpr import distribute_tensions, twist_capacities
    from taut.io import load_cdpr_model
    robot = load_cdpr_model("fastkit")
    assert "fastkit" in _check(robot)
    one = _check(distribute_tensions(robot, [0, 0, 0.6]))
    assert "tensions=<(8,)>" in one
    batch = _check(distribute_tensions(robot, [[0, 0, 0.6]] * 50))
    assert "tensions=<(50, 8)>" in batch
    _check(twist_capacities(robot, [0.0, 0.0, 1.0]))
