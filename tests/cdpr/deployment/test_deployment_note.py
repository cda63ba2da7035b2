"""Regressions of the "bugs to fix on the way" of issue 10 that had no test of their own:
the deployment note must state exactly what the lift certificate proves, under which
assumptions (the cable_state index and World.obstacle bugs are covered by
tests/cdpr/test_cdpr_conventions.py::test_cable_state_reports_the_offending_pose and
tests/plan/se2/test_se2.py, which raises UnknownObstacleError)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from taut.cdpr import lift_bound

ROOT = Path(__file__).resolve().parents[3]
FULL = [[-2.5, -0.05, 0.2], [2.5, 0.05, 2.2]]     # the preset's assumed 5 m x 2 m box


def _raised(robot, dz):
    bases = tuple(replace(b, exit_points={k: np.asarray(v) + (0.0, 0.0, dz)
                                          for k, v in b.exit_points.items()})
                  for b in robot.bases)
    return replace(robot, bases=bases, bounds=None)


def test_refutation_depends_on_the_assumed_exit_heights(fastkit):
    """What the note claims, number for number: refuted with the preset's exits
    (2.40 / 2.25 m), not refuted with every exit 0.5 m higher (bound 185.8 N vs 117.7 N)."""
    assert sorted(set(np.round(fastkit.exits_world[:, 2], 2))) == [2.25, 2.4]
    preset = lift_bound(fastkit, FULL)
    assert preset.refutes and round(preset.bound, 1) == 64.2
    high = lift_bound(_raised(fastkit, 0.5), FULL)
    assert not high.refutes
    assert round(high.bound, 1) == 185.8 and round(high.required, 1) == 117.7


def test_deployment_note_states_assumptions_not_the_paper():
    text = (ROOT / "examples/cdpr/fastkit_motion.md").read_text()
    assert "the paper's desired workspace" not in text
    assert "with the paper's numbers" not in text
    for claim in ("5 m long by 2 m high", "2.40 m and 2.25 m above the ground",
                  "What is *not* proved", "0.5 m higher"):
        assert claim in text, claim
