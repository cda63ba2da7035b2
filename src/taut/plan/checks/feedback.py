"""Feedback on the object (issue 28, part 3): robots that correct the measured object back
to the planned path, simulated against open loop under the robustness analysis's drifting
robot errors (docs/sheet_sensitivity.md, "Feedback on the object").

The plan's robots are commanded at every plan sample ``t``; the real robots are off by the
position error of :func:`taut.plan.plan_robustness` (the same model, the same seed: trial
``i`` here has the errors of trial ``i`` there), which the controller does not know. What
it sees is its own commands and the object measured with Gaussian noise
(``measurement_noise_m`` per axis). After each sample it adds to the robots' commands

.. math::

    \\Delta u = J^T (J J^T + \\lambda^2 I)^{-1} \\, g \\, (p_{plan}(t) - \\tilde p_o(t)),

the least robot motion (damped least squares, damping :math:`\\lambda`) that moves the
object by a fraction ``gain`` of the measured error, with ``J`` the ``jacobian`` of the
nominal formation's rest state at that sample (known from the plan); the step is capped
(``FEEDBACK_MAX_STEP`` per robot, ``FEEDBACK_MARGIN_FRACTION`` of the state's
``taut_margin``) and shortened while a commanded robot pair would come closer to its sheet
distance than the plan's pair does or than twice the robot error plus ``SHEET_MARGIN``.
The corrections add up (an integrator: a drifting error is followed). The controller first
runs ``FEEDBACK_SETTLE`` steps at the plan's first sample (lift, measure, correct).

Open loop (``gain`` 0) and closed loop are run by the same stepping simulation
(:class:`taut.sheet.Simulator`, the tracker of :func:`taut.sheet.simulate`) on the same
errors and judged as :func:`plan_robustness` judges a replay: tears, drops, the object's
deviation from the plan.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import SimpleNamespace
from typing import NamedTuple

import numpy as np

from ..._validate import as_bounded, as_choice, as_count, require_instance
from ...errors import PlanningError, TautError
from ...sheet import Equilibrium, FKSolver, Simulator
from .. import _tol
from .._options import NOISES
from ..result import PlanResult
from ..world import Scenario
from .robustness import Trial, _dropped, position_error, replay
from ._geometry import pair_slack
from .verify import _sheet_slack

__all__ = ["ObjectFeedback", "object_feedback"]

#: Seed stream of the measurement noise (apart from the robot errors' stream, so open and
#: closed loop see the same robot errors whatever the noise).
_MEASUREMENT_STREAM = 28


@dataclass(frozen=True, eq=False)
class ObjectFeedback:
    """Closed-loop object control against open loop on the same robot errors
    (:func:`object_feedback`). Lengths in m.

    Attributes
    ----------
    success : bool
        The closed loop did no worse: no more tears or drops than open loop and a median
        deviation (over every sample of every run) no larger.
    status : {"ok", "worse"}
    message : str
        One line with the medians and counts.
    robot_error_m, measurement_noise_m, gain, damping : float
        The options used (robot error as in :func:`plan_robustness`'s ``sigma``).
    trials : int
    open_deviation_m, closed_deviation_m : ndarray, shape (trials,)
        Largest distance of the object from the plan's object over each run, m (NaN for
        a torn run, which is not replayed).
    open_samples_m, closed_samples_m : ndarray, shape (trials, T)
        Distance of the object from the plan's object at every plan sample, m (NaN
        where the object is lost or the run torn).
    open_tears, closed_tears, open_drops, closed_drops : int
        Runs with a robot pair beyond its sheet distance / the object dropped by more
        than 5 mm or lost (as in :class:`Robustness`).
    max_correction_m : ndarray, shape (trials,)
        Largest correction of any robot's command over each closed-loop run, m.
    """

    success: bool
    status: str
    message: str
    robot_error_m: float
    measurement_noise_m: float
    gain: float
    damping: float
    trials: int
    open_deviation_m: np.ndarray
    closed_deviation_m: np.ndarray
    open_samples_m: np.ndarray
    closed_samples_m: np.ndarray
    open_tears: int
    closed_tears: int
    open_drops: int
    closed_drops: int
    max_correction_m: np.ndarray

    @property
    def median_open_m(self) -> float:
        """Median of the open loop's object deviation over every sample of every run, m."""
        return _median(self.open_samples_m)

    @property
    def median_closed_m(self) -> float:
        """Median of the closed loop's object deviation over every sample of every run, m."""
        return _median(self.closed_samples_m)


class _Model(NamedTuple):
    """The controller's model along the plan: per sample ``t`` the damped least-squares
    map (2N, 3) from an object error to the robots' correction, the step cap per robot
    and ``FEEDBACK_MARGIN_FRACTION`` of the taut margin (m, Frobenius norm over the
    robots; inf where the taut set changes under any motion)."""

    gains: np.ndarray
    caps: np.ndarray
    margins: np.ndarray


def _gain(state: Equilibrium | None, n: int, damping: float
          ) -> tuple[np.ndarray, float, float]:
    """The damped least-squares map (2N, 3), per-robot step cap and margin cap (m) of
    one model state (:class:`_Model`). A state whose taut set changes under any motion
    (a similar copy of the sheet, Lemma 2: no ``jacobian``) is corrected by translating
    the whole team, the one motion whose effect is exact (the model is invariant under
    translations: the object moves by as much) and keeps every pair distance."""
    if state is None:
        return np.zeros((2 * n, 3)), 0.0, 0.0
    J = state.jacobian.reshape(3, -1)
    margin = np.inf
    if np.all(np.isfinite(J)):
        margin = _tol.FEEDBACK_MARGIN_FRACTION * state.taut_margin
    else:                           # the one exact motion: translating the whole team
        J = np.zeros((3, n, 2))
        J[0, :, 0] = J[1, :, 1] = 1.0 / n
        J = J.reshape(3, -1)
    K = J.T @ np.linalg.inv(J @ J.T + damping ** 2 * np.eye(3))
    return K, _tol.FEEDBACK_MAX_STEP, margin


def _plan_model(result: PlanResult, damping: float) -> _Model:
    """:class:`_Model` from the plan alone: the rest state of the commanded (nominal)
    formation nearest the planned object at every sample (what the controller knows)."""
    assert result.scenario is not None
    solver = FKSolver(result.scenario.team.carrier)
    R, planned = np.asarray(result.robots), np.asarray(result.object)
    out = [_gain(solver.solve(R[t]).closest_stable(planned[t]), R.shape[1], damping)
           for t in range(len(R))]
    return _Model(*(np.array(a) for a in zip(*out)))


def _run(scenario: Scenario, R: np.ndarray, planned: np.ndarray, model: _Model,
         errors: np.ndarray, noise: np.ndarray, gain: float, keep: np.ndarray
         ) -> tuple[Trial, np.ndarray, float]:
    """One run (module docstring) on robot ``errors`` (T, N, 2) and measurement ``noise``
    (T + FEEDBACK_SETTLE, 3); ``gain`` 0 is the open loop. The run judged as
    :func:`robustness.replay` judges one (tears first, then drops and the largest
    deviation from the plan), the deviation per sample (T,) and the largest correction
    of a robot, m. ``keep`` (T, P): least slack each commanded robot pair keeps, m."""
    team = scenario.team.carrier
    u = np.zeros(R.shape[1:])
    real = R + errors
    obj = np.full(planned.shape, np.nan)
    events: list = []
    largest, sim = 0.0, None
    # The first FEEDBACK_SETTLE steps hold the plan's first sample (the team corrects the
    # object before it moves off); the run is judged from the plan's start.
    order = np.concatenate([np.zeros(_tol.FEEDBACK_SETTLE, dtype=int), np.arange(len(R))])
    for step, t in enumerate(order):
        real[t] = R[t] + u + errors[t]
        try:
            state = (sim.step(real[t]) if sim is not None else
                     (sim := Simulator(team, real[t], start=planned[t])).initial)
        except TautError:           # torn (judged below) or no rest state: a drop
            real[t:] = R[t:] + u + errors[t:]
            events.append(_LOST)
            break
        if step >= _tol.FEEDBACK_SETTLE:
            events.extend(state.events)
            obj[t] = state.object
        if state.success and gain > 0:
            u = _update(u, model, t, gain * (planned[t] - state.object - noise[step]),
                        scenario, R[min(t + 1, len(R) - 1)], keep[min(t + 1, len(R) - 1)])
            largest = max(largest, float(np.linalg.norm(u, axis=1).max()))
    dev = np.linalg.norm(obj - planned, axis=1)
    return _judge(scenario, real, dev, events), dev, largest


def _update(u: np.ndarray, model: _Model, t: int, err: np.ndarray, scenario: Scenario,
            next_robots: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """The correction after the step at sample ``t`` (module docstring): the damped
    least-squares step, capped, added; while a commanded pair of the next sample would
    not keep ``keep``, the step is halved, then the correction (none keeps it)."""
    du = model.gains[t] @ err
    cap = min(model.caps[t] * np.sqrt(len(u)), model.margins[t])
    size = float(np.linalg.norm(du))
    if size > cap:
        du *= cap / size
    du = du.reshape(-1, 2)

    def holds(c: np.ndarray) -> bool:
        return bool(np.all(pair_slack(scenario, (next_robots + c)[None])[0][0] >= keep))
    for _ in range(_tol.FEEDBACK_HALVINGS):        # the step halved first,
        if holds(u + du):
            return u + du
        du = 0.5 * du
    for _ in range(_tol.FEEDBACK_HALVINGS):        # then the correction built up
        if holds(u):
            return u
        u = 0.5 * u
    return np.zeros_like(u)


#: Stands for a simulation that could not go on (no rest state), judged as a loss.
_LOST = SimpleNamespace(kind="lost", drop=np.inf)


def _judge(scenario: Scenario, real: np.ndarray, dev: np.ndarray, events: list) -> Trial:
    """A run as :func:`robustness.replay` judges a replay (tears, drops, the largest
    deviation; the geometric margins are not this analysis's)."""
    if _sheet_slack(scenario, real)[0] < 0:
        return Trial(True, False, False, False, False, np.nan, np.nan, np.nan, np.nan)
    worst = float(np.nanmax(dev)) if np.any(np.isfinite(dev)) else np.nan
    return Trial(False, _dropped(events), False, False, False, np.nan, np.nan, np.nan, worst)


def object_feedback(result: PlanResult, *, robot_error_m: float = _tol.POSITION_ACCURACY,
                    measurement_noise_m: float = _tol.MEASUREMENT_NOISE, trials: int = 20,
                    seed: int = 0, gain: float = _tol.FEEDBACK_GAIN,
                    damping: float = _tol.FEEDBACK_DAMPING, noise: str = "disc",
                    correlation: float = 1.0) -> ObjectFeedback:
    """Closed-loop control of the object along a plan against open loop, under the
    drifting robot errors of :func:`plan_robustness` (module docstring).

    Parameters
    ----------
    result : PlanResult
        A successful plan of :func:`taut.plan.plan`.
    robot_error_m : float
        Robot position error, m, in [0, 1] (``sigma`` of :func:`plan_robustness`).
    measurement_noise_m : float
        Standard deviation of the object measurement per axis, m, in [0, 1].
    trials : int
        Runs, 1 to 100000 (each runs the plan twice: open and closed loop).
    seed : int
        Seed of the robot errors (the same draws as :func:`plan_robustness`'s) and of the
        measurement noise.
    gain : float
        Fraction of the measured error corrected per plan sample, in (0, 1].
    damping : float
        Damping of the least squares (dimensionless), in [0, 10].
    noise : {"disc", "gaussian"}
        Robot error model (:class:`Robustness`).
    correlation : float
        The robot errors are drawn every ``correlation`` s, linear in between.

    Returns
    -------
    ObjectFeedback

    Raises
    ------
    InvalidInputError
        An option out of its range.
    PlanningError
        ``result`` is not a successful plan.
    """
    require_instance(result, PlanResult, "result")
    sigma = as_bounded(robot_error_m, "robot_error_m", _tol.MAX_POSITION_ERROR_M, "m",
                       positive=False)
    meas = as_bounded(measurement_noise_m, "measurement_noise_m",
                      _tol.MAX_MEASUREMENT_NOISE_M, "m", positive=False)
    trials = as_count(trials, "trials", minimum=1, maximum=_tol.MAX_TRIALS)
    seed = as_count(seed, "seed", minimum=0)
    gain = as_bounded(gain, "gain", _tol.MAX_FEEDBACK_GAIN, "")
    damping = as_bounded(damping, "damping", _tol.MAX_FEEDBACK_DAMPING, "", positive=False)
    noise = as_choice(noise, NOISES, "noise")
    correlation = as_bounded(correlation, "correlation", _tol.MAX_CORRELATION_S, "s")
    if not result.success or result.scenario is None:
        raise PlanningError("plan", "object feedback needs a successful plan")
    return _compare(result, sigma, meas, trials, seed, gain, damping, noise, correlation)


def _compare(result: PlanResult, sigma: float, meas: float, trials: int, seed: int,
             gain: float, damping: float, noise: str, correlation: float) -> ObjectFeedback:
    """:func:`object_feedback` on validated options."""
    scenario = result.scenario
    assert scenario is not None
    R, times = np.asarray(result.robots), np.asarray(result.times)
    planned = np.asarray(result.object)
    rng = np.random.default_rng(seed)                       # as plan_robustness's
    sensor = np.random.default_rng((seed, _MEASUREMENT_STREAM))
    model = _plan_model(result, damping)
    plan_slack = pair_slack(scenario, R)[0]
    keep = np.minimum(plan_slack, 2 * sigma + _tol.SHEET_MARGIN)
    opened: list[Trial] = []
    closed: list[Trial] = []
    largest: list[float] = []
    per_sample: tuple[list[np.ndarray], list[np.ndarray]] = ([], [])
    for _ in range(trials):
        errors = position_error(rng, times, R.shape[1], sigma, noise, correlation)
        shake = sensor.normal(0.0, meas, (len(R) + _tol.FEEDBACK_SETTLE, 3))
        for g, runs, devs in ((0.0, opened, per_sample[0]), (gain, closed, per_sample[1])):
            trial, dev, big = _run(scenario, R, planned, model, errors, shake, g, keep)
            runs.append(trial)
            devs.append(dev)
        largest.append(big)
    return _outcome(opened, closed, per_sample, np.array(largest), sigma, meas, gain,
                    damping)


def _outcome(opened: list[Trial], closed: list[Trial],
             per_sample: tuple[list[np.ndarray], list[np.ndarray]], largest: np.ndarray,
             sigma: float, meas: float, gain: float, damping: float) -> ObjectFeedback:
    dev_o = np.array([t.deviation for t in opened])
    dev_c = np.array([t.deviation for t in closed])
    tears = (sum(t.torn for t in opened), sum(t.torn for t in closed))
    drops = (sum(t.dropped for t in opened), sum(t.dropped for t in closed))
    med = [_median(dev_o), _median(dev_c)]
    samples = [np.array(d) for d in per_sample]
    med_s = [_median(d) for d in samples]
    ok = tears[1] <= tears[0] and drops[1] <= drops[0] and not med_s[1] > med_s[0]
    message = (f"median object deviation {med_s[1] * 1e3:.3g} mm closed loop vs "
               f"{med_s[0] * 1e3:.3g} mm open loop (largest per run: median "
               f"{med[1] * 1e3:.3g} vs {med[0] * 1e3:.3g} mm) over {len(opened)} runs; "
               f"tears {tears[1]} vs {tears[0]}, drops {drops[1]} vs {drops[0]}")
    return ObjectFeedback(ok, "ok" if ok else "worse", message, sigma, meas, gain, damping,
                          len(opened), dev_o, dev_c, samples[0], samples[1], tears[0],
                          tears[1], drops[0], drops[1], largest)


def _median(values: np.ndarray) -> float:
    """Median of the finite values, NaN without any."""
    finite = values[np.isfinite(values)]
    return float(np.median(finite)) if len(finite) else np.nan
