"""Sheet-carrying teams in MuJoCo: drop the object, and check taut's rest states.

See :mod:`taut.physics._sheet_model` for the recipe and examples/physics/README.md for the
measured accuracy. Lengths in the scenario's unit (any consistent unit); the object's mass
does not enter (forward kinematics of the massless inextensible sheet does not depend on
it), the simulation uses a fixed 1 kg ball.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from .._outcome import check_status
from .._units import GRAVITY
from .._validate import as_array, as_flag, as_positive
from ..errors import InvalidInputError
from ..sheet import Equilibrium, Sheet, SheetTeam, check_formation, forward_kinematics
from ..sheet.team import require_team
from . import _run, _tol
from ._mesh import SheetMesh, sheet_mesh
from ._sheet_model import build_sheet_sim

__all__ = ["SettleResult", "StateCheck", "EquilibriaCheck", "settle", "replay_equilibria",
           "DEFAULT_MESH"]

#: Default mesh: spacings across the sheet's widest vertex pair (about 156 mm on the FK
#: paper's Example 1 sheet, 1.56 m across). examples/physics/README.md's convergence
#: table: the tied height's ~1 mm bias does not change from mesh 7 to 16; the released
#: height (ball radius 0.05 spacings) is within 2.6 mm at 10 and falls as the mesh refines,
#: at a cost that grows fast (Example 1: 4.4 s at 10, 9.4 s at 13; at 16 a rolling
#: released ball took over 5 minutes and did not settle within its budget).
DEFAULT_MESH = 10


@dataclass(frozen=True, eq=False)
class SettleResult:
    """Where a dropped object came to rest on the simulated sheet.

    Attributes
    ----------
    position : ndarray, shape (3,)
        The object's rest position: the sheet point under the ball's centre (so the ball
        radius is accounted for), scenario units.
    contact : ndarray, shape (2,)
        That point in the flat sheet frame (taut's contact point :math:`\\mathbf{v}_o`).
    time : float
        Simulated settling time, s.
    converged : bool
        Ball and sheet came to rest before the time limit.
    nodes : ndarray, shape (M, 3)
        Settled node positions, scenario units (for figures).
    triangles : ndarray of int, shape (T, 3)
    trace : ndarray, shape (K, 4) or None
        ``(t, x, y, z)`` of the ball's centre at every check, when asked for.
    frames : ndarray, shape (K, M, 3) or None
        Node positions at every check, when a trace was asked for (for animations).
    success, status, message
        The result convention of :mod:`taut._outcome`.
    """

    position: np.ndarray
    contact: np.ndarray
    time: float
    converged: bool
    nodes: np.ndarray
    triangles: np.ndarray
    trace: np.ndarray | None
    frames: np.ndarray | None
    success: bool
    status: str
    message: str


@dataclass(frozen=True, eq=False)
class StateCheck:
    """One of taut's rest states checked in MuJoCo.

    Attributes
    ----------
    taut : tuple of int
        The state's taut cables (0-based), as taut reported them.
    kind : str
        taut's verdict: ``"stable"``, ``"saddle"`` or ``"not_equilibrium"``.
    predicted : ndarray, shape (3,)
        taut's object position.
    tied : ndarray, shape (3,)
        Where the object settled tied to the sheet at taut's contact point.
    settled : ndarray, shape (3,)
        Where it came to rest after being released there (NaN when the run failed: see
        ``status``).
    held : bool
        The simulated sheet holds the object at taut's contact point: its tendons' net pull
        on the tied contact node, resolved in the flat sheet, is at most ``hold_tolerance``
        times the object's weight (a frictionless object is pulled sideways otherwise).
    sliding : float
        That net pull divided by the object's weight (0 at an exact equilibrium).
    difference : ndarray, shape (3,)
        ``settled - predicted`` (ball radius accounted for), scenario units (NaN when the
        run failed).
    moved : float
        Distance between where the object was tied and where the released ball rests
        (NaN when the run failed).
    tied_difference : ndarray, shape (3,)
        ``tied - predicted``.
    agrees : bool
        ``held`` for a stable state, not held for a non-equilibrium (saddles: always).
        Read from the tied run: it stands when only the release failed, not when the
        tied run itself did not settle (``message`` says which).
    time : float
        Wall-clock seconds spent on this state (build and simulation).
    nodes : ndarray, shape (M, 3)
        The tied, settled sheet's node positions, scenario units (for figures).
    triangles : ndarray of int, shape (T, 3)
    success, status, message
        The simulation's own outcome (:mod:`taut._outcome`): ``"ok"`` when the tied run
        came to rest and the released object settled on the sheet; ``"diverged"`` when
        the object left the sheet (fell through or off it) or the state became
        non-finite; ``"not_converged"`` when a run was still moving at its time limit.
    """

    taut: tuple[int, ...]
    kind: str
    predicted: np.ndarray
    tied: np.ndarray
    settled: np.ndarray
    held: bool
    sliding: float
    difference: np.ndarray
    moved: float
    tied_difference: np.ndarray
    agrees: bool
    time: float
    nodes: np.ndarray
    triangles: np.ndarray
    success: bool
    status: str
    message: str


@dataclass(frozen=True, eq=False)
class EquilibriaCheck:
    """Every rest state taut reports for one formation, checked in MuJoCo.

    ``success`` is true when every state's physics verdict agrees with taut's (stable
    states held, states that are not equilibria not held; saddles either way) and every
    state's simulation succeeded; ``status`` is ``"ok"``, ``"unverified"`` (taut's answer
    failed the physics check) or else the first failed state's status (``"diverged"``,
    ``"not_converged"``: the check could not be completed).
    ``hold_tolerance`` is the sliding pull, as a fraction of the object's weight, up to
    which the object counts as held.
    """

    states: tuple[StateCheck, ...]
    hold_tolerance: float
    mesh: int
    ball: float
    success: bool
    status: str
    message: str


def _check_inputs(team: SheetTeam, formation: object, mesh: int, ball: float | None
                  ) -> tuple[np.ndarray, int, float]:
    sheet = require_team(team).sheet
    R = check_formation(sheet, as_array(formation, "formation", ndim=2))
    if not isinstance(mesh, (int, np.integer)) or not 4 <= mesh <= 60:
        raise InvalidInputError("mesh", f"must be an integer from 4 to 60 (spacings across "
                                        f"the sheet), got {mesh!r}")
    D = float(np.max(sheet.side_lengths()))
    r = (_tol.BALL_RADIUS * D / mesh) if ball is None else as_positive(ball, "ball")
    if r > 0.2 * D:
        raise InvalidInputError("ball", f"radius {r:g} is too large for a sheet {D:g} across")
    return R, int(mesh), r


def settle(team: SheetTeam, formation: object, *, start: object = None,
           mesh: int = DEFAULT_MESH, ball: float | None = None,
           max_time: float = _tol.MAX_SETTLE_TIME, trace: bool = False) -> SettleResult:
    """Drop the object on the simulated sheet and return where it comes to rest.

    Parameters
    ----------
    team : SheetTeam
        The sheet and the holding height :math:`z_r`, scenario units (its mass is not
        used: the simulation drops a 1 kg ball).
    formation : array_like, shape (N, 2)
        Robot positions :math:`\\mathbf{r}_i`, scenario units.
    start : array_like, shape (3,), optional
        Initial ball centre; default above the robots' centroid, just over the hold height.
    mesh : int
        Mesh spacings across the sheet's widest vertex pair (spacing = width / mesh).
    ball : float, optional
        Ball radius, scenario units (default ``BALL_RADIUS`` = 0.05 spacings).
    max_time : float
        Simulated time limit, s.
    trace : bool
        Record the ball's centre at every settling check.

    Returns
    -------
    SettleResult

    Examples
    --------
    >>> import numpy as np
    >>> from taut.sheet import Sheet, SheetTeam
    >>> sheet = Sheet.regular(3, 500.0)
    >>> r = settle(SheetTeam(sheet, 800.0), 0.8 * sheet.vertices, mesh=8)
    >>> bool(r.converged), bool(0 < r.position[2] < 800)
    (True, True)
    """
    trace = as_flag(trace, "trace")
    R, div, radius = _check_inputs(team, formation, mesh, ball)
    sheet, z = team.sheet, team.hold_height
    p0 = None if start is None else as_array(start, "start", shape=(3,))
    max_t = as_positive(max_time, "max_time")
    m = sheet_mesh(sheet.vertices, div)
    sim = build_sheet_sim(m, sheet.vertices, R, z, ball_radius=radius, ball_start=p0,
                          tie=False, corner_tendons=False)
    _run.ramp(sim)
    rows: list | None = [] if trace else None
    frames: list | None = [] if trace else None
    outcome, t = _run.settle_phase(sim, max_t, rows, frames, watch=True)
    converged = outcome == "settled"
    found = None if outcome in ("left", "diverged") else _run.object_on_sheet(sim)
    nodes = _run.node_positions(sim) / sim.scale
    tr = None if rows is None else np.array(rows) / [1.0, *[sim.scale] * 3]
    fr = None if frames is None else np.array(frames) / sim.scale
    if found is None:
        nan = np.full(3, np.nan)
        return SettleResult(nan, nan[:2], t, False, nodes, m.triangles, tr, fr, False,
                            check_status("diverged"),
                            "the simulation diverged (non-finite state)" if outcome == "diverged"
                            else f"the ball left the sheet after {t:.2f} s (fell through or off)")
    pos, contact = found
    status = "ok" if converged else "not_converged"
    msg = (f"settled at ({pos[0]:.4g}, {pos[1]:.4g}, {pos[2]:.4g}) after {t:.2f} s"
           if converged else f"still moving after {t:.2f} s simulated")
    return SettleResult(pos, contact, t, converged, nodes, m.triangles, tr, fr, converged,
                        check_status(status), msg)


def _release_over(sheet: Sheet, R: np.ndarray, z: float, m: SheetMesh, xy: np.ndarray,
                  radius: float, *, corner_tendons: bool
                  ) -> tuple[str, float, tuple[np.ndarray, np.ndarray] | None]:
    """Hold the ball over ``xy`` (scenario units) while it presses the sheet down, let it
    go, and settle: (outcome of :func:`taut.physics._run.settle_phase`, simulated seconds
    after release, the object's place on the sheet or None).

    When the mesh has a contact node, it is first kept under the ball (the sheet forms
    with taut's contact point under the object); if the ball slips off the sheet that
    way (a pinned non-equilibrium can tilt the sheet away under it), the sheet is formed
    again without the pin."""
    start = np.array([*xy, z + 2 * (_tol.FLEX_RADIUS * m.spacing + radius)])
    for pin in ((True, False) if m.contact is not None else (False,)):
        sim = build_sheet_sim(m, sheet.vertices, R, z, ball_radius=radius, ball_start=start,
                              tie=False, corner_tendons=corner_tendons, hold_xy=True,
                              pin_contact=pin)
        _run.ramp(sim)
        outcome, _ = _run.settle_phase(sim, _tol.MAX_SETTLE_TIME, watch=True)
        if outcome not in ("left", "diverged"):
            break
    else:
        return outcome, 0.0, None
    _run.release(sim)
    outcome, t = _run.settle_phase(sim, _tol.RELEASE_TIME, watch=True)
    found = _run.object_on_sheet(sim)
    if outcome == "settled" and found is None:
        outcome = "left"
    return outcome, t, found


def _replay_state(sheet: Sheet, R: np.ndarray, z: float, eq: Equilibrium, div: int, radius: float,
                  tol: float, *, corner_tendons: bool) -> StateCheck:
    import time

    t0 = time.perf_counter()
    m = sheet_mesh(sheet.vertices, div, contact=eq.contact)
    # Tied: a point load at the contact node, contacts off (the model's object).
    sim = build_sheet_sim(m, sheet.vertices, R, z, ball_radius=radius, ball_start=None,
                          tie=True, corner_tendons=corner_tendons)
    _run.ramp(sim)
    tied_run, _ = _run.settle_phase(sim, _tol.MAX_SETTLE_TIME, speed=_tol.TIED_SETTLE_SPEED)
    tied_at = _run.object_on_sheet(sim)
    assert tied_at is not None                                         # tied: always on
    tied = tied_at[0]
    nodes = _run.node_positions(sim) / sim.scale
    sliding = float(np.linalg.norm(_run.sliding_force(sim)) / (_tol.BALL_MASS * GRAVITY))
    # Released: a second model, the ball held over taut's object position while it presses
    # the sheet down from the flat start (contacts on), so the sheet forms its pocket under
    # the ball; then let go. (A ball put on the point-loaded sheet can miss the pocket: the
    # slack sheet around a point load may fold into a narrow crease.)
    pred = np.asarray(eq.object, dtype=float)
    outcome, t_rel, found = _release_over(sheet, R, z, m, pred[:2], radius,
                                          corner_tendons=corner_tendons)
    held = sliding <= tol
    kind = str(eq.kind)
    agrees = kind == "saddle" or held == (kind == "stable")
    label = "{" + ",".join(str(i + 1) for i in eq.taut) + "}"
    if tied_run == "diverged":
        status, message = "diverged", f"{label}: the tied run diverged (non-finite state)"
    elif tied_run != "settled":
        status = "not_converged"
        message = f"{label}: the tied sheet was still moving after {_tol.MAX_SETTLE_TIME:g} s"
    elif outcome == "left":
        when = f"{t_rel:.1f} s after release" if t_rel > 0 else "while it was being placed"
        status, message = "diverged", f"{label}: the object left the sheet {when}"
    elif outcome == "diverged":
        status, message = "diverged", f"{label}: the released run diverged (non-finite state)"
    elif outcome == "moving":
        status = "not_converged"
        message = f"{label}: the released object was still moving after {t_rel:.1f} s simulated"
    else:
        status, message = "ok", f"{label}: released object settled after {t_rel:.1f} s"
    ok = status == "ok"
    if ok:
        assert found is not None
        settled = found[0]
    else:
        settled = np.full(3, np.nan)
    return StateCheck(tuple(eq.taut), kind, pred, tied, settled, held,
                      sliding, settled - pred, float(np.linalg.norm(settled - tied)),
                      tied - pred, agrees, time.perf_counter() - t0, nodes, m.triangles,
                      ok, check_status(status), message)


def replay_equilibria(team: SheetTeam, formation: object, *, mesh: int = DEFAULT_MESH,
                      ball: float | None = None, hold_tolerance: float | None = None,
                      corner_tendons: bool = True,
                      progress: Callable[[int, int], None] | None = None) -> EquilibriaCheck:
    """Check every rest state taut reports for a formation in MuJoCo.

    For each state of :func:`taut.sheet.forward_kinematics`: the object is tied to the
    simulated sheet at taut's contact point :math:`\\mathbf{v}_o` and settled under gravity
    as a point load (``tied``; ``held`` is read from the sheet's pull on it there). Then,
    in a second model, a ball held over taut's object position presses the sheet down
    from the flat start (contacts on) and is let go (``settled``). Each state's
    ``status`` says whether its runs succeeded: ``"diverged"`` when the object left the
    sheet or the state became non-finite, ``"not_converged"`` when a run was still moving
    at its time limit; ``settled`` is then NaN.

    Parameters
    ----------
    team, formation
        As for :func:`taut.sheet.forward_kinematics` (scenario units; the team's mass is
        not used).
    mesh : int
        Mesh spacings across the sheet's widest vertex pair.
    ball : float, optional
        Ball radius, scenario units (default ``BALL_RADIUS`` = 0.05 spacings).
    hold_tolerance : float, optional
        The object counts as held when the sheet's net sideways pull on the tied object is
        at most this fraction of its weight (dimensionless; default ``HOLD_FRACTION`` =
        0.05).
    corner_tendons : bool
        Add a tendon from every node to every held corner (makes the tied point load
        nearly exact; see the README's table).
    progress : callable(done, total), optional
        Called after each state (the CLI's progress bar).

    Returns
    -------
    EquilibriaCheck
    """
    corner_tendons = as_flag(corner_tendons, "corner_tendons")
    R, div, radius = _check_inputs(team, formation, mesh, ball)
    sheet, z = team.sheet, team.hold_height
    tol = _tol.HOLD_FRACTION if hold_tolerance is None else as_positive(
        hold_tolerance, "hold_tolerance")
    fk = forward_kinematics(team, R)
    states = []
    for k, eq in enumerate(fk.equilibria):
        states.append(_replay_state(sheet, R, z, eq, div, radius, tol,
                                     corner_tendons=corner_tendons))
        if progress is not None:
            progress(k + 1, len(fk.equilibria))
    bad = [s for s in states if not s.agrees]
    failed = [s for s in states if not s.success]
    if bad:
        s = bad[0]
        taut = "{" + ",".join(str(i + 1) for i in s.taut) + "}"
        status = "unverified"
        msg = (f"{len(bad)} of {len(states)} state(s) disagree; first: {taut} ({s.kind}) "
               f"was {'held' if s.held else 'not held'} in physics")
    elif failed:
        status = failed[0].status
        msg = (f"{len(failed)} of {len(states)} simulation(s) failed; first: "
               f"{failed[0].message}")
    else:
        status = "ok"
        msg = f"physics agrees with taut on all {len(states)} state(s)"
    if bad and failed:
        msg += f"; {len(failed)} simulation(s) failed"
    return EquilibriaCheck(tuple(states), tol, div, radius, status == "ok",
                           check_status(status), msg)
