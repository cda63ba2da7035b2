"""Issue 24: the sheet model's size is counted before it is built, and a model of more than
``MAX_SHEET_TENDONS`` tendons is refused at the library entry (naming ``mesh`` or
``sheet``), before any mesh, model or forward kinematics."""

import pytest

from taut.errors import InvalidInputError
from taut.physics import _tol
from taut.physics._mesh import sheet_mesh, sheet_model_size
from taut.sheet import Sheet, SheetTeam


# (5, 24) (~1.7-1.9 s of CPU each) in the slow target; (8, 16) keeps a fine mesh and
# (40, 10), (120, 6) many robots in the fast suite.
@pytest.mark.parametrize("n, divisions", [(3, 10), (8, 16), (40, 10),
                                          pytest.param(5, 24, marks=pytest.mark.slow),
                                          (120, 6)])
@pytest.mark.parametrize("corner_tendons", [False, True])
def test_counts_bound_the_built_model(n, divisions, corner_tendons):
    pytest.importorskip("mujoco")
    from taut.physics._sheet_model import build_sheet_sim
    V = Sheet.regular(n, 700.0).vertices
    nodes, tendons = sheet_model_size(V, divisions, corner_tendons=corner_tendons)
    for contact in (None, 0.3 * V[0] + 0.2 * V[1]):
        m = sheet_mesh(V, divisions, contact=contact)
        sim = build_sheet_sim(m, V, 0.8 * V, 700.0, ball_radius=10.0, ball_start=None,
                              tie=False, corner_tendons=corner_tendons)
        assert len(m.nodes) <= nodes
        assert sim.model.ntendon == len(sim.tendon_pairs)
        # An upper bound, and not a loose one (redundant collinear pairs are the gap).
        assert 0.6 * tendons <= sim.model.ntendon <= tendons


def _team(n):
    sheet = Sheet.regular(n, 1000.0)
    return SheetTeam(sheet, 1000.0), 0.8 * sheet.vertices


def test_many_robots_refused_naming_the_sheet():
    # 1,000 robots (the most taut takes): the corner tendons alone are over the limit at
    # any mesh; was > 3 GB of memory.
    pytest.importorskip("mujoco")
    from taut.physics import replay_equilibria, settle
    team, formation = _team(1000)
    with pytest.raises(InvalidInputError) as err:
        replay_equilibria(team, formation)
    assert err.value.field == "sheet"
    msg = str(err.value)
    assert "1000 robots" in msg and f"more than the {_tol.MAX_SHEET_TENDONS}" in msg
    # The drop (no corner tendons) is checked too: 1,000 boundary nodes all within reach.
    with pytest.raises(InvalidInputError, match="^sheet: 1000 robots: .* at mesh 4, "):
        settle(team, formation, mesh=4)


def test_fine_mesh_refused_naming_a_mesh_that_fits():
    pytest.importorskip("mujoco")
    from taut.physics import replay_equilibria
    team, formation = _team(64)
    V = team.sheet.vertices
    assert sheet_model_size(V, 60, corner_tendons=True)[1] > _tol.MAX_SHEET_TENDONS
    with pytest.raises(InvalidInputError) as err:
        replay_equilibria(team, formation, mesh=60)
    assert err.value.field == "mesh"
    fits = int(str(err.value).rsplit("mesh ", 1)[1].split()[0])
    assert 4 <= fits < 60
    assert sheet_model_size(V, fits, corner_tendons=True)[1] <= _tol.MAX_SHEET_TENDONS
    for finer in range(fits + 1, 61):                 # the finest coarser mesh that fits
        assert sheet_model_size(V, finer, corner_tendons=True)[1] > _tol.MAX_SHEET_TENDONS


def test_a_coarser_mesh_is_searched_past_a_larger_one():
    # 320 robots: mesh 10 is over the limit and so is mesh 4 (every boundary node within
    # reach of every other), but a mesh between fits: the count is not monotonic in the
    # mesh, and the finest one that fits is named.
    pytest.importorskip("mujoco")
    from taut.physics import replay_equilibria
    team, formation = _team(320)
    V, limit = team.sheet.vertices, _tol.MAX_SHEET_TENDONS
    sizes = {d: sheet_model_size(V, d, corner_tendons=True)[1] for d in range(4, 11)}
    fits = max(d for d, t in sizes.items() if t <= limit)
    assert sizes[10] > limit and sizes[4] > limit and 4 < fits < 10
    with pytest.raises(InvalidInputError, match=f"^mesh: .* at mesh 10, .*; mesh {fits} fits$"):
        replay_equilibria(team, formation, mesh=10)
