"""Predicted work of the exact wrench and twist sets (private): the candidate facets each
enumeration will build, and the numbers it holds for them, in closed form, checked against
:data:`taut._validate.MAX_SET_NUMBERS` before any array is allocated.

Both sets enumerate subsets (:mod:`taut.cdpr.sets.wrench`: ``(r + 1)``-subsets of the
``K`` tension constraints; :mod:`taut.cdpr.sets.zonotope`: ``(m - 1)``-subsets of the
zonotope generators), so their memory and time grow as binomial coefficients of the cable
count: a model a few cables larger than a real robot would need tens of gigabytes. Memory
is proportional to the candidates times the numbers each one holds (its subset matrix and
its row), so that product is what the budget bounds.

A batch of poses is bounded by the same count: the sets returned at once (each candidate
facet a row of ``n`` numbers and its offset, for every pose) hold at most
:data:`MAX_SET_NUMBERS` numbers (:func:`check_batch_sets`), and the functions that reduce
each set to a few numbers (axis capacities, margins) build the sets
:func:`batch_block` poses at a time, so any batch is accepted and only one block's sets are
alive at once.
"""

from __future__ import annotations

from math import comb

from ..._validate import MAX_SET_NUMBERS
from ...errors import InvalidInputError
from ..model.robot import CableRobot

__all__: list[str] = []


def wrench_work(robot: CableRobot, tipping: bool, sliding: bool) -> tuple[int, int]:
    """(candidate facets, numbers) per pose of the AWS certificates
    (:func:`taut.cdpr.statics._farkas.certificates`): ``K`` single rows, ``C(K, 2)`` pairs
    and ``C(K, r + 1)`` subsets in general position (``r = m - n >= 2``, each an
    ``(r + 1) x r`` matrix), with ``K = 2 m`` tension bounds plus the tipping edges and
    friction faces that are included; every candidate also gets a row of ``n`` numbers."""
    K = 2 * robot.m
    if tipping and robot.has_tipping:
        K += robot.n_edges
    if sliding and robot.has_sliding:
        K += sum(b.friction_sides for b in robot.bases if b.mobile and b.friction is not None)
    r, n = robot.m - robot.dof, robot.dof
    small = K + (comb(K, 2) if r >= 1 else 0)
    general = comb(K, r + 1) if r >= 2 else 0
    return small + general, small * (2 * max(r, 1) + n) + general * ((r + 1) * r + n)


def twist_work(m: int, n_base: int, n_cable: int) -> tuple[int, int]:
    """(candidate facets, numbers) per pose of the task-mode twist set of ``m`` cables with
    ``n_base`` base and ``n_cable`` cable generators (joints whose rate range is not a
    point). Every cable moving (:func:`taut.cdpr.sets.zonotope._facets_base_and_identity`):
    ``2 C(m, j + 1) C(n_base, j)`` facets for each ``j`` base columns, each a row of ``m``
    plus a ``(j + 1) x (j + 1)`` factor. Otherwise
    (:func:`taut.cdpr.sets.zonotope.zonotope_hrep`) ``2 C(n_base + n_cable, m - 1)``, each
    an ``m x (m - 1)`` subset and its complete QR factors (about ``3 m^2`` numbers)."""
    if n_cable < m:
        c = comb(n_base + n_cable, m - 1)
        return 2 * c, c * (3 * m * m + 2 * m)
    facets = numbers = 0
    for j in range(min(n_base, m - 1) + 1):
        c = comb(m, j + 1) * comb(n_base, j)
        facets += 2 * c
        numbers += c * (2 * m + (j + 1) ** 2)
    return facets, numbers


def check_set_work(work: tuple[int, int], robot: CableRobot, what: str,
                   detail: str = "") -> None:
    """Raise :class:`InvalidInputError` (field ``cables``) when the predicted ``work``
    (candidate facets, numbers) per pose exceeds :data:`MAX_SET_NUMBERS`; ``what`` names
    the set, ``detail`` the inputs besides the cable count that the count depends on."""
    facets, numbers = work
    if numbers > MAX_SET_NUMBERS:
        extra = f" and {detail}" if detail else ""
        raise InvalidInputError(
            "cables", f"{robot.m} cables{extra} give {facets:,} candidate facets of the "
                      f"{robot.dof}-DoF {what} per pose ({numbers:,} numbers); at most "
                      f"{MAX_SET_NUMBERS:,} numbers")


def block_size(work: tuple[int, int], block: int) -> int:
    """Poses per vectorised block (at most ``block``) so that one block holds at most
    :data:`MAX_SET_NUMBERS` numbers."""
    return max(1, min(block, MAX_SET_NUMBERS // max(work[1], 1)))


def batch_block(facets: int, dim: int, block: int = 256) -> int:
    """Poses per block (at most ``block``) whose sets of ``facets`` facets in ``dim``
    dimensions (a row and an offset each) hold at most :data:`MAX_SET_NUMBERS` numbers."""
    return block_size((facets, facets * (dim + 1)), block)


def check_batch_sets(facets: int, dim: int, poses: int, what: str) -> None:
    """Raise :class:`InvalidInputError` (field ``poses``) when the sets of ``poses`` poses,
    ``facets`` facets each in ``dim`` dimensions, returned at once would hold more than
    :data:`MAX_SET_NUMBERS` numbers (more than :func:`batch_block` poses)."""
    most = batch_block(facets, dim, block=poses)
    if poses > most:
        raise InvalidInputError(
            "poses", f"{poses:,} poses of the {what} ({facets:,} candidate facets each) "
                     f"would hold {poses * facets * (dim + 1):,} numbers; at most "
                     f"{MAX_SET_NUMBERS:,} ({most:,} poses here): pass fewer poses (axis "
                     f"capacities and margins take any batch)")
