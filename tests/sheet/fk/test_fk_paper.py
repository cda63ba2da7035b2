"""Forward kinematics against the FK paper's examples and the authors' own code."""

import numpy as np
import pytest

from taut.sheet import GRAVITY, Sheet, forward_kinematics
from taut.sheet import SheetTeam

# Table III of the FK paper (Example 2, r2 and r4 at +-353 mm): taut set (1-based),
# v_o (mm), p_o (mm).
TABLE_III = [
    ((4, 5, 8), (-12.7, -13.0), (-8.6, -30.5, 261.8)),
    ((1, 5, 7, 8), (-14.8, -193.2), (-26.6, -347.8, 310.2)),
    ((3, 4, 5, 8), (16.4, -22.2), (43.3, -46.9, 263.2)),
    ((3, 5, 7, 8), (51.4, -165.0), (98.7, -290.9, 300.5)),
    ((4, 5, 6, 8), (-220.7, -76.7), (-389.3, -142.0, 340.6)),
    ((1, 3, 5, 7, 8), (-13.9, -193.3), (-25.0, -348.0, 310.2)),
]


def solve(example, method="fast", mass=None):
    return forward_kinematics(SheetTeam(Sheet(example["Vn_mm"]), example["zr_mm"], mass=mass),
                              np.array(example["Rn_mm"]), method=method)


def as_table(result):
    return {tuple(i + 1 for i in e.taut): e for e in result.equilibria}


@pytest.mark.parametrize("name", [
    "example1", "example2_as_printed", "example2_r2_r4_at_353mm", "example3_zr1000",
    "example4_r1_at_52_13cm_zr1000", "example5_zr1000", "example6a", "example6b", "example6c"])
def test_fast_matches_reference_code(reference, name):
    """Same taut sets and positions as the authors' code (printed to 0.01 mm)."""
    ex = reference[name]
    got = as_table(solve(ex))
    want = {tuple(s["taut"]): s for s in ex["solutions"]}
    assert set(got) == set(want)
    for taut, s in want.items():
        np.testing.assert_allclose(got[taut].object, s["po"], atol=0.0051)
        np.testing.assert_allclose(got[taut].contact, s["vo"], atol=0.0051)


@pytest.mark.parametrize("name", [
    "example1", "example2_as_printed", "example2_r2_r4_at_353mm",
    "example4_r1_at_52_13cm_zr1000", "example6a", "example6b", "example6c"])
def test_exhaustive_funnel_matches_reference_code(reference, name):
    ex = reference[name]
    r = solve(ex, method="exhaustive")
    f = ex["funnel"]
    assert (r.funnel.combinations, r.funnel.form_closure, r.funnel.cqp_feasible,
            r.funnel.height_feasible, r.funnel.force_closure) == (
        f["combinations_tried"], f["form_closure_rank_pass"], f["cqp_slack_check_pass"],
        f["cqp_slack_and_z_in_0_zr_pass"], f["force_closure_pass_final"])


def test_example3_funnel_up_to_one_borderline_set(reference):
    """Example 3 differs from the reference code by one set in step 3 only: a slack
    test decided within rounding (our tolerance is relative to the sheet size)."""
    ex = reference["example3_zr1000"]
    r = solve(ex, method="exhaustive")
    assert (r.funnel.combinations, r.funnel.form_closure) == (968, 582)
    assert abs(r.funnel.cqp_feasible - ex["funnel"]["cqp_slack_check_pass"]) <= 1
    assert r.funnel.height_feasible == ex["funnel"]["cqp_slack_and_z_in_0_zr_pass"]
    assert r.funnel.force_closure == 8


def test_example1_kinds(reference):
    """Three paper solutions; {1,2,3,4} passes the paper's test but is no equilibrium."""
    r = solve(reference["example1"])
    kinds = {t: e.kind for t, e in as_table(r).items()}
    assert kinds == {(1, 2, 3): "stable", (1, 3, 4): "stable",
                      (1, 2, 3, 4): "not_equilibrium"}
    w = as_table(r)[(1, 2, 3, 4)].weights
    np.testing.assert_allclose(w, [1.03, -0.48, 0.95, -0.51], atol=0.01)   # docs/sheet_kinematics.md §3


def test_example1_not_equilibrium_state_can_descend(reference):
    """Moving (r_o, v_o) by 1 mm from the {1,2,3,4} state lowers the object."""
    ex = reference["example1"]
    r = solve(ex)
    e = as_table(r)[(1, 2, 3, 4)]
    R, V, zr = np.array(ex["Rn_mm"]), np.array(ex["Vn_mm"]), ex["zr_mm"]

    def depth(x):
        F = np.max(np.sum((x[:2] - R) ** 2, 1) - np.sum((x[2:] - V) ** 2, 1))
        return np.sqrt(-F)

    x0 = np.concatenate([e.object[:2], e.contact])
    assert depth(x0) == pytest.approx(zr - e.object[2], abs=1e-6)
    rng = np.random.default_rng(0)
    dirs = rng.normal(size=(2000, 4))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    assert max(depth(x0 + d) for d in dirs) > depth(x0) + 1e-3
    # ... whereas the stable states are local minima of the height.
    s = as_table(r)[(1, 2, 3)]
    xs = np.concatenate([s.object[:2], s.contact])
    assert max(depth(xs + d) for d in dirs) < depth(xs)


def test_example2_table_iii(reference):
    r = solve(reference["example2_r2_r4_at_353mm"], method="exhaustive")
    got = as_table(r)
    assert set(got) == {row[0] for row in TABLE_III}
    for taut, vo, po in TABLE_III:
        np.testing.assert_allclose(got[taut].contact, vo, atol=0.1)
        np.testing.assert_allclose(got[taut].object, po, atol=0.1)
    assert [t for t, e in got.items() if e.stable] == [(4, 5, 8)]
    assert (r.funnel.combinations, r.funnel.form_closure, r.funnel.cqp_feasible,
            r.funnel.force_closure) == (219, 182, 22, 6)             # Table II


@pytest.mark.parametrize("name,taut", [("example6a", tuple(range(1, 9))),
                                       ("example6b", (2, 3, 4, 5, 6, 7, 8)),
                                       ("example6c", (2, 3, 4, 6, 7, 8))])
def test_table_v(reference, name, taut):
    for method in ("fast", "exhaustive", "subsets"):
        r = solve(reference[name], method=method)
        assert len(r.equilibria) == 1
        e = r.equilibria[0]
        assert tuple(i + 1 for i in e.taut) == taut
        np.testing.assert_allclose(e.object, [0, 0, 1000 - np.sqrt(900**2 - 500**2)], atol=1e-6)
        np.testing.assert_allclose(e.contact, [0, 0], atol=1e-6)
        assert e.kind == "stable"
        np.testing.assert_allclose(e.weights.sum(), 1.0)
        assert np.all(e.weights >= 0)


@pytest.mark.parametrize("n", [3, 4, 5, 6, 9, 12, 20, 40])
def test_lemma2_regular_polygons(n):
    """Lemma 2: regular sheet and formation -> one all-taut solution at the centre."""
    rs, rf, zr = 0.9, 0.5, 1.0
    sheet = Sheet.regular(n, rs, phase=0.3)
    t = 0.3 + 2 * np.pi * np.arange(n) / n
    formation = rf * np.column_stack([np.cos(t), np.sin(t)])
    r = forward_kinematics(SheetTeam(sheet, zr, mass=2.0), formation)
    assert len(r.equilibria) == 1
    e = r.equilibria[0]
    assert e.taut == tuple(range(n))
    np.testing.assert_allclose(e.object, [0, 0, zr - np.sqrt(rs**2 - rf**2)], atol=1e-12)
    assert e.stable
    # Symmetric load sharing (minimum-norm weights) and tensions m g L / (n d).
    np.testing.assert_allclose(e.weights, 1.0 / n, atol=1e-9)
    d = np.sqrt(rs**2 - rf**2)
    np.testing.assert_allclose(e.tensions, 2.0 * GRAVITY * rs / (n * d), rtol=1e-9)


@pytest.mark.parametrize("name", ["example1", "example2_r2_r4_at_353mm", "example5_zr1000"])
def test_tensions_balance_the_weight(reference, name):
    """Sum of cable forces equals the object's weight for every equilibrium (FK eq. 16),
    and taut cables are exactly as long as their virtual cable, slack ones shorter."""
    ex = reference[name]
    R, V, zr = np.array(ex["Rn_mm"]), np.array(ex["Vn_mm"]), ex["zr_mm"]
    r = solve(ex, mass=3.0)
    for e in r.equilibria:
        p = np.column_stack([R, np.full(len(R), zr)])
        span = np.linalg.norm(p - e.object, axis=1)
        cable = np.linalg.norm(V - e.contact, axis=1)
        taut = np.array(e.taut)
        np.testing.assert_allclose(span[taut], cable[taut], rtol=1e-9)
        slack = np.setdiff1d(np.arange(len(R)), taut)
        assert np.all(span[slack] < cable[slack])
        np.testing.assert_allclose(e.cable_lengths, cable[taut], rtol=1e-12)
        if e.kind == "not_equilibrium":
            continue
        unit = (p[taut] - e.object) / span[taut, None]
        force = (e.tensions[:, None] * unit).sum(axis=0)
        np.testing.assert_allclose(force, [0, 0, 3.0 * GRAVITY], atol=1e-9 * 3.0 * GRAVITY)
        assert np.all(e.tensions >= -1e-9)
