"""The sheet-team model: the sheet, the robots' common holding height and the object's
mass, validated once and shared by every analysis (forward and inverse kinematics,
simulation, planning, physics)."""

from __future__ import annotations

from dataclasses import dataclass

from numpy.typing import ArrayLike

from .._validate import as_mass, require_instance
from ..errors import InvalidInputError
from .model import Sheet, check_hold_height

__all__ = ["SheetTeam"]


def as_sheet(sheet: Sheet | ArrayLike, field: str = "sheet") -> Sheet:
    """``sheet`` if it is a :class:`Sheet`, else a :class:`Sheet` of the (N, 2) vertex
    array it holds.

    Raises
    ------
    InvalidSheetError
        The vertices do not form a valid sheet.
    InvalidInputError
        ``sheet`` is neither a :class:`Sheet` nor an array of vertices.
    """
    if isinstance(sheet, Sheet):
        return sheet
    try:
        return Sheet(sheet)  # type: ignore[arg-type]
    except TypeError:
        raise InvalidInputError(field, "must be a taut.sheet.Sheet or an (N, 2) array"
                                ) from None


@dataclass(frozen=True, eq=False)
class SheetTeam:
    """A team of robots holding a deformable sheet that carries an object (the VVCM model
    of the FK paper, Sec. II): the model every sheet analysis takes.

    Robot ``i`` holds sheet vertex ``i``; all robots hold the sheet at the same height.
    Validated once, here; immutable afterwards.

    Parameters
    ----------
    sheet : Sheet or array_like, shape (N, 2)
        The sheet (an (N, 2) vertex array is turned into a :class:`Sheet`). Any length
        unit; it is the unit of the hold height and of every formation.
    hold_height : float
        Height :math:`z_r` of all holding points above the ground, same length unit as the
        sheet (> 0, at most :data:`taut._validate.MAX_SHEET_LENGTH`).
    mass : float, optional
        Object mass, kg (> 0, at most :data:`taut._validate.MAX_MASS_KG`). Only tensions
        (N, with g = 9.81 m/s^2) need it; without it they are not reported.

    Attributes
    ----------
    n : int
        Number of robots (= sheet vertices).

    Raises
    ------
    InvalidSheetError
        The vertices do not form a valid sheet.
    InvalidInputError
        A non-positive, non-finite or out-of-range hold height or mass; a sheet that is
        neither a :class:`Sheet` nor a vertex array.

    Examples
    --------
    >>> import taut.sheet as ts
    >>> team = ts.SheetTeam(ts.Sheet([[0, 0], [1, 0], [1, 1], [0, 1]]), 1.0, mass=2.0)
    >>> team.n, team.hold_height, team.mass
    (4, 1.0, 2.0)
    >>> res = ts.forward_kinematics(team, [[0, 0], [0.9, 0], [0.9, 0.9], [0, 0.9]])
    >>> res.lowest.taut
    (0, 1, 2, 3)
    >>> ts.SheetTeam(team.sheet, -1.0)
    Traceback (most recent call last):
    ...
    taut.errors.InvalidInputError: hold_height: must be positive, got -1
    """

    sheet: Sheet
    hold_height: float
    mass: float | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "sheet", as_sheet(self.sheet))
        object.__setattr__(self, "hold_height", check_hold_height(self.hold_height))
        if self.mass is not None:
            object.__setattr__(self, "mass", as_mass(self.mass, "mass"))

    @property
    def n(self) -> int:
        """Number of robots (= sheet vertices)."""
        return self.sheet.n

    def __repr__(self) -> str:
        mass = "" if self.mass is None else f", mass={self.mass:g}"
        return f"SheetTeam({self.sheet!r}, hold_height={self.hold_height:g}{mass})"


def require_team(team: object, field: str = "team") -> SheetTeam:
    """``team`` if it is a :class:`SheetTeam` (validated when it was made), else an
    :class:`InvalidInputError` naming the expected type."""
    return require_instance(team, SheetTeam, field)
