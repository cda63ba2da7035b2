"""Result objects of sheet forward kinematics: frozen, with named fields.

Both results follow taut's outcome convention (:mod:`taut._outcome`): ``success`` when a
formation holds the object in at least one stable state, ``status`` ``"ok"``,
``"not_strict"`` (single results: the lowest rest state is not a strict minimum) or
``"infeasible"``, and a ``message`` saying what was found or why not. One physical state
is reported once (:mod:`taut.sheet.fk._merge`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable, Literal

import numpy as np
from numpy.typing import ArrayLike

from ..._units import GRAVITY
from ..._validate import as_array
from ...errors import InfeasibleFormationError, InvalidInputError
from .._lifted import KIND_NAMES, KIND_NOT_EQUILIBRIUM, KIND_STABLE
from .._tol import MERGE_RTOL
from ..model import Sheet, check_formation
from ._lowest import (NO_REST, OFF_SHEET, lowest_by_descent, may_find_stable,
    may_find_stable_batch)
from ._merge import coincident_groups, merged_weights
from ._solve import explain_no_equilibrium
from ._sensitivity import Sensitivity, equilibrium_sensitivity
from ..._repr import CompactRepr

__all__ = ["Equilibrium", "Funnel", "FKResult", "BatchFKResult", "EquilibriumKind"]


#: What a rest state found by forward kinematics is (:attr:`Equilibrium.kind`).
EquilibriumKind = Literal["stable", "saddle", "not_equilibrium"]


@dataclass(frozen=True, eq=False)
class Equilibrium:
    """One rest state of the object found by forward kinematics.

    Attributes
    ----------
    taut : tuple of int
        0-based indices of the taut cables :math:`\\mathcal{I}_t` (ascending).
    object : ndarray, shape (3,)
        Object position :math:`\\mathbf{p}_o = (x_o, y_o, z_o)` in the world frame.
    contact : ndarray, shape (2,)
        Contact point :math:`\\mathbf{v}_o` in the sheet frame.
    weights : ndarray, shape (k,)
        Share of the object's weight carried vertically by each taut cable
        (:math:`w_i`, summing to 1, with :math:`\\mathbf{r}_o = \\sum w_i \\mathbf{r}_i` and
        :math:`\\mathbf{v}_o = \\sum w_i \\mathbf{v}_i`). A negative weight means the state is
        not an equilibrium of the model. Where more cables are taut than the state
        determines (e.g. Lemma 2), the minimum-norm non-negative weights are reported.
    tensions : ndarray, shape (k,), or None
        Cable tensions :math:`F_i = w_i m g L_i / d` in newtons when a mass was given and
        the state is an equilibrium (None otherwise: no tensions can hold it there).
    cable_lengths : ndarray, shape (k,)
        Lengths :math:`l_i = |\\mathbf{v}_i - \\mathbf{v}_o|` of the taut cables.
    kind : {"stable", "saddle", "not_equilibrium"}
        ``stable``: strict local minimum of the object's height (all weights positive and
        positive-definite reduced Hessian). ``saddle``: an equilibrium that is not a strict
        minimum. ``not_equilibrium``: passes the paper's force-closure test (projection
        inside the taut robots' polygon) but no non-negative weights exist, so the object
        would move (docs/sheet_kinematics.md §3).
    """

    taut: tuple[int, ...]
    object: np.ndarray
    contact: np.ndarray
    weights: np.ndarray
    tensions: np.ndarray | None
    cable_lengths: np.ndarray
    kind: EquilibriumKind

    @property
    def stable(self) -> bool:
        """True when the state is a strict local minimum of the potential energy."""
        return self.kind == "stable"

    @property
    def is_equilibrium(self) -> bool:
        """True unless the exact force-closure test fails."""
        return self.kind != "not_equilibrium"

    @property
    def height(self) -> float:
        """Object height :math:`z_o`."""
        return float(self.object[2])

    @property
    def jacobian(self) -> np.ndarray:
        """Derivative of the object position with respect to every robot's position,
        shape (3, N, 2): ``jacobian[c, j, a]`` = d (x_o, y_o, z_o)[c] / d (robot j)[a]
        (dimensionless), exact within the taut set (implicit function theorem on the
        stationarity conditions, docs/sheet_sensitivity.md); zero for slack robots, NaN
        where the state's system is singular (more than five taut cables, or dependent
        ones). Computed on first access."""
        return self._sensitivity().object

    @property
    def contact_jacobian(self) -> np.ndarray:
        """d v_o / d (robot j), shape (2, N, 2), dimensionless (as :attr:`jacobian`)."""
        return self._sensitivity().contact

    @property
    def weight_jacobian(self) -> np.ndarray:
        """d w_i / d (robot j), shape (k, N, 2), per length unit (as :attr:`jacobian`;
        rows in the order of :attr:`weights`)."""
        return self._sensitivity().weights

    @property
    def tension_jacobian(self) -> np.ndarray | None:
        """d F_i / d (robot j), shape (k, N, 2), N per length unit of
        :math:`F_i = w_i m g l_i / d`; None without a mass."""
        return self._sensitivity().tensions

    @property
    def taut_margin(self) -> float:
        """Robot motion (length unit: the Frobenius norm of the (N, 2) displacement) to
        the nearest change of taut set predicted by the linearisation: a load share
        reaching 0 or a slack cable becoming taut (0 when a share is not positive; a
        motion with every robot within ``taut_margin / sqrt(N)`` stays inside)."""
        return self._sensitivity().margin

    def _sensitivity(self) -> Sensitivity:
        """The cached :class:`~taut.sheet.fk._sensitivity.Sensitivity` (the formation it
        needs is attached by the :class:`FKResult` that reports this state)."""
        sens = self.__dict__.get("_sens")
        if sens is None:
            ctx = self.__dict__.get("_ctx")
            if ctx is None:
                raise InvalidInputError("equilibrium", "has no formation attached: "
                                        "sensitivities exist for states reported by "
                                        "forward kinematics")
            vertices, formation, hold_height, mass, scale = ctx
            sens = equilibrium_sensitivity(vertices, formation, hold_height, mass, scale,
                                           self.taut, self.object, self.contact,
                                           self.weights)
            self.__dict__["_sens"] = sens
        return sens

    def __repr__(self) -> str:
        p = ", ".join(f"{c:.6g}" for c in self.object)      # taut as the attribute: 0-based
        return (f"Equilibrium(taut={tuple(int(i) for i in self.taut)}, object=({p}), "
                f"kind={self.kind!r})")


@dataclass(frozen=True)
class Funnel:
    """How many taut-cable sets survive each step of the FK paper's Algorithm 1.

    ``combinations`` (step 1), ``form_closure`` (step 2, eq. 5 rank test),
    ``cqp_feasible`` (step 3: slack cables stay slack, eq. 4 ``A2 x > b2``; this is the
    count the paper prints in Tables II and IV), ``height_feasible`` (step 3's remaining
    conditions: real depth and :math:`0 < z_o < z_r`), ``force_closure`` (step 4).
    """

    combinations: int
    form_closure: int
    cqp_feasible: int
    height_feasible: int
    force_closure: int


def _equilibrium(taut: tuple[int, ...], obj: np.ndarray, contact: np.ndarray,
                 weights: np.ndarray, tensions: np.ndarray | None, lengths: np.ndarray,
                 kind: str) -> Equilibrium:
    """An :class:`Equilibrium` without the dataclass ``__init__`` (the hot path of
    :class:`FKResult`; fields as in the class)."""
    e = object.__new__(Equilibrium)
    e.__dict__.update(taut=taut, object=obj, contact=contact, weights=weights,
                      tensions=tensions, cable_lengths=lengths, kind=kind)
    return e


_KIND_RANK = {"stable": 0, "saddle": 1, "not_equilibrium": 2}


def _merge_equilibria(eqs: tuple[Equilibrium, ...], sheet: Sheet, formation: np.ndarray,
                      hold_height: float, mass: float | None) -> tuple[Equilibrium, ...]:
    """``eqs`` with coinciding states reported once (:mod:`taut.sheet.fk._merge`), in
    output order (taut-set size, then taut set)."""
    if len(eqs) < 2:
        return eqs
    # Screen: coinciding states have coinciding heights (cheap, and nearly always decisive).
    tol = MERGE_RTOL * sheet.size
    z = sorted(float(e.object[2]) for e in eqs)
    if all(b - a > tol for a, b in zip(z, z[1:])):
        return eqs
    obj = np.array([e.object for e in eqs])
    contact = np.array([e.contact for e in eqs])
    labels = coincident_groups(obj, contact, sheet.size)
    if labels is None:
        return eqs
    out = []
    for g in np.unique(labels):
        members = [eqs[k] for k in np.flatnonzero(labels == g)]
        if len(members) == 1:
            out.append(members[0])
            continue
        rep = min(members, key=lambda e: (_KIND_RANK[e.kind], e.height))
        idx = np.array(rep.taut, dtype=np.intp)     # at its point; not the members' union
        w = merged_weights(sheet.vertices, formation, hold_height, sheet.size, idx,
                           rep.object[:2], rep.contact)
        lengths = np.linalg.norm(sheet.vertices[idx] - rep.contact, axis=1)
        kind = rep.kind
        tensions = None
        if mass is not None and kind != "not_equilibrium":
            tensions = w * (mass * GRAVITY) * lengths / (hold_height - rep.height)
        out.append(_equilibrium(tuple(int(i) for i in idx), rep.object.copy(),
                                rep.contact.copy(), w, tensions, lengths, kind))
    out.sort(key=lambda e: (len(e.taut), e.taut))
    return tuple(out)


def _with_lowest(eqs: tuple[Equilibrium, ...], sheet: Sheet, formation: np.ndarray,
                 hold_height: float, mass: float | None
                 ) -> tuple[tuple[Equilibrium, ...], bool, str | None]:
    """``eqs`` and, when none of them is stable, the lowest rest state found by direct
    minimisation (:mod:`taut.sheet.fk._lowest`) in place of a state at the same point;
    whether the minimisation supplied it, and if it found none, why (``_lowest.FLOOR``,
    ``OFF_SHEET`` or ``NO_REST``)."""
    if any(e.kind == "stable" for e in eqs):
        return eqs, False, None
    found = lowest_by_descent(sheet.vertices, formation, hold_height, sheet.size,
                              [(e.object, e.contact) for e in eqs])
    if isinstance(found, str):
        return eqs, False, found
    idx, obj, contact, w, strict = found
    lengths = np.linalg.norm(sheet.vertices[idx] - contact, axis=1)
    tensions = (None if mass is None
                else w * (mass * GRAVITY) * lengths / (hold_height - obj[2]))
    new = _equilibrium(tuple(int(i) for i in idx), obj, contact, w, tensions, lengths,
                       "stable" if strict else "saddle")
    tol = MERGE_RTOL * sheet.size
    keep = [e for e in eqs if max(np.abs(e.object - obj).max(),
                                  np.abs(e.contact - contact).max()) > tol]
    out = sorted(keep + [new], key=lambda e: (len(e.taut), e.taut))
    return tuple(out), True, None


class FKResult:
    """All rest states of the object for one formation (FK paper's output
    :math:`\\mathbb{P}_o, \\mathbb{V}_o, \\mathbb{I}_t`). Frozen.

    Attributes
    ----------
    equilibria : tuple of Equilibrium
        Every state that passes the paper's Algorithm 1, states at one point merged
        into one (``MERGE_RTOL``), plus the lowest rest state when only the direct
        minimisation found it; sorted by number of taut cables then by taut set. (Built on first access when the result came from the compiled
        kernel; the numbers are fixed when the result is made.)
    funnel : Funnel or None
        Step counts of Algorithm 1 (``method="exhaustive"`` only).
    method : str
        The FK method used.
    sheet, formation, hold_height, mass
        The inputs (formation as an (N, 2) array).
    success : bool
        At least one stable state: the formation holds the object.
    status : {"ok", "not_strict", "infeasible"}
        ``"ok"`` exactly when ``success``; ``"not_strict"`` when the lowest rest state
        (found by direct minimisation) is not a strict minimum of the height.
    direct : bool
        The enumeration missed the lowest rest state and a direct minimisation of the
        object's height supplied it (docs/sheet_fk_solver.md "The lowest state exists").
    message : str
        One line: how many states were found and how many are stable; without any state,
        why (e.g. the states the object would reach below the floor, FK paper eq. 15).
    """

    _equilibria: tuple[Equilibrium, ...] | None
    _rows: np.ndarray | None
    _enum: tuple[Equilibrium, ...]
    _message: str | None
    _direct: bool
    _why: str | None
    funnel: Funnel | None
    method: str
    sheet: Sheet
    formation: np.ndarray
    hold_height: float
    mass: float | None

    def __init__(self, equilibria: tuple[Equilibrium, ...], funnel: Funnel | None,
                 method: str, sheet: Sheet, formation: np.ndarray, hold_height: float,
                 mass: float | None) -> None:
        eqs = _merge_equilibria(tuple(equilibria), sheet, formation, hold_height, mass)
        self.__dict__.update(_equilibria=None, _rows=None, _enum=eqs, _message=None,
                             _direct=False, _why=None, funnel=funnel, method=method,
                             sheet=sheet, formation=formation, hold_height=hold_height,
                             mass=mass)

    @classmethod
    def _from_rows(cls, rows: np.ndarray, method: str, sheet: Sheet, formation: np.ndarray,
                   hold_height: float, mass: float | None) -> "FKResult":
        """A result whose equilibria are built on access from kernel rows (layout of
        ``_kernels.small``: kind, taut-set size, object, contact, depth, taut mask,
        weights, lengths, ...)."""
        self = object.__new__(cls)
        self.__dict__.update(_equilibria=None, _rows=rows, _enum=(), _message=None,
                             _direct=False, _why=None, funnel=None,
                             method=method, sheet=sheet, formation=formation,
                             hold_height=hold_height, mass=mass)
        return self

    @classmethod
    def _rows_maker(cls, method: str, sheet: Sheet, hold_height: float, mass: float | None
                    ) -> Callable[[np.ndarray, np.ndarray], "FKResult"]:
        """``make(rows, formation)``, the same as ``_from_rows(rows, method, sheet,
        formation, hold_height, mass)`` for one solver: the fields fixed per solver are set
        once and ``make`` copies one dict (the per-call path of ``FKSolver.solve``; a
        keyword update costs ~0.3 us more)."""
        template = cls._from_rows(np.zeros((0, 0)), method, sheet, np.zeros((0, 2)),
                                  hold_height, mass).__dict__
        new, set_dict = object.__new__, object.__setattr__

        def make(rows: np.ndarray, formation: np.ndarray) -> "FKResult":
            fields = template.copy()
            fields["_rows"] = rows
            fields["formation"] = formation
            self = new(cls)
            set_dict(self, "__dict__", fields)
            return self
        return make

    @classmethod
    def _out_maker(cls, method: str, sheet: Sheet, hold_height: float, mass: float | None
                   ) -> Callable[[np.ndarray, int], "FKResult"]:
        """``make(out, k)``: as :meth:`_rows_maker` for the buffer ``out`` of one
        ``_kernels.batch.solve_one`` call whose ``k`` rows are the answer. The rows
        (``out[:k]``) and the formation (the kernel's copy in ``out``'s last row) are
        views made on first read (``__getattr__``): the per-call path makes no array."""
        template = cls._from_rows(np.zeros((0, 0)), method, sheet, np.zeros((0, 2)),
                                  hold_height, mass).__dict__
        del template["_rows"], template["formation"]
        new, set_dict = object.__new__, object.__setattr__

        def make(out: np.ndarray, k: int) -> "FKResult":
            fields = template.copy()
            fields["_out"] = out
            fields["_k"] = k
            self = new(cls)
            set_dict(self, "__dict__", fields)
            return self
        return make

    if not TYPE_CHECKING:          # (mypy would otherwise accept any attribute name)
        def __getattr__(self, name: str) -> Any:
            """``_rows`` and ``formation`` of a result of :meth:`_out_maker`, made on
            first read (views of the kernel's buffer) and kept; any other missing name
            raises."""
            fields = self.__dict__
            out = fields.get("_out")
            if out is None or name not in ("_rows", "formation"):
                raise AttributeError(f"{type(self).__name__!r} object has no attribute "
                                     f"{name!r}")
            N = fields["sheet"].n
            fields.setdefault("_rows", out[:fields["_k"]])
            fields.setdefault("formation", out[-1, :2 * N].reshape(N, 2))
            return fields[name]

    def __setattr__(self, name: str, value: object) -> None:
        raise AttributeError(f"FKResult is frozen: cannot assign to {name!r}")

    def __delattr__(self, name: str) -> None:
        raise AttributeError(f"FKResult is frozen: cannot delete {name!r}")

    @property
    def equilibria(self) -> tuple[Equilibrium, ...]:
        eqs = self._equilibria
        if eqs is None:
            # Built once, on first access; the rows stay (a thread that read
            # ``_equilibria`` as None before another set it builds the same tuple again).
            eqs = self._build(self._rows)
            self.__dict__["_equilibria"] = eqs
        return eqs

    def _build(self, rows: np.ndarray | None) -> tuple[Equilibrium, ...]:
        """The states: the enumeration's (from the kernel ``rows`` when given) and, when
        none is stable, the direct minimisation's lowest (:func:`_with_lowest`)."""
        eqs = self._enum if rows is None or len(rows) == 0 else self._row_states(rows)
        return self._attach(*_with_lowest(eqs, self.sheet, self.formation,
                                          self.hold_height, self.mass))

    def _attach(self, eqs: tuple[Equilibrium, ...], direct: bool, why: str | None
                ) -> tuple[Equilibrium, ...]:
        """``eqs`` (an answer of :func:`_with_lowest`) as this result's states: records
        ``direct`` and ``why`` and gives each state the formation its lazy sensitivities
        need."""
        self.__dict__.update(_direct=direct, _why=why)
        ctx = (self.sheet.vertices, self.formation, self.hold_height, self.mass,
               self.sheet.size)
        for e in eqs:
            e.__dict__["_ctx"] = ctx
        return eqs

    @classmethod
    def _settled(cls, found: tuple[tuple[Equilibrium, ...], bool, str | None],
                 method: str, sheet: Sheet, formation: np.ndarray, hold_height: float,
                 mass: float | None) -> "FKResult":
        """A result whose states are ``found``, an answer of :func:`_with_lowest` already
        worked out (by a :class:`BatchFKResult`): nothing is solved again."""
        self = object.__new__(cls)
        self.__dict__.update(_rows=None, _enum=found[0], _message=None, funnel=None,
                             method=method, sheet=sheet, formation=formation,
                             hold_height=hold_height, mass=mass)
        self.__dict__["_equilibria"] = self._attach(*found)
        return self

    def _row_states(self, rows: np.ndarray) -> tuple[Equilibrium, ...]:
        """The enumeration's states from kernel rows, states at one point merged."""
        N = self.sheet.n
        scale = self.sheet.size
        force = None if self.mass is None else self.mass * GRAVITY
        out = []
        for row in rows:
            idx = np.flatnonzero(row[8:8 + N])
            w = row[8 + N + idx]
            lengths = row[8 + 2 * N + idx]
            kind = int(row[0])
            tensions = None
            if force is not None and kind != KIND_NOT_EQUILIBRIUM:
                tensions = w * force * (lengths / scale) / row[7]
            out.append(_equilibrium(tuple(idx.tolist()), row[2:5].copy(), row[5:7].copy(),
                                    w, tensions, lengths, KIND_NAMES[kind]))
        eqs = tuple(out)
        if len(rows) > 1:                        # the merge's height screen, on the rows
            z = sorted(rows[:, 4].tolist())
            tol = MERGE_RTOL * scale
            if not all(b - a > tol for a, b in zip(z, z[1:])):
                eqs = _merge_equilibria(eqs, self.sheet, self.formation, self.hold_height,
                                        self.mass)
        return eqs

    def _enumerated_stable(self) -> bool:
        """The enumeration found a stable state (read from its rows, before any state is
        built)."""
        rows = self._rows
        if rows is not None and len(rows):
            return KIND_STABLE in rows[:, 0].tolist()   # (a list: ~10x quicker than np.any)
        return any(e.stable for e in self._enum)

    def _no_stable_state(self) -> bool:
        """True when, before the states are built, no stable state can exist: the
        enumeration found none and the direct minimisation cannot supply one here
        (``_lowest.may_find_stable``; away from a similar copy it is not run for this)."""
        if self._equilibria is not None or self._enumerated_stable():
            return False
        return not may_find_stable(self.sheet.vertices, self.formation, self.sheet.size)

    @property
    def success(self) -> bool:
        """At least one stable state (the formation holds the object)."""
        if self._equilibria is None:
            if self._enumerated_stable():
                return True
            if not may_find_stable(self.sheet.vertices, self.formation, self.sheet.size):
                return False
        return any(e.stable for e in self.equilibria)

    @property
    def direct(self) -> bool:
        """True when the enumeration of taut sets missed the lowest rest state and the
        direct minimisation of the object's height supplied it (docs/sheet_fk_solver.md)."""
        self.equilibria
        return bool(self._direct)

    @property
    def status(self) -> str:
        """``"ok"`` when :attr:`success`; ``"not_strict"`` when the lowest rest state is
        not a strict minimum of the height (it is reported, kind ``"saddle"``);
        else ``"infeasible"`` (no rest state above the floor)."""
        if self.success:
            return "ok"
        return "not_strict" if self.lowest is not None else "infeasible"

    @property
    def message(self) -> str:
        """What was found, or why there is no stable state (one line; the reason for a
        result without any state is worked out on first access)."""
        msg = self._message
        if msg is None:
            msg = self._describe()
            self.__dict__["_message"] = msg
        return msg

    def _describe(self) -> str:
        eqs = self.equilibria
        off = {OFF_SHEET: "; the object slides off the sheet (descending its height carries "
                          "the contact point over the sheet's edge: no rest state)",
               NO_REST: "; no rest state: a direct minimisation of the height stops where "
                        "no non-negative load shares balance the object",
               }.get(self._why or "", "")
        if not eqs:
            return "no equilibrium: " + explain_no_equilibrium(
                self.sheet, self.formation, self.hold_height) + off
        stable = sum(e.stable for e in eqs)
        how = (" (the lowest found by direct minimisation of the height: the enumeration "
               "missed it)" if self._direct else "")
        if stable:
            return f"{len(eqs)} solution(s), {stable} stable{how}"
        if self._direct:
            return (f"lowest rest state not strict: {len(eqs)} solution(s), none stable"
                    f"{how}")
        saddle = sum(e.kind == "saddle" for e in eqs)
        return (f"no stable state: {len(eqs)} solution(s), {saddle} saddle, "
                f"{len(eqs) - saddle} not an equilibrium{off}")

    @property
    def stable(self) -> tuple[Equilibrium, ...]:
        """The stable equilibria (without building the other states where the enumeration
        found no stable one away from a similar copy of the sheet: there are none)."""
        if self._no_stable_state():
            return ()
        return tuple(e for e in self.equilibria if e.stable)

    @property
    def lowest(self) -> Equilibrium | None:
        """The lowest rest state (least potential energy): the lowest stable equilibrium;
        without one, the non-strict minimum found by direct minimisation (kind
        ``"saddle"``, :attr:`status` ``"not_strict"``). None only when the object would
        rest on the ground (no state with :math:`z_o > 0`)."""
        eqs = self.equilibria                    # sets _direct
        st = [e for e in eqs if e.stable]
        if st:
            return min(st, key=lambda e: e.height)
        if self._direct:
            return min((e for e in self.equilibria if e.kind == "saddle"),
                       key=lambda e: e.height, default=None)
        return None

    def closest_stable(self, point: ArrayLike) -> Equilibrium | None:
        """The stable equilibrium whose object is nearest to ``point``.

        Parameters
        ----------
        point : array_like, shape (3,) or (2,)
            A reference object position :math:`\\mathbf{p}_o` (e.g. the previous state
            of a tracked object), same length unit as the formation; with two
            coordinates only the horizontal distance counts.

        Returns
        -------
        Equilibrium or None
            The nearest stable state (Euclidean distance; the first in output order on
            ties), None when there is no stable state.

        Examples
        --------
        >>> import taut.sheet as ts
        >>> team = ts.SheetTeam(ts.Sheet([[0, 0], [1, 0], [1, 1], [0, 1]]), 1.0)
        >>> res = ts.forward_kinematics(team, [[0, 0], [0.9, 0], [0.9, 0.9], [0, 0.9]])
        >>> e = res.closest_stable([0.45, 0.45, 0.5])
        >>> e is not None and e.stable
        True
        """
        p = as_array(point, "point", ndim=1)
        if p.shape[0] not in (2, 3):
            raise InvalidInputError("point", f"must have 2 (x, y) or 3 (x, y, z) "
                                             f"coordinates, got {p.shape[0]}")
        st = self.stable
        if not st:
            return None
        d = [float(np.sum((e.object[:len(p)] - p) ** 2)) for e in st]
        return st[int(np.argmin(d))]

    def __len__(self) -> int:
        rows = self._rows
        if (self._equilibria is None and rows is not None and len(rows) == 1
                and rows[0, 0] == KIND_STABLE):
            return 1
        return len(self.equilibria)

    def __repr__(self) -> str:
        return (f"FKResult(method={self.method!r}, N={self.sheet.n}, "
                f"equilibria={len(self)}, stable={len(self.stable)})")


#: The padded per-solution arrays of a batch, in this order: count (B,), valid (B, K),
#: taut (B, K, N), object (B, K, 3), contact (B, K, 2), weights (B, K, N), tensions
#: (B, K, N) or None, kind (B, K).
_Padded = tuple


def _padded_field(i: int) -> Any:
    """Property ``i`` of the padded arrays (:data:`_Padded`) of a :class:`BatchFKResult`,
    built on first read (``BatchFKResult._final``)."""
    return property(lambda self: self._final()[i])


class BatchFKResult(CompactRepr):
    """Forward kinematics of ``B`` formations of one sheet, as padded arrays. Frozen.

    Row ``b`` holds ``count[b]`` solutions in slots ``0..count[b]-1`` (same order as
    :class:`FKResult`); later slots are padding (``valid`` False, NaN positions). A
    formation the sheet cannot span (a robot pair farther apart than its sheet vertices)
    has no solutions, ``feasible`` False and ``status`` ``"infeasible"``; the other rows
    are answered as usual. The states' sensitivities (``jacobian``, ``taut_margin``, ...:
    docs/sheet_sensitivity.md) are read per state, ``result(b).equilibria[k].jacobian``.

    As in :class:`FKResult`, the direct minimisation of the height (formations whose
    enumeration found no stable state, docs/sheet_fk_solver.md "The lowest state exists")
    runs only when a field that depends on it is first read: the per-solution arrays and
    ``status`` run it for every such formation, ``success`` and ``message`` only for
    those next to a similar copy of the sheet, ``result(b)`` for formation ``b`` alone
    (and only when its states are read); ``feasible`` and the inputs never. The numbers
    are fixed when the result is made: reading the fields in any order gives the same
    values.

    Attributes
    ----------
    count : ndarray of int, shape (B,)
    valid : ndarray of bool, shape (B, K)
    taut : ndarray of bool, shape (B, K, N)
        Taut cables of each solution.
    object : ndarray, shape (B, K, 3)
    contact : ndarray, shape (B, K, 2)
    weights : ndarray, shape (B, K, N)
        Weight of each cable (0 for slack cables).
    tensions : ndarray, shape (B, K, N), or None
        Tensions in N (0 for slack cables, NaN for the taut cables of non-equilibria)
        when a mass was given.
    kind : ndarray of int8, shape (B, K)
        What each solution is (:attr:`Equilibrium.kind`): 0 stable, 1 saddle,
        2 not_equilibrium, -1 padding.
    feasible : ndarray of bool, shape (B,)
        The sheet can span formation ``b`` (the FK paper's ``FormationFeasible``).
    success : ndarray of bool, shape (B,)
        Formation ``b`` is feasible and has at least one stable state.
    status : ndarray of str, shape (B,)
        ``"ok"`` where ``success``; ``"not_strict"`` where the direct minimisation found
        a lowest rest state that is not a strict minimum; else ``"infeasible"``.
    message : str
        One line over the batch: how many formations hold the object, and the first
        formation the sheet cannot span.
    sheet, formations, hold_height, mass, method
        The inputs (formations as a (B, N, 2) array) and the FK method used.
    """

    #: Fields in the order :class:`~taut._repr.CompactRepr` prints them.
    REPR_FIELDS = ("count", "valid", "taut", "object", "contact", "weights", "tensions",
                   "kind", "feasible", "success", "status", "message", "sheet",
                   "formations", "hold_height", "mass", "method")

    _enum: _Padded | Callable[[], _Padded]
    _kind: np.ndarray
    _padded: _Padded | None
    _missing: np.ndarray
    _found: dict[int, tuple[tuple[Equilibrium, ...], bool, str | None]]
    _success: np.ndarray | None
    _status: np.ndarray | None
    _message: str | None
    feasible: np.ndarray
    sheet: Sheet
    formations: np.ndarray
    hold_height: float
    mass: float | None
    method: str

    def __init__(self, padded: _Padded | Callable[[], _Padded], kind: np.ndarray,
                 missing: np.ndarray, feasible: np.ndarray, sheet: Sheet,
                 formations: np.ndarray, hold_height: float, mass: float | None,
                 method: str) -> None:
        """``padded``: the enumeration's states (:data:`_Padded`, coinciding ones already
        merged), or a function building them on first need; ``kind``: their kinds (B, K);
        ``missing``: the feasible formations among them without a stable state (the
        direct minimisation's candidates)."""
        ready = not callable(padded) and not len(missing)
        self.__dict__.update(_enum=padded, _kind=kind, _padded=padded if ready else None,
                             _missing=missing, _found={}, _success=None, _status=None,
                             _message=None, feasible=feasible, sheet=sheet,
                             formations=formations, hold_height=hold_height, mass=mass,
                             method=method)

    def __setattr__(self, name: str, value: object) -> None:
        raise AttributeError(f"BatchFKResult is frozen: cannot assign to {name!r}")

    def __delattr__(self, name: str) -> None:
        raise AttributeError(f"BatchFKResult is frozen: cannot delete {name!r}")

    # -- the padded arrays (the direct minimisation's states included) -------------------
    count = _padded_field(0)
    valid = _padded_field(1)
    taut = _padded_field(2)
    object = _padded_field(3)
    contact = _padded_field(4)
    weights = _padded_field(5)
    tensions = _padded_field(6)
    kind = _padded_field(7)

    def _states(self) -> _Padded:
        """The enumeration's padded states (``_enum``), built on first call when given as
        a function, published at once."""
        enum = self._enum
        if callable(enum):
            enum = enum()
            self.__dict__["_enum"] = enum
        return enum

    def _lowest_of(self, b: int) -> tuple[tuple[Equilibrium, ...], bool, str | None]:
        """:func:`_with_lowest` of formation ``b`` (one of ``_missing``), worked out once."""
        found = self._found.get(b)
        if found is None:
            found = _with_lowest(_row_states(self.sheet, self._states(), b), self.sheet,
                                 self.formations[b], self.hold_height, self.mass)
            self._found[b] = found
        return found

    def _final(self) -> _Padded:
        """The padded arrays with the direct minimisation's lowest state in every
        formation of ``_missing`` it supplied one for (one more slot where needed); built
        on first call into fresh arrays, published at once."""
        padded = self._padded
        if padded is not None:
            return padded
        if not len(self._missing):
            padded = self._states()
            self.__dict__["_padded"] = padded
            return padded
        supplied = {}
        for b in self._missing.tolist():
            eqs, direct, _ = self._lowest_of(b)
            if direct:
                supplied[b] = eqs
        enum = self._states()
        K = max([enum[1].shape[1]] + [len(e) for e in supplied.values()])
        padded = (enum[0].copy(),) + tuple(
            None if a is None else _widen(a, K, fill)
            for a, fill in zip(enum[1:], (False, False, np.nan, np.nan, 0.0, 0.0, -1)))
        for b, eqs in supplied.items():
            _write_row(b, eqs, *padded)
        self.__dict__["_padded"] = padded
        return padded

    # -- outcome -------------------------------------------------------------------------
    @property
    def success(self) -> np.ndarray:
        s = self._success
        if s is None:
            s = self.feasible & _has_kind(self._kind, KIND_STABLE)
            missing = self._missing
            if len(missing):
                # Only next to a similar copy can the descent supply a stable state
                # (_lowest.may_find_stable, for all of them at once; as FKResult.success).
                near = may_find_stable_batch(self.sheet.vertices, self.formations[missing],
                                             self.sheet.size)
                for b in missing[near].tolist():
                    s[b] = any(e.stable for e in self._lowest_of(b)[0])
            self.__dict__["_success"] = s
        return s

    @property
    def status(self) -> np.ndarray:
        st = self._status
        if st is None:
            success = self.success
            direct = np.zeros(len(success), dtype=bool)
            for b in self._missing.tolist():
                direct[b] = self._lowest_of(b)[1]
            st = np.where(success, "ok", np.where(direct, "not_strict", "infeasible"))
            self.__dict__["_status"] = st
        return st

    @property
    def message(self) -> str:
        msg = self._message
        if msg is None:
            msg = _batch_message(self.sheet, self.formations, self.success, self.feasible)
            self.__dict__["_message"] = msg
        return msg

    @property
    def stable(self) -> np.ndarray:
        """Bool (B, K): which solutions are stable."""
        return self.kind == KIND_STABLE

    def __len__(self) -> int:
        return int(self.formations.shape[0])

    def result(self, b: int) -> FKResult:
        """The solutions of formation ``b`` as an :class:`FKResult` (its direct
        minimisation, when it needs one, shared with this batch's).

        Raises
        ------
        InfeasibleFormationError
            Formation ``b`` is not feasible (as :func:`~taut.sheet.forward_kinematics`
            raises for it).
        """
        b = range(len(self))[b]
        if not self.feasible[b]:
            check_formation(self.sheet, self.formations[b])        # raises with the pair
        formation = self.formations[b].copy()
        found = self._found.get(b)
        if found is not None:
            return FKResult._settled(found, self.method, self.sheet, formation,
                                     self.hold_height, self.mass)
        return FKResult(_row_states(self.sheet, self._states(), b), None, self.method,
                        self.sheet, formation, self.hold_height, self.mass)


def _row_states(sheet: Sheet, padded: _Padded, b: int) -> tuple[Equilibrium, ...]:
    """The states of formation ``b`` in the padded arrays (:data:`_Padded`), in order."""
    count, _, taut, obj, contact, weights, tensions, kind = padded
    out = []
    for k in range(int(count[b])):
        idx = np.flatnonzero(taut[b, k])
        code = int(kind[b, k])
        out.append(_equilibrium(
            tuple(int(i) for i in idx), obj[b, k].copy(), contact[b, k].copy(),
            weights[b, k, idx].copy(),
            (None if tensions is None or code == KIND_NOT_EQUILIBRIUM
             else tensions[b, k, idx].copy()),
            np.linalg.norm(sheet.vertices[idx] - contact[b, k], axis=1), KIND_NAMES[code]))
    return tuple(out)


def _write_row(b: int, states: tuple[Equilibrium, ...], count: np.ndarray,
               valid: np.ndarray, taut: np.ndarray, obj: np.ndarray, contact: np.ndarray,
               weights: np.ndarray, tensions: np.ndarray | None, kind: np.ndarray) -> None:
    """Replace formation ``b``'s states in the padded arrays by ``states``, in place."""
    m = len(states)
    count[b] = m
    valid[b] = False
    valid[b, :m] = True
    taut[b] = False
    obj[b] = np.nan
    contact[b] = np.nan
    weights[b] = 0.0
    kind[b] = -1
    if tensions is not None:
        tensions[b] = 0.0
    for j, e in enumerate(states):
        idx = np.array(e.taut, dtype=np.intp)
        taut[b, j, idx] = True
        obj[b, j] = e.object
        contact[b, j] = e.contact
        weights[b, j, idx] = e.weights
        kind[b, j] = KIND_NAMES.index(e.kind)
        if tensions is not None:
            tensions[b, j, idx] = np.nan if e.tensions is None else e.tensions


def _has_kind(kinds: np.ndarray, code: int) -> np.ndarray:
    """Formations with a state of kind ``code``: (B,) bool of the padded ``kinds`` (B, K).
    One column at a time (K is a few slots): ~10 x faster than ``np.any(..., axis=1)``
    over the short axis, and the same values."""
    has = kinds[:, 0] == code if kinds.shape[1] else np.zeros(kinds.shape[0], dtype=bool)
    for j in range(1, kinds.shape[1]):
        has |= kinds[:, j] == code
    return has


def _widen(a: np.ndarray, K: int, fill: float | bool | int) -> np.ndarray:
    """A fresh copy of the padded array ``a`` (B, K0, ...) with ``K - K0`` more slots of
    ``fill``."""
    extra = np.full((a.shape[0], K - a.shape[1]) + a.shape[2:], fill, dtype=a.dtype)
    return np.concatenate([a, extra], axis=1)


def _batch_message(sheet: Sheet, formations: np.ndarray, success: np.ndarray,
                   feasible: np.ndarray) -> str:
    """The one-line message of a batch: how many formations hold the object, and why the
    first the sheet cannot span cannot be spanned."""
    message = (f"{int(np.count_nonzero(success))} of {len(success)} formation(s) hold the "
               "object in a stable state")
    torn = np.flatnonzero(~feasible)
    if len(torn):
        b = int(torn[0])
        try:
            check_formation(sheet, formations[b])
            why = "the sheet cannot span it"                   # pragma: no cover
        except InfeasibleFormationError as exc:
            why = exc.problem
        message += f"; {len(torn)} infeasible, the first is formation {b}: {why}"
    return message
