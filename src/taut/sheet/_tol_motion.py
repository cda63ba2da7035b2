"""Thresholds of inverse kinematics and quasi-static simulation (one place, each with its
unit and the reason for its value). Lengths are relative to the sheet size unless said
otherwise; see docs/sheet_kinematics.md §1 for the normalised frame."""

from __future__ import annotations

# --------------------------------------------------------------------------- IK

#: Smallest load share (dimensionless, of a total of 1) an IK solution may give a cable:
#: below it a cable is "taut but unloaded" and the state sits on a transition.
MIN_WEIGHT = 1e-6
#: Smallest reduced-Hessian eigenvalue (dimensionless, Hessian scaled to diag(1,1,-1,-1))
#: of an IK solution; a strictly positive margin so the object does not roll away.
MIN_CURVATURE = 1e-6
#: A pair is refuted by the radial-spacing proof only when it is violated by more than this
#: (relative): far above rounding (1e-16) so the proof survives float64 arithmetic.
SPACING_MARGIN = 1e-8
#: An IK answer may put a robot pair this much (relative) beyond its sheet distance: a
#: rounding-level allowance for pairs *at* their limit (the boundary case), ten times
#: tighter than the formation check's GEOMETRY_RTOL (1e-9) so answers always pass it.
BOUNDARY_RTOL = 1e-10
#: Residual (relative) of the balance and contact equations accepted before verification.
EQUATION_RTOL = 1e-11
#: The forward-kinematics verification: a stable all-taut equilibrium within this distance
#: (relative) of the target (issue 12's acceptance figure).
VERIFY_RTOL = 1e-6
#: Loosening (dimensionless, of a cosine) of the pairwise angle limits in the convex
#: relaxation, so that rounding can only make the relaxation *larger* (still valid).
RELAX_COS_SLACK = 1e-9
#: A relaxation certificate must separate by at least this (relative, in units of the
#: horizontal reach): a strict margin far above the LP solver's 1e-9 feasibility tolerance.
CERTIFICATE_MIN_MARGIN = 1e-7
#: Default number of multi-start searches before IK reports ``budget_exhausted``.
DEFAULT_BUDGET = 40

# --------------------------------------------------------------------------- simulation

#: Continuation tolerance at an event (times the sheet size), plus a motion-based term.
CONTINUATION_RTOL = 1e-6
#: Precision (fraction of a step) to which an event is located.
EVENT_STEP_TOL = 1e-10
#: Teams up to this size use FK's complete 'subsets' method at events (cost grows as 2^N).
SUBSETS_UP_TO = 10
#: A descent has arrived when the pieces active at its point (within 1e-6) form a stable
#: state this close (times the sheet size) to it.
ARRIVAL_RTOL = 0.05
#: Pieces of F within this (normalised) of the maximum count as active for arrival.
ARRIVAL_ACTIVE_TOL = 1e-6
#: Rank tolerance (relative to the largest singular value) for affine independence of
#: lifted points when choosing a support; the kernel's SINGULAR_RTOL order of magnitude.
SUPPORT_RANK_RTOL = 1e-9
