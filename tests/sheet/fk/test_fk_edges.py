"""Sheet answers at the edges (issue 25): regular sheets held as scaled copies, coordinates
written to finite digits, noise far below any physical scale. One physical state is
reported once, by every method, backend and the batch; a hanging object always has a
lowest rest state."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

import taut.sheet as ts
from taut.errors import InfeasibleFormationError, InvalidInputError
from taut.sheet import FKSolver, HAVE_NUMBA, Sheet, SheetTeam
from taut.sheet._tol import MERGE_RTOL, SNAP_MIN, SNAP_TOL, TAUT_TOL
from taut.sheet.fk._similar import similar_copy

from fk_exact import brute_lowest, exact_states, sharp_minimum
from test_fk_edges_property import draw_team

BACKENDS = ["numba", "numpy"] if HAVE_NUMBA else ["numpy"]


def regular(n: int) -> np.ndarray:
    a = 2 * np.pi * np.arange(n) / n
    return np.c_[np.cos(a), np.sin(a)]


def digits_team(n: int, scale: float = 0.9, digits: int = 6):
    """A regular n-gon and its scaled copy, both written to ``digits`` decimals."""
    V = np.round(regular(n), digits)
    return SheetTeam(Sheet(V), 1.0, mass=1.0), np.round(scale * V, digits)


def noisy_team(n: int, noise: float, seed: int, scale: float = 0.9):
    V = regular(n)
    R = scale * V + noise * np.random.default_rng(seed).standard_normal(V.shape)
    return SheetTeam(Sheet(V), 1.0, mass=1.0), R


def answers(team: SheetTeam, R: np.ndarray) -> dict[str, ts.FKResult]:
    """The result of every method, backend and the batch for one formation."""
    out = {}
    for backend in BACKENDS:
        for method in ("fast", "subsets"):
            out[f"{method}-{backend}"] = FKSolver(team, method=method,
                                                  backend=backend).solve(R)
    if team.n <= 12:
        out["exhaustive"] = ts.forward_kinematics(team, R, method="exhaustive")
    out["batch"] = ts.forward_kinematics_batch(team, R[None]).result(0)
    return out


def assert_physical(res: ts.FKResult) -> None:
    """No state twice; every state balances (sum w = 1, sum w r_i = r_o, sum w v_i = v_o)."""
    size = res.sheet.size
    eqs = res.equilibria
    for i, a in enumerate(eqs):
        for b in eqs[i + 1:]:
            d = max(np.abs(a.object - b.object).max(), np.abs(a.contact - b.contact).max())
            assert d > MERGE_RTOL * size, (a, b)
        if a.is_equilibrium:
            idx = list(a.taut)
            assert a.weights.min() >= -1e-8
            assert a.weights.sum() == pytest.approx(1.0, abs=1e-9)
            np.testing.assert_allclose(a.weights @ res.formation[idx], a.object[:2],
                                       atol=1e-8 * size)
            np.testing.assert_allclose(a.weights @ res.sheet.vertices[idx], a.contact,
                                       atol=1e-8 * size)


def assert_agree(results: dict[str, ts.FKResult], size: float) -> None:
    """Every answer has one or more stable states, the same ones (positions within the
    merge tolerance), no state twice."""
    ref_name, ref = next(iter(results.items()))
    ref_pts = sorted(e.object.tolist() for e in ref.stable)
    assert ref_pts, ref_name
    for name, res in results.items():
        assert res.success and res.lowest is not None and res.lowest.stable, name
        assert_physical(res)
        pts = sorted(e.object.tolist() for e in res.stable)
        assert len(pts) == len(ref_pts), (name, res.stable, ref.stable)
        np.testing.assert_allclose(pts, ref_pts, atol=2 * MERGE_RTOL * size, err_msg=name)


# n = 30 (~2 s of CPU) in the slow target; 16 and 24 keep the rounded regular polygon in
# the fast suite.
@pytest.mark.parametrize("n", [16, 24, pytest.param(30, marks=pytest.mark.slow)])
def test_regular_polygon_written_to_six_decimals_has_one_state(n):
    """Issue 25: a regular 30-gon at 0.9x written to 6 decimals was 129 "stable" states at
    one point (24-gon 77, 16-gon 17; the 16-gon later none stable at all): one state, at
    the centre, hanging sqrt(1 - 0.81) = 0.4359 below the robots."""
    team, R = digits_team(n)
    res = answers(team, R)
    assert_agree(res, team.sheet.size)
    for r in res.values():
        assert len(r.stable) == 1
        np.testing.assert_allclose(r.lowest.object, [0, 0, 1 - np.sqrt(1 - 0.81)], atol=2e-5)


@pytest.mark.parametrize("seed", range(4))
def test_decagon_with_tiny_noise_has_one_state(seed):
    """Issue 25: a regular decagon at 0.9x with 1e-7 noise gave two stable states 1e-9 to
    7e-7 apart, from every method."""
    team, R = noisy_team(10, 1e-7, seed)
    res = answers(team, R)
    assert_agree(res, team.sheet.size)
    assert all(len(r.stable) == 1 for r in res.values())


@pytest.mark.parametrize("n", [5, 6])
@pytest.mark.parametrize("noise", [1e-13, 1e-12, 1e-11, 1e-10, "digits"])
def test_exhaustive_finds_the_hanging_state(n, noise):
    """Issue 25: Algorithm 1 found no stable state on pentagons and hexagons at 0.9x with
    noise 1e-13..1e-10 or written to 6 decimals, where "fast" found the one there is."""
    team, R = digits_team(n) if noise == "digits" else noisy_team(n, noise, 7)
    assert_agree(answers(team, R), team.sheet.size)


@pytest.mark.parametrize("seed", range(4))
def test_octagon_with_noise_is_held(seed):
    """Issue 25: an octagon at 0.9x plus 1e-7 noise was reported with a single
    not_equilibrium state and no stable one."""
    team, R = noisy_team(8, 1e-7, seed)
    assert_agree(answers(team, R), team.sheet.size)


def stretch(team: SheetTeam, R: np.ndarray, e: ts.Equilibrium) -> np.ndarray:
    """(L_j^2 - l_j^2) / s^2 (N,) of state ``e``, from world coordinates: robot-to-object
    distance squared minus cable length squared on the sheet (0 on a taut cable)."""
    L2 = ((R - e.object[:2]) ** 2).sum(axis=1) + (team.hold_height - e.object[2]) ** 2
    l2 = ((team.sheet.vertices - e.contact) ** 2).sum(axis=1)
    return (L2 - l2) / team.sheet.size ** 2


def test_merged_state_is_every_cable_at_full_length():
    """The hexagon written to 6 decimals split into two stable states 3.5e-6 apart, each on
    4 cables with two zero weights. The one state reported is on exactly the cables at full
    length at its point (within TAUT_TOL), not on the union of the members' cables: two of
    those are slack there by 1.3e-6 of the squared size (issue 25: the simulator, which
    tests the cables at its own point, disagreed with such a union). Its non-negative
    weights balance it."""
    team, R = digits_team(6)
    for method in ("fast", "subsets", "exhaustive"):
        res = ts.forward_kinematics(team, R, method=method)
        (e,) = res.equilibria
        assert e.stable and len(e.taut) == 4, method
        s = stretch(team, R, e)
        assert e.taut == tuple(np.flatnonzero(s >= -TAUT_TOL)), (method, s)
        assert np.sort(s)[:2].max() < -1e-6, (method, s)       # two cables truly slack
        lengths = np.linalg.norm(team.sheet.vertices[list(e.taut)] - e.contact, axis=1)
        np.testing.assert_allclose(e.cable_lengths, lengths)
        assert e.tensions is not None and np.all(e.tensions >= 0)
        np.testing.assert_allclose(e.weights @ R[list(e.taut)], e.object[:2], atol=1e-12)


@pytest.mark.parametrize("seed", range(0, 1200, 20))
def test_every_state_is_on_the_cables_at_full_length(seed):
    """One definition of taut (``_lifted.taut_at``): on the edge teams of the property run
    (regular and random copies, noise, finite digits, collinear and coincident robots),
    every state of every method, backend and the batch -- enumerated, merged or supplied by
    the direct minimisation -- names exactly the cables whose robot-to-object distance
    equals their length on the sheet within TAUT_TOL, computed here in world coordinates
    (the kernels compute it in lifted coordinates)."""
    sheet, R, label = draw_team(seed)
    team = SheetTeam(sheet, 4.0 * sheet.size)
    try:
        res = answers(team, R)
    except InfeasibleFormationError:
        return
    # Within SNAP_TOL of a similar copy the states are the copy's (docs/sheet_fk_solver.md
    # "Next to a similar copy"): their cables are at full length in the copy.
    copy, scale, dist = similar_copy(sheet.vertices, R[None])
    snap = SNAP_MIN * sheet.size < dist[0] <= SNAP_TOL * sheet.size and scale[0] <= 1.0
    for name, r in res.items():
        for e in r.equilibria:
            full = [tuple(np.flatnonzero(stretch(team, F, e) >= -TAUT_TOL))
                    for F in ([R, copy[0]] if snap else [R])]
            assert e.taut in full, (label, name, e, stretch(team, R, e))


def test_batch_merges_like_single_results():
    """The batch reports the same states as the single calls, formation by formation."""
    team, R0 = digits_team(6)
    _, R1 = noisy_team(6, 1e-3, 3)
    b = ts.forward_kinematics_batch(team, np.stack([R0, R1, R0]))
    for k, R in enumerate([R0, R1, R0]):
        one = ts.forward_kinematics(team, R)
        assert int(b.count[k]) == len(one.equilibria)
        np.testing.assert_allclose(b.object[k, :b.count[k]],
                                   [e.object for e in one.equilibria], atol=1e-12)


def test_lowest_by_direct_minimisation_says_so():
    """A regular 16-gon at 0.9x written to 6 decimals: the enumeration reports only a
    not-an-equilibrium state at the centre; the direct minimisation supplies the stable
    state hanging there and the message says so."""
    team, R = digits_team(16)
    res = ts.forward_kinematics(team, R)
    assert res.success and res.status == "ok"
    assert res.direct and "direct minimisation" in res.message
    # In exact rational arithmetic (fk_exact) the lowest rest point is the centre, with
    # every other cable at full length (the 6-digit data keep that 8-fold symmetry) and
    # the rest slack by ~1e-6: the taut set is those 8. Weights 1/8 on each balance the
    # object there and their gradients span R^4, so it is a strict (sharp) minimum; float64
    # places it within 1.2e-6 of the sheet size (one state: MERGE_RTOL).
    low = res.lowest
    assert low.taut == tuple(range(1, 16, 2))
    exact = exact_states(team.sheet.vertices, R, team.hold_height, cables=low.taut)
    assert [float(c) for c in exact[0].x] == [0.0, 0.0, 0.0, 0.0]
    assert all(exact[0].slack[i] == 0 for i in low.taut)
    assert min(exact[0].slack[i] for i in range(0, 16, 2)) > 0
    assert sharp_minimum(team.sheet.vertices, R, exact[0], {i: Fraction(1, 8) for i in low.taut})
    assert np.abs(exact[0].object(team.hold_height) - low.object).max() < MERGE_RTOL


def test_a_flat_lowest_state_is_reported_as_not_strict():
    """A square sheet squeezed along y only (robots at (+-1, +-(1 - c))): every cable's
    condition |r_o - r_i|^2 + d^2 <= |v_o - v_i|^2 has the same x-terms on both sides when
    the object and the contact point move together along x, so the depth does not depend
    on that shift: the lowest states form a segment (d^2 = 1 - (1 - c)^2, all four cables
    taut), a minimum that is not strict. The enumeration finds no isolated state; the
    direct minimisation reports it, kind "saddle", status "not_strict" (not dropped)."""
    V = np.array([[1, 1], [-1, 1], [-1, -1], [1, -1]], float)
    for c, th in ((0.2, 0.0), (0.5, 0.7)):
        Q = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
        R = np.array([[1, 1 - c], [-1, 1 - c], [-1, -1 + c], [1, -1 + c]]) @ Q.T + [3.0, -2.0]
        team = SheetTeam(Sheet(V), 3.0)
        for method in ("fast", "subsets", "exhaustive"):
            res = ts.forward_kinematics(team, R, method=method)
            low = res.lowest
            assert res.status == "not_strict" and not res.success and res.direct, method
            assert low.kind == "saddle" and low.taut == (0, 1, 2, 3), method
            assert "not strict" in res.message
            assert low.height == pytest.approx(3.0 - np.sqrt(2 * c - c * c), abs=1e-12)
            np.testing.assert_allclose(low.weights.sum(), 1.0, atol=1e-12)
            # The flatness itself: the same depth after sliding along the trough.
            d2 = [np.min(np.sum((low.contact + s * np.array([1.0, 0]) - V) ** 2, axis=1)
                         - np.sum((low.object[:2] + s * Q[:, 0] - R) ** 2, axis=1))
                  for s in (0.0, 0.3, -0.4)]
            np.testing.assert_allclose(d2, (3.0 - low.height) ** 2, atol=1e-12)
        b = ts.forward_kinematics_batch(team, R[None])
        assert b.status.tolist() == ["not_strict"] and b.count.tolist() == [1]


def test_an_object_that_slides_off_the_sheet_has_no_rest_state():
    """A copy of an obtuse triangle (circumcentre outside it) at 0.8x, far above the
    floor: no rest state exists (the independent constrained minimisation ends with the
    contact point on the sheet's edge); the result says so in one line, lowest is None."""
    V = np.array([[0, 0], [4, 0], [2, 0.6]], float)
    team = SheetTeam(Sheet(V), 10.0)
    _, rest = brute_lowest(V, 0.8 * V, 10.0)
    assert not rest
    for method in ("fast", "exhaustive"):
        res = ts.forward_kinematics(team, 0.8 * V, method=method)
        assert res.lowest is None and res.status == "infeasible" and not res.success
        assert not res.direct and res.equilibria == ()
        assert res.message.endswith("the object slides off the sheet (descending its "
                                    "height carries the contact point over the sheet's "
                                    "edge: no rest state)")


def test_clear_cases_are_unchanged():
    """Away from a similar copy nothing is merged or added (the square's one state)."""
    team = SheetTeam(Sheet([[0, 0], [1, 0], [1, 1], [0, 1]]), 1.0)
    res = ts.forward_kinematics(team, [[0, 0], [0.9, 0], [0.9, 0.9], [0, 0.9]])
    assert not res.direct and res.message == "1 solution(s), 1 stable"
    low = ts.forward_kinematics(SheetTeam(team.sheet, 0.2),
                                [[0, 0], [0.9, 0], [0.9, 0.9], [0, 0.9]])
    assert low.lowest is None and low.status == "infeasible"     # it would hang below the floor


@pytest.mark.parametrize("backend", BACKENDS)
def test_mass_limit_on_every_path(backend):
    """Issue 25: forward_kinematics(..., mass=1e308) returned tensions [inf, inf, inf] on
    the compiled path; the limit lives in the team, which every path takes."""
    with pytest.raises(InvalidInputError, match="mass"):
        SheetTeam(Sheet([[0, 0], [1, 0], [0, 1]]), 1.0, mass=1e308)
    team = SheetTeam(Sheet([[0, 0], [1, 0], [0, 1]]), 1.0, mass=1e6)
    res = FKSolver(team, backend=backend).solve([[0, 0], [0.9, 0], [0, 0.9]])
    assert all(np.all(np.isfinite(e.tensions)) for e in res.stable)


def test_no_unreachable_error_class():
    """IK answers an unreachable target with a result (status "unreachable"), never an
    exception: the class the README once named does not exist."""
    import taut.errors as errors
    assert not hasattr(errors, "UnreachableTargetError")


def _trough(c: float):
    """The squeezed square of the flat-minimum test (not strict, no similar copy)."""
    return np.array([[1, 1 - c], [-1, 1 - c], [-1, -1 + c], [1, -1 + c]], float)


@pytest.mark.parametrize("backend", BACKENDS)
def test_batch_runs_the_direct_minimisation_only_for_what_is_read(backend, monkeypatch):
    """The batch, like the single result, minimises the height directly (formations
    without a stable state) only when a field that depends on it is read; the values do
    not depend on the order the fields are read in, and ``result(b)`` reuses the batch's."""
    import taut.sheet.fk.results as fr
    calls = []

    def counted(*args, **kwargs):
        calls.append(1)
        return fr.lowest_by_descent.__wrapped__(*args, **kwargs)
    counted.__wrapped__ = fr.lowest_by_descent
    monkeypatch.setattr(fr, "lowest_by_descent", counted)
    V = np.array([[1, 1], [-1, 1], [-1, -1], [1, -1]], float)
    solver = FKSolver(SheetTeam(Sheet(V), 3.0, mass=2.0), backend=backend)
    forms = np.stack([_trough(0.2), 0.8 * V, _trough(0.5), 3.0 * V])
    lazy, eager = solver.solve_batch(forms), solver.solve_batch(forms)
    assert len(lazy) == 4 and lazy.feasible.tolist() == [True, True, True, False]
    assert lazy.success.tolist() == [False, True, False, False]
    assert lazy.message.startswith("1 of 4 formation(s) hold") and not calls
    assert lazy.result(1).success and not lazy.result(0).success and not calls
    kind = eager.kind                                      # every missing row, once
    assert len(calls) == 2 and eager.result(0).direct and len(calls) == 2
    assert eager.status.tolist() == ["not_strict", "ok", "not_strict", "infeasible"]
    assert lazy.status.tolist() == eager.status.tolist() and len(calls) == 4
    for name in ("count", "valid", "taut", "object", "contact", "weights", "tensions"):
        np.testing.assert_array_equal(getattr(lazy, name), getattr(eager, name), name)
    np.testing.assert_array_equal(lazy.kind, kind)
    assert len(calls) == 4 and "status=<(4,) str>" in repr(lazy)
    low = lazy.result(2).lowest                            # the batch's state, not re-solved
    assert low.kind == "saddle" and len(calls) == 4
    np.testing.assert_array_equal(low.object, lazy.object[2, 0])
    np.testing.assert_array_equal(low.tensions, lazy.tensions[2, 0, :4])
    with pytest.raises(AttributeError, match="frozen"):
        lazy.count = None


def test_batch_next_to_a_copy_answers_success_from_the_direct_minimisation():
    """Next to a similar copy the direct minimisation can supply a stable state (the
    16-gon written to 6 decimals), so ``success`` runs it there, as the single call."""
    team, R = digits_team(16)
    b = ts.forward_kinematics_batch(team, np.stack([R, R]))
    one = ts.forward_kinematics(team, R)
    assert b.success.tolist() == [True, True] and b.status.tolist() == ["ok", "ok"]
    assert b.result(1).direct and one.direct
    assert int(b.count[0]) == len(one.equilibria)
    np.testing.assert_allclose(b.object[0, :b.count[0]],
                               [e.object for e in one.equilibria], atol=1e-12)
