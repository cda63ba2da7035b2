"""The scenarios the page offers without an upload: the repository's ``examples/`` files
(when the package runs from a source checkout), the shipped cable-robot presets, and
generated regular-polygon teams of any size."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InvalidInputError, ScenarioError
from ..io import read_mapping
from ..io.cdpr_model import PRESETS, preset_path
from ..sheet import Sheet, SheetTeam, inverse_kinematics

__all__ = ["Catalog", "regular_team"]

#: Folders of ``examples/`` holding each view's scenario files.
_FOLDERS = {"sheet": "sheet", "plan": "plan", "cdpr": "cdpr"}


def _default_root() -> Path | None:
    root = Path(__file__).resolve().parents[3] / "examples"
    return root if root.is_dir() else None


class Catalog:
    """Bundled scenarios by view (``"sheet"``, ``"plan"``, ``"cdpr"``).

    Parameters
    ----------
    root : Path, optional
        An ``examples/`` folder; default: the source checkout's, if there is one.
    """

    def __init__(self, root: Path | None = None) -> None:
        self.root = root if root is not None else _default_root()

    def names(self) -> dict[str, list[str]]:
        """``{view: [name, ...]}``; cable-robot presets are listed by preset name."""
        out: dict[str, list[str]] = {k: [] for k in _FOLDERS}
        if self.root is not None:
            for kind, folder in _FOLDERS.items():
                d = self.root / folder
                if d.is_dir():
                    out[kind] = sorted(p.name for p in d.glob("*.yaml"))
        out["cdpr"] = list(PRESETS) + out["cdpr"]
        return out

    def mapping(self, kind: str, name: str) -> dict[str, Any]:
        """The parsed file of a bundled scenario.

        Raises
        ------
        ScenarioError
            ``example``: not one of :meth:`names` for that view.
        """
        listed = self.names().get(kind)
        if listed is None:
            raise InvalidInputError("kind", f"must be one of {', '.join(_FOLDERS)}")
        if name not in listed:
            raise ScenarioError("example", f"no bundled {kind} scenario named {name!r}")
        if kind == "cdpr" and name in PRESETS:
            return read_mapping(preset_path(name))
        assert self.root is not None
        return read_mapping(self.root / _FOLDERS[kind] / name)


def regular_team(n: int, *, radius: float = 1000.0, hold_height: float = 1000.0,
                 seed: int = 0) -> dict[str, Any]:
    """A sheet scenario mapping: a regular ``n``-gon sheet (circumradius ``radius``, mm)
    held at ``hold_height`` by a formation that rests the object in a generic stable
    state (the all-taut inverse-kinematics formation for the object at half the hold
    height, pulled 20 % towards the object, leaving the robots room to be dragged, and
    jittered by 1 % of the sheet size, so no cable set is degenerate).

    Examples
    --------
    >>> m = regular_team(5)
    >>> len(m["sheet"]), len(m["formation"]), m["hold_height"]
    (5, 5, 1000.0)
    """
    if not isinstance(n, int) or isinstance(n, bool) or not 3 <= n <= 64:
        raise InvalidInputError("n", f"must be an integer from 3 to 64, got {n!r}")
    sheet = Sheet.regular(n, radius)
    centre = np.zeros(2) + 0.05 * radius          # off the symmetry centre
    target = (*centre, 0.5 * hold_height)
    ik = inverse_kinematics(SheetTeam(sheet, hold_height), target)
    if not ik.success:                 # regular teams are always reachable there; guard anyway
        raise InvalidInputError("n", f"no formation for a regular {n}-gon team: {ik.message}")
    rng = np.random.default_rng(seed)
    formation = centre + 0.8 * (ik.formation - centre)
    formation = formation + rng.uniform(-0.01, 0.01, formation.shape) * radius
    return {
        "name": f"regular {n}-gon team (generated)", "units": "mm",
        "hold_height": float(hold_height), "mass": 1.0,
        "sheet": np.round(sheet.vertices, 6).tolist(),
        "formation": np.round(formation, 6).tolist(),
    }
