"""Monitors of a simulated run (batched over its time steps): cable tensions against
``[t_min, t_max]`` (FASTKIT eq. 20), tipping moments of every mobile base about every
support-polygon edge from the *actual* tensions and cable directions (eqs. 21-23), motor
torque and speed saturation. Violations become :class:`ControlEvent` episodes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..kinematics._bases import moved_edges
from ..model.robot import CableRobot

__all__ = ["ControlEvent"]


@dataclass(frozen=True)
class ControlEvent:
    """One episode of a violated limit.

    Attributes
    ----------
    kind : str
        ``"slack"`` (tension below t_min), ``"over_tension"`` (above t_max), ``"tipping"``
        (an edge moment > 0), ``"torque_saturation"`` (at the peak torque),
        ``"above_rated"`` (above the rated torque for longer than the model's
        ``peak_duration``), ``"speed_saturation"``.
    index : int
        Cable index (tensions, motors) or edge index (tipping).
    name : str
        Cable name, or ``"<base> edge <j>"``.
    start, end : float
        First and last violating sample, s.
    worst : float
        Extreme value during the episode (N, N m, rad/s).
    limit : float
        The limit violated (same unit).
    """

    kind: str
    index: int
    name: str
    start: float
    end: float
    worst: float
    limit: float

    def describe(self) -> str:
        """One line, e.g. ``slack C21 1.234-1.301 s (worst 0.00 N, limit 5.00 N)``."""
        return (f"{self.kind} {self.name} {self.start:.3f}-{self.end:.3f} s "
                f"(worst {self.worst:.3f}, limit {self.limit:.3f})")


def tipping_margins(robot: CableRobot, exits: np.ndarray, unit: np.ndarray,
                    tensions: np.ndarray, base_poses: np.ndarray) -> np.ndarray:
    """Tipping margins ``-m_Cj`` (T, E), N m (>= 0: the base does not tip), of FASTKIT eqs.
    21-23 for actual exit points (T, m, 3), cable unit vectors (T, m, 3) (attachment to exit)
    and tensions (T, m), with the bases at ``base_poses`` (T, K, 3).

    The force of cable i on its base is ``-t_i u_i`` at ``b_i``, so the moment about edge j
    is ``u_Cj . ((c_j - b_i) x t_i u_i)`` summed over the base's cables, plus the weight term.
    """
    if robot.n_edges == 0:
        return np.zeros((tensions.shape[0], 0))
    same = (robot.edge_base[:, None] == robot.cable_base[None, :]).astype(float)   # (E, m)
    static = bool(np.all(base_poses == base_poses[:1]) and np.all(exits == exits[:1]))
    if static:                       # u_Cj . ((c_j - b_i) x u_i) = u_i . (u_Cj x (c_j - b_i))
        pts, dirs, m0 = moved_edges(robot, base_poses[:1])
        V = np.cross(dirs[0][:, None, :], pts[0][:, None, :] - exits[0][None, :, :])
        coef = np.einsum("emk,tmk->tem", V * same[:, :, None], unit)
    else:
        pts, dirs, m0 = moved_edges(robot, base_poses)                     # (T, E, 3)
        lever = pts[:, :, None, :] - exits[:, None, :, :]                  # (T, E, m, 3)
        d = dirs[:, :, None, :]
        V0 = d[..., 1] * lever[..., 2] - d[..., 2] * lever[..., 1]
        V1 = d[..., 2] * lever[..., 0] - d[..., 0] * lever[..., 2]
        V2 = d[..., 0] * lever[..., 1] - d[..., 1] * lever[..., 0]
        coef = (V0 * unit[:, None, :, 0] + V1 * unit[:, None, :, 1]
                + V2 * unit[:, None, :, 2]) * same[None]
    return -(np.einsum("tem,tm->te", coef, tensions) + m0[:1] if static else
             np.einsum("tem,tm->te", coef, tensions) + m0)


def episodes(times: np.ndarray, values: np.ndarray, bad: np.ndarray, kind: str,
             names: list[str], limit: np.ndarray, worst: str) -> list[ControlEvent]:
    """Episodes of consecutive ``bad`` samples per column of ``values`` (T, c); ``worst`` is
    ``"min"`` or ``"max"``."""
    out = []
    for j in np.nonzero(bad.any(axis=0))[0]:
        b = bad[:, j].astype(np.int8)
        edges = np.diff(np.r_[0, b, 0])
        for s, e in zip(np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0] - 1):
            seg = values[s:e + 1, j]
            w = float(seg.min() if worst == "min" else seg.max())
            out.append(ControlEvent(kind, int(j), names[j], float(times[s]), float(times[e]),
                                    w, float(limit[j])))
    return out
