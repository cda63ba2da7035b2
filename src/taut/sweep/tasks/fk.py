"""``fk_stability_map``: rest states of one sheet over transformed formations.

Each point transforms the base scenario's formation about its centroid ``c``:

    r_i' = c + scale * Rot(rotation) * Stretch(stretch, stretch_angle) * (r_i - c) + noise,

where ``Stretch(s, a) = Rot(a) diag(s, 1) Rot(-a)`` stretches along the direction ``a``,
and ``noise`` is seeded normal noise of standard deviation ``jitter`` per robot coordinate
(0 by default). A plain rotation is a symmetry of the model (FK commutes with rigid motions
of the formation), so ``rotation`` alone never changes the counts; the heading that matters
for a non-regular formation is that of the stretch. Formations that the sheet cannot reach
(a robot pair farther apart than its sheet vertices) are reported with ``feasible`` false.
Forward kinematics runs batched over each chunk (one call per hold height).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ...sheet import SheetTeam, forward_kinematics_batch
from ..task import Columns, Task

__all__ = ["FK_STABILITY_MAP", "transform_formations"]

#: Relative slack of the pre-filter of infeasible formations (the solver's own check
#: decides; this only keeps clearly infeasible formations out of the batch).
_FEASIBLE_RTOL = 1e-9


@dataclass(frozen=True, eq=False)
class _Context:
    team: SheetTeam          # the scenario's (its hold height and mass are the defaults)
    formation: np.ndarray
    limits: np.ndarray       # (N, N) sheet distances


def _prepare(spec: Any, sc: Any) -> _Context:
    return _Context(sc.team, np.asarray(sc.formation, float), sc.team.sheet.side_lengths())


def transform_formations(formation: np.ndarray, cols: Columns, seeds: np.ndarray,
                         ) -> np.ndarray:
    """The transformed formations (B, N, 2) of a chunk (see the module docstring)."""
    c = formation.mean(axis=0)
    rel = formation - c
    b = len(seeds)
    a = np.deg2rad(cols["stretch_angle"])
    s = cols["stretch"]
    ca, sa = np.cos(a), np.sin(a)
    # Stretch(s, a) = I + (s - 1) u u^T with u = (cos a, sin a).
    stretch = np.empty((b, 2, 2))
    stretch[:, 0, 0] = 1 + (s - 1) * ca * ca
    stretch[:, 1, 1] = 1 + (s - 1) * sa * sa
    stretch[:, 0, 1] = stretch[:, 1, 0] = (s - 1) * ca * sa
    t = np.deg2rad(cols["rotation"])
    rot = np.empty((b, 2, 2))
    rot[:, 0, 0] = rot[:, 1, 1] = np.cos(t)
    rot[:, 1, 0] = np.sin(t)
    rot[:, 0, 1] = -np.sin(t)
    m = cols["scale"][:, None, None] * rot @ stretch
    out = c + np.einsum("bij,nj->bni", m, rel)
    jitter = cols["jitter"]
    if np.any(jitter > 0):
        for k in np.flatnonzero(jitter > 0):
            rng = np.random.default_rng(int(seeds[k]))
            out[k] += rng.normal(0.0, jitter[k], size=out[k].shape)
    return out


def _feasible(ctx: _Context, forms: np.ndarray) -> np.ndarray:
    d = np.linalg.norm(forms[:, :, None, :] - forms[:, None, :, :], axis=-1)
    slack = _FEASIBLE_RTOL * ctx.team.sheet.size
    return np.all(d <= ctx.limits * (1 + _FEASIBLE_RTOL) + slack, axis=(1, 2))


def _solve_group(ctx: _Context, forms: np.ndarray, hold: float, mass: float | None,
                 out: Columns, rows: np.ndarray) -> None:
    res = forward_kinematics_batch(SheetTeam(ctx.team.sheet, hold, mass), forms)
    out["feasible"][rows] = res.feasible      # a borderline formation the pre-filter let through
    _store_all(res, out, rows)


def _store_all(res: Any, out: Columns, rows: np.ndarray) -> None:
    """Every row of a batch at once: counts, and the lowest stable state of each formation."""
    kind = res.kind                                       # (B, K), -1 padding
    out["n_equilibria"][rows] = np.sum((kind == 0) | (kind == 1), axis=1)
    out["n_stable"][rows] = np.sum(kind == 0, axis=1)
    out["n_saddle"][rows] = np.sum(kind == 1, axis=1)
    out["n_states"][rows] = res.count
    if kind.shape[1] == 0:
        return
    z = np.where(kind == 0, res.object[..., 2], np.inf)
    low = np.argmin(z, axis=1)
    b = np.flatnonzero(np.isfinite(z[np.arange(len(low)), low]))
    if b.size == 0:
        return
    lb = low[b]
    taut = res.taut[b, lb]                                # (b, N) bool
    out["lowest_height"][rows[b]] = res.object[b, lb, 2]
    out["min_share"][rows[b]] = np.min(np.where(taut, res.weights[b, lb], np.inf), axis=1)
    if res.tensions is not None:
        out["max_tension"][rows[b]] = np.max(np.where(taut, res.tensions[b, lb], -np.inf),
                                             axis=1)
    codes = taut @ (1 << np.arange(taut.shape[1], dtype=np.int64))
    uniq, first = np.unique(codes, return_index=True)
    names = {int(c): ",".join(str(i) for i in np.flatnonzero(taut[f]))
             for c, f in zip(uniq, first)}
    out["lowest_taut"][rows[b]] = [names[int(c)] for c in codes]


def _run(ctx: _Context, cols: Columns, seeds: np.ndarray) -> Columns:
    b = len(seeds)
    out: Columns = {
        "feasible": np.ones(b, dtype=bool),
        "n_states": np.zeros(b, dtype=np.int64),
        "n_equilibria": np.zeros(b, dtype=np.int64),
        "n_stable": np.zeros(b, dtype=np.int64),
        "n_saddle": np.zeros(b, dtype=np.int64),
        "lowest_height": np.full(b, np.nan),
        "lowest_taut": np.full(b, "", dtype=object),
        "min_share": np.full(b, np.nan),
        "max_tension": np.full(b, np.nan),
    }
    forms = transform_formations(ctx.formation, cols, seeds)
    ok = _feasible(ctx, forms)
    out["feasible"][:] = ok
    holds, masses = cols["hold_height"], cols["mass"]
    keys = np.stack([holds, masses], axis=1)
    for key in np.unique(keys[ok], axis=0):
        rows = np.flatnonzero(ok & (holds == key[0]) & (masses == key[1]))
        mass = None if key[1] <= 0 else float(key[1])
        _solve_group(ctx, forms[rows], float(key[0]), mass, out, rows)
    return out


def _defaults(ctx: _Context) -> dict[str, float]:
    """Values of parameters that are not swept; hold height and mass are the scenario's."""
    return {"scale": 1.0, "stretch": 1.0, "stretch_angle": 0.0, "rotation": 0.0,
            "jitter": 0.0, "hold_height": ctx.team.hold_height,
            "mass": -1.0 if ctx.team.mass is None else float(ctx.team.mass)}


FK_STABILITY_MAP = Task(
    name="fk_stability_map",
    summary="rest states of a sheet scenario over formation scale, stretch and heading",
    parameters={
        "scale": "factor on the formation about its centroid (1 = as in the scenario)",
        "stretch": "factor along the stretch direction (1 = no stretch)",
        "stretch_angle": "direction of the stretch, degrees",
        "rotation": "rotation of the formation about its centroid, degrees (a symmetry)",
        "jitter": "standard deviation of seeded noise per robot coordinate, length unit",
        "hold_height": "hold height z_r, length unit (default: the scenario's)",
        "mass": "object mass, kg (<= 0: none; default: the scenario's)",
    },
    outputs={
        "feasible": "the sheet can span the formation",
        "n_states": "rest-state candidates passing the paper's checks",
        "n_equilibria": "stable + saddle states",
        "n_stable": "stable states (strict local minima of the object's height)",
        "n_saddle": "equilibria that are not minima",
        "lowest_height": "object height z_o of the lowest stable state, length unit",
        "lowest_taut": "taut cables of the lowest stable state, 0-based, comma separated",
        "min_share": "smallest load share w_i among its taut cables",
        "max_tension": "largest cable tension of the lowest stable state, N (needs mass)",
    },
    defaults=_defaults,
    default_chunk=2048,
    needs_base="sheet scenario",
    prepare=_prepare,
    run=_run,
)

