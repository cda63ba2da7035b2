"""Issue 28, done-when checks on the shipped plan examples and the 50-scenario suite (slow):
differential-drive trajectories at 0.2 m/s, 0.5 m/s^2, 1 rad/s re-verify with 0 violations
at an independent 10x resampling, and the crossing planner is never slower than its SE(2)
bypass baseline on a scenario both solve."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from taut.io import load_plan_scenario
from taut.plan import generate_suite, plan

from .test_trajectories import LIMITS, reverify_10x, violations

pytestmark = pytest.mark.slow

EXAMPLES = Path(__file__).parents[2] / "examples" / "plan"


@pytest.fixture(scope="module")
def plans():
    """(name, scenario, crossing plan, bypass plan) of every example and suite scenario."""
    cases = [(p.stem, load_plan_scenario(p)) for p in sorted(EXAMPLES.glob("*.yaml"))]
    cases += [(f"suite {i}", sc) for i, sc in enumerate(generate_suite(50, 2024))]
    return [(name, sc, plan(sc), plan(sc, baseline="se2")) for name, sc in cases]


def test_differential_trajectories_reverify_everywhere(plans):
    from taut.plan import robot_trajectories
    bad, ratios = [], []
    for name, sc, result, _ in plans:
        if not result.success:
            continue
        tr = robot_trajectories(result, drive="differential", **LIMITS)
        problems = ([] if tr.success else [tr.message]) + violations(tr)
        check = reverify_10x(sc, result, tr)
        if not check.success:
            problems.append(check.message)
        if problems:
            bad.append((name, problems))
        ratios.append(tr.duration / result.duration)
    assert len(ratios) >= 50 and bad == []
    print(f"differential / rigid duration: median {np.median(ratios):.2f}, range "
          f"{min(ratios):.2f}-{max(ratios):.2f}")


def test_crossing_is_never_slower_than_the_bypass_baseline(plans):
    both = [(name, c.duration, b.duration) for name, _, c, b in plans
            if c.success and b.success]
    assert len(both) >= 45
    slower = [x for x in both if x[1] > x[2] * (1 + 1e-9)]
    assert slower == []
