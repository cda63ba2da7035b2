"""Sheet-carrying teams in MuJoCo: drop the object, and check taut's rest states.

See :mod:`taut.physics._sheet_model` for the recipe and examples/physics/README.md for the
measured accuracy. Lengths in the scenario's unit (any consistent unit); the ball has the
team's mass (kg; 1 kg when the team has none: forward kinematics of the massless
inextensible sheet does not depend on it).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable

import numpy as np

from .._outcome import check_status
from .._units import GRAVITY
from .._validate import as_array, as_flag, as_positive
from ..errors import InvalidInputError, require_extra
from ..sheet import Equilibrium, Sheet, SheetTeam, check_formation, forward_kinematics
from ..sheet.team import require_team
from . import _run, _tol
from ._mesh import SheetMesh, sheet_mesh, sheet_mesh_spacing, sheet_model_size
from ._sheet_model import SheetSim, build_sheet_sim
from ._statics import barrier, model_pull
from .._repr import CompactRepr

__all__ = ["SettleResult", "StateCheck", "EquilibriaCheck", "settle", "replay_equilibria",
           "DEFAULT_MESH"]

#: Default mesh: spacings across the sheet's widest vertex pair (about 156 mm on the FK
#: paper's Example 1 sheet, 1.56 m across). examples/physics/README.md's convergence
#: table: the tied height's ~1 mm bias does not change from mesh 7 to 16; the released
#: height (ball radius 0.05 spacings) is within 2.6 mm at 10 and falls as the mesh refines,
#: at a cost that grows fast (Example 1: 4.4 s at 10, 9.4 s at 13; at 16 a rolling
#: released ball took over 5 minutes and did not settle within its budget).
DEFAULT_MESH = 10


@dataclass(frozen=True, eq=False, repr=False)
class SettleResult(CompactRepr):
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


@dataclass(frozen=True, eq=False, repr=False)
class StateCheck(CompactRepr):
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
        Where it came to rest after being released there (NaN when a run failed: see
        ``status``; kept when the state is ``"not_strict"``).
    held : bool
        The simulated sheet holds the object at taut's contact point: its tendons' net pull
        on the tied contact node, resolved in the flat sheet, is at most ``hold_tolerance``
        times the object's weight (a frictionless object is pulled sideways otherwise).
    sliding : float
        That net pull divided by the object's weight (0 at an exact equilibrium). With
        corner tendons (the default) it is the pull of the corner tendons the tied
        simulation has taut, read as rigid cables at the lowest point they let the object
        hang (MuJoCo's own tendon forces, from soft limits, pull stable states sideways by
        up to 0.05 of the weight at any mesh); at a state with four or more taut cables
        the point load is statically indeterminate and this is the least pull over the
        tensions that hold it (see :func:`taut.physics._run.sliding_force`).
    predicted_sliding : float
        The least sideways pull taut's own model exerts on the object there, as a
        fraction of its weight (0 at an equilibrium; ``inf`` when the taut cables cannot
        carry the weight): what ``sliding`` measures.
    resolved : bool
        The held verdict can tell taut's verdict apart: false for a state that is not an
        equilibrium but whose model pull is at most ``hold_tolerance`` (it lies within the
        check's resolution of an equilibrium), where held or not held is not evidence
        either way. With the default tolerance and corner tendons (``HOLD_FRACTION`` =
        1e-4, stable states reading below 1e-12) every non-equilibrium of issue 31's
        30-team sample is resolved (smallest model pull 0.001); with
        ``corner_tendons=False`` (``FORCE_HOLD_FRACTION`` = 0.05) those pulled by 0.001-0.04
        are not.
    difference : ndarray, shape (3,)
        ``settled - predicted`` (ball radius accounted for), scenario units (NaN when the
        run failed).
    moved : float
        Distance between where the object was tied and where the released ball rests
        (NaN when the run failed).
    tied_difference : ndarray, shape (3,)
        ``tied - predicted``.
    agrees : bool
        ``held`` for a stable state, not held for a non-equilibrium (saddles and
        unresolved states: always).
        Read from the tied run: it stands when only the release failed; when the tied
        run itself did not settle, the pull of a moving sheet is no verdict and this is
        true (``status`` and ``message`` say the run failed).
    time : float
        Wall-clock seconds spent on this state (build and simulation).
    reached : tuple of int or None
        The taut set of another of taut's rest states where the released object came to
        rest (its settled position is nearer that state's object than this one's), else
        None.
    basin : float
        When the released object left a stable state for another one: how far it must
        rise to get there along a straight path of its contact point in the flat sheet, an
        upper bound on the depth of this state's basin (scenario units); NaN otherwise.
    nodes : ndarray, shape (M, 3)
        The tied, settled sheet's node positions, scenario units (for figures).
    triangles : ndarray of int, shape (T, 3)
    success, status, message
        The simulation's own outcome (:mod:`taut._outcome`): ``"ok"`` when the tied run
        came to rest and the released object settled on the sheet; ``"diverged"`` when
        the object left the sheet (fell through or off it) or the state became
        non-finite; ``"not_converged"`` when a run was still moving at its time limit;
        ``"not_strict"`` when the released object left a stable state whose basin is
        shallower than the ball's reach (ball plus sheet collision radius): a marginal
        state that a finite object does not keep (``reached``, ``basin``).
    """

    taut: tuple[int, ...]
    kind: str
    predicted: np.ndarray
    tied: np.ndarray
    settled: np.ndarray
    held: bool
    sliding: float
    predicted_sliding: float
    resolved: bool
    difference: np.ndarray
    moved: float
    tied_difference: np.ndarray
    agrees: bool
    time: float
    reached: tuple[int, ...] | None
    basin: float
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
    ``"not_converged"``: the check could not be completed; ``"not_strict"``: a released
    object left a marginal stable state). States whose verdict is not resolved (see
    :attr:`StateCheck.resolved`) are named in ``message``.
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


def _mass(team: SheetTeam) -> float:
    """The ball's mass, kg: the team's object mass, else ``BALL_MASS``."""
    return _tol.BALL_MASS if team.mass is None else float(team.mass)


#: Coarsest and finest mesh accepted (spacings across the sheet).
_MIN_MESH, _MAX_MESH = 4, 60


def _check_size(sheet: Sheet, div: int, corner_tendons: bool) -> None:
    """Refuse a sheet model of more than ``MAX_SHEET_TENDONS`` tendons before anything is
    built (issue 24: its memory grows with them). Names ``mesh`` and the finest coarser
    mesh that fits when one does, else ``sheet``. The count is not monotonic in the mesh
    (at a coarse mesh every boundary node of a many-sided sheet is within reach of every
    other), so coarser meshes are tried in turn; with corner tendons no mesh fits when
    the corner-to-corner ones alone are too many."""
    def tendons(d: int) -> tuple[int, int]:
        return sheet_model_size(sheet.vertices, d, corner_tendons=corner_tendons)

    nodes, count = tendons(div)
    limit = _tol.MAX_SHEET_TENDONS
    if count <= limit:
        return
    n = len(sheet.vertices)
    what = (f"the MuJoCo sheet model would have {nodes} nodes and about {count} tendons "
            f"at mesh {div}, more than the {limit} taut simulates (about 1 GB of memory)")
    if not (corner_tendons and n * (n - 1) > limit):
        for d in range(div - 1, _MIN_MESH - 1, -1):
            if tendons(d)[1] <= limit:
                raise InvalidInputError("mesh", f"{what}; mesh {d} fits")
    raise InvalidInputError("sheet", f"{n} robots: {what}, and no coarser mesh fits")


def _check_inputs(team: SheetTeam, formation: object, mesh: int, ball: float | None, *,
                  corner_tendons: bool) -> tuple[np.ndarray, int, float]:
    sheet = require_team(team).sheet
    R = check_formation(sheet, as_array(formation, "formation", ndim=2))
    if not isinstance(mesh, (int, np.integer)) or not _MIN_MESH <= mesh <= _MAX_MESH:
        raise InvalidInputError("mesh", f"must be an integer from {_MIN_MESH} to {_MAX_MESH} "
                                        f"(spacings across the sheet), got {mesh!r}")
    _check_size(sheet, int(mesh), corner_tendons)
    D = float(np.max(sheet.side_lengths()))
    r = (_tol.BALL_RADIUS * sheet_mesh_spacing(sheet.vertices, int(mesh)) if ball is None
         else as_positive(ball, "ball"))
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
        The sheet, the holding height :math:`z_r`, scenario units, and the ball's mass
        (kg; 1 kg when the team has none).
    formation : array_like, shape (N, 2)
        Robot positions :math:`\\mathbf{r}_i`, scenario units.
    start : array_like, shape (3,), optional
        Initial ball centre; default above the robots' centroid, just over the hold height.
    mesh : int
        Mesh spacings across the sheet's widest vertex pair (spacing = width / mesh), 4 to
        60. A model of more than ``MAX_SHEET_TENDONS`` tendons is refused before it is
        built (:class:`taut.errors.InvalidInputError` naming ``mesh``, or ``sheet`` when
        no coarser mesh fits).
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
    require_extra("mujoco")
    trace = as_flag(trace, "trace")
    R, div, radius = _check_inputs(team, formation, mesh, ball, corner_tendons=False)
    sheet, z = team.sheet, team.hold_height
    p0 = None if start is None else as_array(start, "start", shape=(3,))
    max_t = as_positive(max_time, "max_time")
    m = sheet_mesh(sheet.vertices, div)
    sim = build_sheet_sim(m, sheet.vertices, R, z, ball_radius=radius, ball_start=p0,
                          tie=False, corner_tendons=False, ball_mass=_mass(team))
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
                  radius: float, *, corner_tendons: bool, mass: float = _tol.BALL_MASS
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
                              pin_contact=pin, ball_mass=mass)
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


def _run_status(label: str, tied_run: str, outcome: str, t_rel: float) -> tuple[str, str]:
    """Status and message of one state's two runs (tied, then released)."""
    if tied_run == "diverged":
        return "diverged", f"{label}: the tied run diverged (non-finite state)"
    if tied_run != "settled":
        return "not_converged", (f"{label}: the tied sheet was still moving after "
                                 f"{_tol.MAX_SETTLE_TIME:g} s")
    if outcome == "left":
        when = f"{t_rel:.1f} s after release" if t_rel > 0 else "while it was being placed"
        return "diverged", f"{label}: the object left the sheet {when}"
    if outcome == "diverged":
        return "diverged", f"{label}: the released run diverged (non-finite state)"
    if outcome == "moving":
        return "not_converged", (f"{label}: the released object was still moving after "
                                 f"{t_rel:.1f} s simulated")
    return "ok", f"{label}: released object settled after {t_rel:.1f} s"


def _label(taut: tuple[int, ...]) -> str:
    return "{" + ",".join(str(i + 1) for i in taut) + "}"


def _tied_run(sheet: Sheet, R: np.ndarray, z: float, m: SheetMesh, radius: float, *,
              corner_tendons: bool, mass: float) -> tuple[SheetSim, str]:
    """The tied half of a state's check: the object tied to ``m``'s contact node as a
    point load (contacts off: the model's object), settled until it moves slower than
    ``TIED_SETTLE_SPEED`` or ``MAX_SETTLE_TIME`` passes. Returns the simulation as it
    stopped and the outcome of :func:`taut.physics._run.settle_phase`."""
    sim = build_sheet_sim(m, sheet.vertices, R, z, ball_radius=radius, ball_start=None,
                          tie=True, corner_tendons=corner_tendons, ball_mass=mass)
    _run.ramp(sim)
    outcome, _ = _run.settle_phase(sim, _tol.MAX_SETTLE_TIME, speed=_tol.TIED_SETTLE_SPEED)
    return sim, outcome


def _sliding(sim: SheetSim, mass: float) -> float:
    """The sheet's least net sideways pull on the tied contact node
    (:func:`taut.physics._run.sliding_force`) over the object's weight (``mass``, kg)."""
    return float(np.linalg.norm(_run.sliding_force(sim)) / (mass * GRAVITY))


def _replay_state(sheet: Sheet, R: np.ndarray, z: float, eq: Equilibrium, div: int, radius: float,
                  tol: float, *, corner_tendons: bool, mass: float) -> StateCheck:
    import time

    t0 = time.perf_counter()
    m = sheet_mesh(sheet.vertices, div, contact=eq.contact)
    sim, tied_run = _tied_run(sheet, R, z, m, radius, corner_tendons=corner_tendons,
                              mass=mass)
    tied_at = _run.object_on_sheet(sim)
    assert tied_at is not None                                         # tied: always on
    tied = tied_at[0]
    nodes = _run.node_positions(sim) / sim.scale
    sliding = _sliding(sim, mass)
    del sim                 # freed before the released run's model is built (issue 24)
    pred = np.asarray(eq.object, dtype=float)
    model = model_pull(sheet.vertices, R, z, tuple(eq.taut), pred, np.asarray(eq.contact))
    # Released: a second model, the ball held over taut's object position while it presses
    # the sheet down from the flat start (contacts on), so the sheet forms its pocket under
    # the ball; then let go. (A ball put on the point-loaded sheet can miss the pocket: the
    # slack sheet around a point load may fold into a narrow crease.)
    outcome, t_rel, found = _release_over(sheet, R, z, m, pred[:2], radius,
                                          corner_tendons=corner_tendons, mass=mass)
    held = sliding <= tol
    kind = str(eq.kind)
    resolved = kind != "not_equilibrium" or model > tol
    agrees = (kind == "saddle" or not resolved or tied_run != "settled"
              or held == (kind == "stable"))
    status, message = _run_status(_label(tuple(eq.taut)), tied_run, outcome, t_rel)
    ok = status == "ok"
    if ok:
        assert found is not None
        settled = found[0]
    else:
        settled = np.full(3, np.nan)
    return StateCheck(tuple(eq.taut), kind, pred, tied, settled, held, sliding, model,
                      resolved, settled - pred, float(np.linalg.norm(settled - tied)),
                      tied - pred, agrees, time.perf_counter() - t0, None, np.nan, nodes,
                      m.triangles, ok, check_status(status), message)


def _where_released(team: SheetTeam, R: np.ndarray, states: list[StateCheck],
                    contacts: list[np.ndarray], reach: float) -> list[StateCheck]:
    """Mark each released object that came to rest nearer another of taut's states than
    its own (``reached``); a stable state it left over a rim lower than ``reach`` (the
    ball's radius plus the sheet's collision radius, scenario units: a ball of that size
    does not see a shallower dip) is marginal (status ``"not_strict"``, ``basin``)."""
    out = []
    for k, s in enumerate(states):
        if not s.success or len(states) < 2:
            out.append(s)
            continue
        # Another state is reached only if it lies beyond the ball's reach from this one
        # (nearer states are one place to a ball of that size).
        dist = [float(np.linalg.norm(s.settled - o.predicted))
                if o is s or np.linalg.norm(o.predicted - s.predicted) > reach else np.inf
                for o in states]
        j = int(np.argmin(dist))
        if j == k:
            out.append(s)
            continue
        other = states[j]
        if s.kind != "stable":
            out.append(replace(s, reached=other.taut))
            continue
        rim = barrier(team.sheet.vertices, R, team.hold_height,
                      (s.predicted, contacts[k]), (other.predicted, contacts[j]))
        if rim > reach:
            out.append(replace(s, reached=other.taut, basin=rim))
            continue
        msg = (f"{_label(s.taut)}: marginal: the released object left for "
               f"{_label(other.taut)} ({s.difference[2]:+.1f} in height); the state's basin "
               f"is at most {rim:.2g} deep, less than the ball's reach {reach:.2g}")
        out.append(replace(s, reached=other.taut, basin=rim, success=False,
                           status=check_status("not_strict"), message=msg))
    return out


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
        As for :func:`taut.sheet.forward_kinematics` (scenario units; the team's mass,
        kg, is the ball's, 1 kg when it has none).
    mesh : int
        Mesh spacings across the sheet's widest vertex pair, 4 to 60; refused above
        ``MAX_SHEET_TENDONS`` tendons, as for :func:`settle` (regular teams: 12 robots
        up to mesh 60, 100 up to 34, 310 up to 11; 330 or more at none).
    ball : float, optional
        Ball radius, scenario units (default ``BALL_RADIUS`` = 0.05 spacings; a sheet
        scenario's ``object.radius``, :attr:`taut.io.SheetScenario.object_radius`).
    hold_tolerance : float, optional
        The object counts as held when the sheet's net sideways pull on the tied object is
        at most this fraction of its weight (dimensionless; default ``HOLD_FRACTION`` =
        1e-4 with corner tendons, whose taut set is read as rigid cables, and
        ``FORCE_HOLD_FRACTION`` = 0.05 without them, where MuJoCo's soft tendon forces are
        read; see :func:`taut.physics._run.sliding_force`).
    corner_tendons : bool
        Add a tendon from every node to every held corner (makes the tied point load
        nearly exact; see the README's table).
    progress : callable(done, total), optional
        Called after each state (the CLI's progress bar).

    Returns
    -------
    EquilibriaCheck
    """
    require_extra("mujoco")
    corner_tendons = as_flag(corner_tendons, "corner_tendons")
    R, div, radius = _check_inputs(team, formation, mesh, ball,
                                   corner_tendons=corner_tendons)
    sheet, z = team.sheet, team.hold_height
    default = _tol.HOLD_FRACTION if corner_tendons else _tol.FORCE_HOLD_FRACTION
    tol = default if hold_tolerance is None else as_positive(hold_tolerance, "hold_tolerance")
    fk = forward_kinematics(team, R)
    states = []
    for k, eq in enumerate(fk.equilibria):
        states.append(_replay_state(sheet, R, z, eq, div, radius, tol,
                                     corner_tendons=corner_tendons, mass=_mass(team)))
        if progress is not None:
            progress(k + 1, len(fk.equilibria))
    reach = radius + _tol.FLEX_RADIUS * sheet_mesh_spacing(sheet.vertices, div)
    states = _where_released(team, R, states, [np.asarray(e.contact) for e in fk.equilibria],
                             reach)
    return _summary(states, tol, div, radius)


def _summary(states: list[StateCheck], tol: float, div: int, radius: float
             ) -> EquilibriaCheck:
    bad = [s for s in states if not s.agrees]
    failed = [s for s in states if not s.success]
    if bad:
        s = bad[0]
        status = "unverified"
        msg = (f"{len(bad)} of {len(states)} state(s) disagree; first: {_label(s.taut)} "
               f"({s.kind}) was {'held' if s.held else 'not held'} in physics")
    elif failed:
        status = failed[0].status
        msg = (f"{len(failed)} of {len(states)} state(s) not confirmed; first: "
               f"{failed[0].message}")
    else:
        status = "ok"
        msg = f"physics agrees with taut on all {len(states)} state(s)"
    if bad and failed:
        msg += f"; {len(failed)} state(s) not confirmed"
    unresolved = [_label(s.taut) for s in states if not s.resolved]
    if unresolved:
        msg += (f"; {', '.join(unresolved)} not resolved (taut's own pull there is "
                f"within the hold tolerance)")
    return EquilibriaCheck(tuple(states), tol, div, radius, status == "ok",
                           check_status(status), msg)
