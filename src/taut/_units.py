"""Physical constants shared by every family of taut (SI units)."""

from __future__ import annotations

__all__ = ["GRAVITY"]

#: Gravitational acceleration, m/s^2: the value of the FK paper and of the cable-robot
#: models (9.81, not the standard 9.80665), used for every weight and simulated gravity.
GRAVITY = 9.81
