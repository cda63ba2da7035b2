"""A control simulation's length is bounded (issue 24, "no input makes a command use more
than ~1 GB"): ``taut cdpr simulate --dwell 86400`` (a day's rest at each waypoint, 1 kHz)
allocated its reference before the simulation refused it as too many control steps, and
10 million accepted steps needed ~40 GB. A pick-and-place reference is counted before it
is built (the closed-form count is the length of the references built), and a
simulation longer than :data:`taut._validate.MAX_CONTROL_STEPS` steps is refused before
its arrays are allocated."""

import numpy as np
import pytest

from taut._validate import MAX_CONTROL_STEPS
from taut.cdpr import pick_and_place
from taut.cdpr.control.references import _samples, _segment_time, waypoint_segments
from taut.errors import InvalidInputError

WAYPOINTS = [[-0.5, 0, 1.0], [0.5, 0, 1.0], [0.2, 0.1, 1.2]]


@pytest.mark.parametrize("profile", ["quintic", "trapezoidal"])
@pytest.mark.parametrize("speed, dwell, rate", [(1.0, 0.3, 1000.0), (0.07, 0.0, 250.0),
                                                (2.5, 1.234, 777.0)])
def test_the_predicted_sample_count_is_the_references_length(fastkit, profile, speed,
                                                             dwell, rate):
    ref = pick_and_place(fastkit, WAYPOINTS, speed, profile=profile, dwell=dwell, rate=rate)
    moving = sum(_samples(_segment_time(d, speed, 3.0, profile), rate) - 1
                 for d, _ in waypoint_segments(np.array(WAYPOINTS, float)))
    assert len(ref.times) == moving + int(round(dwell * rate)) * len(WAYPOINTS) + 1


@pytest.mark.parametrize("kw, field", [(dict(dwell=86_400.0), "dwell"),
                                       (dict(speed=1e-9), "speed"),
                                       (dict(dwell=20.0, rate=2000.0), "dwell")])
def test_a_reference_past_the_batch_limit_is_refused_before_allocating(fastkit, kw, field):
    with pytest.raises(InvalidInputError) as err:
        pick_and_place(fastkit, WAYPOINTS, **kw)
    assert err.value.field == field
    assert f"more than {MAX_CONTROL_STEPS}" in err.value.problem


def test_the_command_refuses_a_days_dwell_in_one_line(capsys):
    from taut.cli import main
    code = main(["cdpr", "simulate", "fastkit", "--waypoints", "-0.5,0,1.0; 0.5,0,1.0",
                 "--dwell", "86400"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "dwell:" in err, err


@pytest.mark.parametrize("kw, field", [(dict(duration=100.5), "duration"),
                                       (dict(duration=50.0, control_rate=2500.0), "duration"),
                                       (dict(duration=60.0, settle=50.0), "settle")])
def test_a_simulation_past_the_step_limit_is_refused(fastkit, kw, field):
    from taut.cdpr import TorqueController, simulate
    ref = pick_and_place(fastkit, WAYPOINTS[:2], dwell=0.1)
    with pytest.raises(InvalidInputError) as err:
        simulate(fastkit, ref, TorqueController(), **kw)
    assert err.value.field == field
    assert f"more than {MAX_CONTROL_STEPS}" in err.value.problem
