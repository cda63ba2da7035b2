"""Every numerical threshold of the sheet core, in one place: forward kinematics first,
then inverse kinematics and the quasi-static simulation.

All FK work happens in a normalised frame (formation and sheet centred, lengths divided
by the sheet size :math:`s`, docs/sheet_kinematics.md §1), so "normalised length" below
means a length in units of the sheet size and "normalised area" one in units of
:math:`s^2`. Changing any value here can change answers; the ones a user may want to
move are exposed as keyword arguments where they are used.
"""

from __future__ import annotations

# --- Taut sets, weights, stability (decide the answers; docs/sheet_kinematics.md §1-§5) ---

#: Cable ``j`` counts as taut when :math:`L_j^2 - l_j^2 \\ge -` this (normalised area).
#: Rounding of the lifted-point products is ~1e-15; 1e-9 also absorbs inputs given to
#: ~9 significant digits (a robot pair placed "at" its sheet distance).
TAUT_TOL = 1e-9
#: Weights above ``-WEIGHT_TOL`` count as non-negative (dimensionless load shares, sum 1).
#: Ten times ``TAUT_TOL``: where the taut set changes, a cable that is taut only within
#: ``TAUT_TOL`` carries a weight of that order and either sign.
WEIGHT_TOL = 1e-8
#: Reduced-Hessian eigenvalues above this count as positive (dimensionless: the Hessian
#: of q is scaled to diag(1, 1, -1, -1), eigenvalues lie in [-1, 1]).
CURVATURE_TOL = 1e-9
#: Candidates whose weights all exceed this (dimensionless) pass the paper's projection
#: test unchecked: r_o = sum w_i r_i is then strictly inside the taut robots' polygon.
INSIDE_WEIGHT = 1e-6
#: Angular slack (radians) of the paper's projection test (no gap wider than pi).
ANGLE_TOL = 1e-9
#: Squared relative distance (dimensionless) below which the projected object counts as
#: sitting on a taut robot in the projection test (a distance of 1e-12 of the polygon).
COINCIDE_RTOL2 = 1e-24

# --- Lagrange systems (which candidate systems are solvable) ---

#: Relative determinant (|det K| / product of row norms, dimensionless) below which a
#: candidate's Lagrange system is checked for singularity by its condition number.
SINGULAR_RTOL = 1e-10
#: Condition number (dimensionless) above which a Lagrange system counts as singular
#: (affinely dependent lifted points give ~1e16; valid ill-conditioned ones reach ~1e8).
MAX_CONDITION = 1e12
#: One-sided Jacobi (compiled condition-number test) stops rotating a column pair whose
#: cosine is below this (dimensionless): machine precision, columns orthogonal.
JACOBI_TOL = 1e-15
#: With affinely independent candidates (hull faces) a solution component above this
#: (dimensionless weights / normalised mu) means LAPACK solved a singular system.
MAX_SOLUTION = 1e9

# --- Ranks and flatness of the lifted points (normalised lengths) ---

#: Singular values of centred lifted points, differences or weight equations below this
#: times the largest (or 1) count as zero: lifted coordinates are O(1) normalised, their
#: rounding ~1e-15, genuine thickness of non-degenerate teams >> 1e-9.
RANK_TOL = 1e-9
#: Relative thickness (smallest over largest singular value of the centred lifted points)
#: below which the points are flat for Qhull's purposes ...
EXACT_FLAT = 1e-13
#: ... and below which (but above EXACT_FLAT) they are "nearly flat": neither the flat
#: nor the full hull is reliable, so small teams take every subset.
NEAR_FLAT = 1e-9
#: Linear independence threshold of Gaussian elimination in the exhaustive method
#: (relative to the largest row norm or 1): as in the paper's rank test (eq. 5).
ELIMINATION_RTOL = 1e-10
#: The "up" axis lies in the lifted points' affine hull when its projection has norm
#: above 1 - this (dimensionless).
UP_IN_HULL_TOL = 1e-9
#: Facets whose outward unit normal has last component above this are upper facets (the
#: shortcut path); in reduced coordinates facets with up-component above minus this.
UPPER_NORMAL_TOL = 1e-12

# --- Closed-form stationary points from facet normals (_candidates) ---

#: Faces whose spanning directions have a relative size or mutual sine below this are
#: solved by the Lagrange kernel rather than in closed form from the facet normals.
FALLBACK_SIN = 1e-3
#: Relative determinant of the 1x1 / 2x2 closed-form systems below which they count as
#: singular (then the Lagrange kernel decides).
CLOSED_FORM_RTOL = 1e-12
#: Gram-Schmidt residual (relative squared norm) below which the closed-form curvature
#: is left to the SVD-based reduced Hessian (digits lost to cancellation).
GRAM_SCHMIDT_RTOL2 = 1e-2
#: Guard against division by zero in ratios of squared norms (any tiny positive value).
TINY = 1e-300

# --- Input checks and snapping (relative to the sheet size) ---

#: Equilibria whose object points and contact points both lie within this distance
#: (relative to the sheet size) of each other are one physical state and are reported once
#: (fk._merge; docs/sheet_fk_solver.md "One state, one answer"): above the splitting float64
#: and finite-digit data cause next to a similar copy of the sheet (measured up to 3.5e-6:
#: a regular hexagon at 0.9x written to 6 decimals), and 500x below a robot's 5 mm error on
#: a 1 m sheet (the planner's robustness check), so no two states a team can tell apart merge.
MERGE_RTOL = 1e-5
#: The direct minimisation of the object's height (fk._lowest) can supply a *stable* state
#: the enumeration missed only within this distance (relative to the sheet size) of a similar
#: copy of the sheet, where float64 cannot tell a cable slack by 1e-9 from a taut one; 10x
#: the largest noise of the issue-25 property test (1e-4), far outside SNAP_TOL. Elsewhere
#: the enumeration's stable states are complete, so ``FKResult.stable``/``success`` skip the
#: descent there (it still runs, on first access, for ``lowest``, ``status``, ``message``).
DIRECT_RTOL = 1e-3
#: Iterations of each descent of the direct minimisation of the object's height (fk._lowest;
#: run where the enumeration reports no stable state): from the centroids it arrives within
#: a few dozen; one still running drifts towards the floor.
DIRECT_MAXIT = 400
#: Pieces of F within this (normalised: squared lengths over the squared sheet size) of the
#: maximum where the descent stops are re-solved exactly, every subset of 3..5 of them
#: (fk._lowest): next to a similar copy the descent can stop on a flat-looking face whose
#: neighbours carry the true minimiser (seed 34152 of the issue-25 property test: it stops
#: on a 2-cable face, the strict minimum's third cable 1.6e-6 below the maximum there);
#: 60x that, and far below the gaps between distinct states of a generic team.
DIRECT_NEAR_TOL = 1e-4
#: At most this many of those pieces (the highest) are re-solved: C(10, <=5) = 637 systems.
DIRECT_NEAR_MAX = 10
#: Relative tolerance (times the sheet size) for geometric equalities on input data:
#: robot pairs may exceed their sheet distance by this much (rounding of given data).
GEOMETRY_RTOL = 1e-9
#: Winding-number slack (radians) when telling a convex polygon from a star.
WINDING_TOL = 1e-6
#: The fast formation check accepts pairs whose squared distance is below the squared
#: sheet distance shrunk by this relative amount; anything closer to the limit gets the
#: full check (which applies GEOMETRY_RTOL).
FAST_CHECK_RTOL = 1e-12
#: Formations within this distance (relative to the sheet size) of a similar copy of the
#: sheet are solved as that copy (see fk._solve._snap_near_similar; docs/sheet_fk_solver.md):
#: closer than this, float64 names one rest state by many taut sets (seen: 40 stable
#: "states" within 1.1e-8 of each other at 1e-10 from a copy, N = 22).
SNAP_TOL = 1e-7
#: ... but not those closer than this (relative): they are the copy, up to rounding.
SNAP_MIN = 1e-13
#: Relative widening of the compiled pre-screen of the snap test (its closed-form fit
#: agrees with the SVD-based one to ~1e-12; the exact test runs on what passes).
SCREEN_SLACK = 1e-6
#: An IK contact point must lie inside the sheet by this much (relative to the sheet size;
#: ``Sheet.contains(tol=-...)``): the same rounding margin as GEOMETRY_RTOL, on the other side,
#: so a point given "on" an edge is rejected as not strictly inside.
CONTACT_INSET_RTOL = 1e-9

# --- Weight families (LP / QP for taut sets larger than the state determines) ---

#: Equality residual (dimensionless) the QP's min-norm weights must meet to be used.
FAMILY_RESIDUAL = 1e-9
#: SLSQP function tolerance for the min-norm non-negative weights (dimensionless).
FAMILY_FTOL = 1e-15


# ==============================================================================
# Inverse kinematics and quasi-static simulation (lengths relative to the sheet size).
# ==============================================================================

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
#: Of those, how many run before the branch-and-bound proof is tried (reachable targets the
#: construction misses are nearly always found within a few starts; the proof costs more).
EARLY_SEARCHES = 8
#: Default number of angle boxes (each one LP) the branch-and-bound unreachability proof may
#: examine before giving up; the hardest refutations of the 1,000-target benchmark took ~200.
DEFAULT_BRANCH_BOXES = 800
#: Boxes of a first, short branch-and-bound attempt made before any multi-start search: most
#: refutations need fewer (7-40 on the benchmark), and it costs ~0.1 s where the search with
#: its finite-difference curvature constraint (N <= 4) costs seconds.
EARLY_BRANCH_BOXES = 64
#: Residual of the balance equation and the contact equations (relative to the formation's
#: largest centred coordinate, or 1 for contacts) under which ``IKConstraints.feasible``
#: holds: a rounding allowance, the same value as the formation check's GEOMETRY_RTOL.
IK_FEASIBLE_RTOL = 1e-9
#: A reference robot closer than this horizontally to the object (normalised length) gives
#: no direction to turn towards; its sheet direction is used instead.
REFERENCE_MIN_RADIUS = 1e-9
#: SLSQP function tolerance of the joint (angles, weights) optimisation (dimensionless
#: objective in normalised units): tight; the result is then polished and checked against
#: EQUATION_RTOL.
IK_SLSQP_FTOL = 1e-12
#: The joint optimisation keeps each robot pair inside ``1 - this`` of its sheet distance
#: (dimensionless): strictly inside, 1000x BOUNDARY_RTOL, so the small moves of polishing
#: keep the pairs within their limits.
IK_PAIR_SHRINK = 1e-7
#: Pair-limit constraint generation (dense SLSQP gets one Jacobian row per pair it is
#: given: all N(N-1)/2 pairs of a 1,000-robot team are 8 GB per copy). Each solve is given
#: every robot's this many nearest robots (at the current point) ...
IK_PAIR_NEIGHBOURS = 6
#: ... plus every pair whose squared-distance slack is below this fraction of its squared
#: limit (dimensionless; violated pairs included). After a solve, any left-out pair below it
#: is added and the solve repeated, so a pair left out of the final solve is at least this
#: far inside its limit: inactive, and the answer is the all-pairs problem's.
IK_PAIR_NEAR = 0.05
#: Most solves (rounds) of that constraint generation per optimisation; when a round still
#: leaves out a near or violated pair, the last point is returned and the caller's exact
#: check (``check_solution``) decides, as for any other SLSQP result.
IK_PAIR_ROUNDS = 6
#: A cable counts as too short for the depth when its length is at most ``depth * (1 + this)``
#: (dimensionless): rounding of the given lengths (~1e-16) must not hide a cable at the depth.
DEPTH_RTOL = 1e-12
#: A relaxation certificate's multipliers must sum to 1 within this (dimensionless): they
#: come from an LP solver, so rounding of ~1e-15 per entry is allowed, no more.
MULTIPLIER_SUM_TOL = 1e-12
#: Armijo sufficient-decrease constant (dimensionless) of the backtracking line searches
#: (maximum-entropy weights, geometric median, nonsmooth descent): the usual textbook value.
ARMIJO_C1 = 1e-4
#: Maximum-entropy weights: Newton stops when the dual gradient's norm (dimensionless: the
#: weighted mean of normalised offsets) is below this, i.e. at machine precision ...
MAXENT_GRAD_TOL = 1e-15
#: ... and its line search accepts any step once the step factor is below this.
MAXENT_MIN_STEP = 1e-12
#: Geometric median: the median counts as on one of the points (no unit vector there) when
#: closer than this (dimensionless: the points are unit directions).
MEDIAN_COINCIDE = 1e-13
#: Geometric median: converged when the gradient's norm is below this times the total weight
#: (dimensionless; machine precision of a sum of unit vectors) ...
MEDIAN_RTOL = 1e-14
#: ... and its damped Newton step is abandoned below this step factor (dimensionless).
MEDIAN_MIN_STEP = 1e-14
#: Closure directions are accepted when the weighted sum of the unit vectors is below this
#: times the total weight (dimensionless): far above the median's convergence (1e-14).
CLOSURE_RTOL = 1e-10

#: Default IK ``sheet_margin`` (relative to the sheet size): every robot pair of an answer
#: stays this far inside its sheet distance -- the planner's default (10 mm) on its 1 m
#: sheets, so 5 mm of error on each robot of a pair cannot tear the sheet.
IK_MARGIN_RTOL = 0.01
#: Relative slack (dimensionless) of the IK margin test: polishing moves robots by ~1e-9,
#: so an answer optimised to the margin is accepted within this fraction of it.
MARGIN_SLACK = 1e-6
#: Seeded draws of the IK robustness admission: each robot displaced by ``position_error``
#: in a random direction; the object must stay held in every draw ...
ROBUST_DRAWS = 8
#: ... i.e. a stable state within this many times ``position_error`` of the target
#: (dimensionless): the object follows the robots by about their error; a state farther
#: away is a jump to another branch (or none: lost).
ROBUST_REACH = 20.0
#: Seed of those draws (answers are deterministic).
ROBUST_SEED = 25

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
#: Past a degenerate state (more than 5 taut cables, not trackable) the simulation leaves it
#: at once: the next look is this fraction of a step further (dimensionless), far above
#: EVENT_STEP_TOL so the state is actually left.
DEGENERATE_STEP = 1e-6
#: Nonsmooth descent: initial width (normalised area, as F) of the epsilon-active set of
#: pieces; it shrinks by 10x whenever the descent stalls ...
DESCENT_EPS0 = 1e-3
#: ... down to this width, below which the descent stops at a (Clarke) stationary point.
DESCENT_MIN_EPS = 1e-12
#: Nonsmooth descent: a squared norm of the minimum-norm gradient below this (normalised)
#: means the point is epsilon-stationary (norm 1e-11, rounding of O(1) gradients).
DESCENT_GRAD2_TOL = 1e-22
#: Nonsmooth descent: the Armijo line search gives up below this step length (normalised).
DESCENT_MIN_STEP = 1e-14

# --------------------------------------------------------------------------- backends

#: The compiled kernel and the numpy path agree on every equilibrium's object, contact
#: and cable lengths to this (relative to the sheet size; issue 12's acceptance bound).
#: Both try the same candidates with the same screens and, next to a similar copy, both
#: answer the copy, so what is left is rounding of well-conditioned systems: measured
#: worst 1.4e-13 on 1,080 hypothesis-style teams (docs/sheet_fk_solver.md).
BACKEND_RTOL = 1e-9
#: ... and on load shares (dimensionless, of a total of 1) and relative tensions: the
#: same minimum-norm non-negative shares for dependent taut sets (one shared routine,
#: ``_finalize._weights_family``); measured worst 4.7e-13.
BACKEND_WEIGHT_TOL = 1e-9
