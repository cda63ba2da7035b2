"""Every numerical threshold of the cable-robot core, in one place (private).

Each constant says its unit and why it has its value. *Relative* thresholds are
dimensionless and multiply a scale named in the comment; *absolute* ones carry a unit.
Thresholds that change answers a user sees (feasible or not) are also exposed as
documented keyword arguments of the public functions; the constants here are their
defaults.
"""

from __future__ import annotations

# --- rank and degeneracy --------------------------------------------------------------
#: Relative singular-value threshold (dimensionless, times the largest singular value)
#: below which a wrench matrix W, a parallel Jacobian A or a driver twist map counts as
#: rank deficient. 1e-9 keeps 7 digits of margin above float64 round-off (~1e-16 times the
#: condition number of well-posed FASTKIT poses, <= 1e3) while flagging true singularities.
RANK_TOL = 1e-9

#: Relative threshold (times the largest generator entry) on the smallest |R| diagonal of
#: a QR factorisation below which a generator subset does not span a hyperplane (zonotope
#: facet enumeration) or a set of Farkas rows counts as degenerate. Smaller than RANK_TOL
#: because these are products of several entries; 1e-10 was tuned to keep every facet of
#: the FASTKIT twist and wrench sets and drop none (the tests compare against LPs).
SUBSET_DEGENERACY = 1e-10

#: Relative norm (times the largest row entry) below which a combined H-row is a zero
#: row (a certificate with no wrench/twist dependence), and the threshold on direction
#: components in ray shooting (capacities). Dimensionless; 1e-12 is ~1e4 ulp.
ZERO_ROW = 1e-12

#: Added to a scale before dividing by it so that an all-zero batch entry gives 0, not NaN
#: (dimensionless; far below any physical scale).
TINY = 1e-300

#: Pairs of Farkas rows with ``cos(angle) <= -(1 - OPPOSITE_COS)`` are treated as
#: opposite (parallel constraints facing each other). Dimensionless.
OPPOSITE_COS = 1e-12

#: Lower bound on Farkas multipliers after normalisation to max 1 (dimensionless): slightly
#: negative values within this are round-off of a valid non-negative certificate.
MULTIPLIER_SIGN = 1e-9

#: Squared norm below which a constraint row of the exact QP enumeration is ignored
#: (units of tension^2 per unit null-space coordinate; rows are O(1)). And the determinant
#: below which two rows are parallel (no vertex).
QP_ROW_SQ = 1e-24
QP_PARALLEL = 1e-12

# --- feasibility ----------------------------------------------------------------------
#: Tension/moment feasibility slack, relative to the largest tension limit t_max (so in N,
#: and N m per metre of lever arm). 1e-9 of t_max is far above LP/QP solver round-off and
#: far below any physically meaningful tension.
FEAS_REL = 1e-9

#: Equilibrium residual ``|W t + w_e|`` accepted as balanced, relative to
#: ``1 + max |w_e|`` (N, N m). Same reasoning as FEAS_REL.
RESIDUAL_REL = 1e-9

#: Multiplier of FEAS_REL used by the exact wrench-feasibility vertex test: the vertex
#: candidate is computed from two constraint rows, so its error is a few times that of one
#: row; 4 keeps the test agreeing with HiGHS on every bench pose.
VERTEX_SLACK = 4.0

#: SLSQP acceptance slack on inequality rows (relative to t_max): the SQP's own accuracy
#: is ~1e-8, looser than the LP's; 1e-6 of t_max (e.g. 45 uN for FASTKIT).
SLSQP_REL = 1e-6

#: Default slack of ``contains`` tests of wrench and twist sets (absolute, in the set's
#: units: N / N m or m/s / rad/s).
CONTAINS_TOL = 1e-9

#: Relative tolerance (times 1 + largest coordinate, m) of the frame-box and
#: desired-workspace membership tests: a point on the box face is inside.
BOX_REL = 1e-9

#: Relative cable length (times 1 + largest exit coordinate, m) below which an attachment
#: point sits on its exit point and the cable direction is undefined.
ZERO_LENGTH_REL = 1e-12

# --- model validation -----------------------------------------------------------------
#: Footprint checks, relative to the polygon's extent (edge length) or its square (area,
#: turn): repeated points and zero area at 1e-9, collinear turns at 1e-12; winding number
#: within 1e-6 rad of 2 pi.
FOOTPRINT_EDGE = 1e-9
FOOTPRINT_TURN = 1e-12
WINDING_RAD = 1e-6

#: Symmetry and positive semi-definiteness of inertia matrices, relative to
#: 1 + max |I| (kg m^2).
INERTIA_REL = 1e-12

# --- motion ---------------------------------------------------------------------------
#: A redundancy-resolution scale ``s >= 1 - SCALE_ONE`` counts as the whole twist
#: (dimensionless).
SCALE_ONE = 1e-9

#: Smallest joint-rate limit used to normalise rates (m/s or rad/s): guards a zero limit.
RATE_FLOOR = 1e-12

#: Equality-row component (dimensionless, rows are unit) below which a twist axis lies in
#: the span of a navigation-mode twist set.
SPAN_TOL = 1e-9

# --- lift certificate -----------------------------------------------------------------
#: Branch-and-bound stops refining a cell once its upper bound is within LIFT_RTOL * t_max
#: of the incumbent (dimensionless): the certified bound is then at most that much above
#: the true maximum per cable.
LIFT_RTOL = 1e-5

#: The certificate refutes only when the bound falls short of the required force by more
#: than REFUTE_REL times the weight (dimensionless): guards round-off at the boundary.
REFUTE_REL = 1e-6

# --- cable interference ----------------------------------------------------------------
#: Length along each cable from an anchor it shares with another cable (a common exit
#: eyelet or attachment ring) over which the two are in contact by design, m. Beyond it
#: the pair interferes like any other (closest distance below the cable diameter); two
#: cables leaving one anchor at angle theta then interfere iff 2 ANCHOR_LENGTH sin(theta/2)
#: < min_distance, e.g. below 5.7 deg for 2 mm cables. 20 mm is the size of a typical
#: eyelet or swivel ring of 1-5 mm cables (not from the papers: an assumption).
ANCHOR_LENGTH = 0.02

# --- wrench closure -------------------------------------------------------------------
#: A pose has wrench closure when the most balanced self-stress ``W t = 0`` with
#: ``max t = 1`` has ``min t > CLOSURE_TOL`` (dimensionless): far above HiGHS's 1e-7
#: feasibility tolerance, far below any usable pretension ratio.
CLOSURE_TOL = 1e-6


# ==============================================================================
# The moving robot: CDPR forward kinematics, dynamics and control simulation (SI units).
# ==============================================================================

#: FK converged when the largest cable-length residual is below this, m. Far below the
#: 1e-9 m round-trip promise, and ~1e4 ulp of a 5 m length, so Gauss-Newton reaches it.
FK_RESIDUAL_TOL = 1e-11

#: FK keeps iterating until the length residual or the step is below this, m: ~30 ulp of a
#: 5 m length, so the pose is as exact as float64 allows (the success test stays
#: FK_RESIDUAL_TOL).
FK_POLISH_TOL = 1e-14

#: Two FK solutions are the same when their positions differ by less than this, m, and their
#: rotations by less than this many rad: well above the converged precision, far below any
#: geometrically distinct assembly mode.
FK_SAME_SOLUTION = 1e-6

#: Gauss-Newton iterations before FK reports "not_converged" (quadratic convergence needs ~6
#: from a start in the basin; extra ones let Levenberg damping recover a poor start).
FK_MAX_ITER = 60

#: Elastic static equilibrium converged when the force residual is below this, N (and N m):
#: 1e-9 of the FASTKIT 45 N limit, so the pose it implies is exact to ~1e-12 m.
EQUILIBRIUM_FORCE_TOL = 1e-8

#: Explicit (semi-implicit Euler) stability: the integrator step h must satisfy
#: omega_max * h <= this, rad. The method is stable for omega h < 2; 1.0 keeps the
#: period-elongation error below ~4 % on the stiffest mode.
STABILITY_OMEGA_H = 1.0

#: Width of the tanh regularisation of the gearbox loss's direction (plant) and of the smooth
#: friction model the controllers compensate and the tension estimate inverts, motor side,
#: rad/s (the plant's rotor friction itself is set-valued: it sticks, see
#: taut.cdpr.control.dynamics). 1 rad/s is 0.4 % of FASTKIT's 250 rad/s speed limit.
FRICTION_SPEED_WIDTH = 1.0

#: A simulated platform has diverged when its position leaves the frame box by more than
#: this, m (half a metre outside the frame is no longer a cable robot).
DIVERGENCE_MARGIN = 0.5

#: A cable counts as slack below ``t_min - EVENT_TENSION_TOL`` and over-tensioned above
#: ``t_max + EVENT_TENSION_TOL``, N: far below any physically meaningful violation, above the
#: rounding of the closed-form tension distribution.
EVENT_TENSION_TOL = 1e-6

#: Velocity a reference CSV may imply at most, m/s and rad/s: beyond it the file is
#: almost certainly in mm or degrees.
MAX_REFERENCE_SPEED = 20.0

# --- formerly inline thresholds (issue 10: one home per core) ---------------------------
#: Relative threshold (times |d1|^2 |d2|^2) on the determinant of the closest-point system
#: of two segments below which they count as parallel (interference). Dimensionless;
#: 1e-14 is ~100 ulp of the product, so only numerically parallel pairs take the fallback.
SEGMENT_PARALLEL = 1e-14

#: Slack (control steps) subtracted from ``duration * rate`` before rounding up, so that a
#: duration that is a whole number of steps up to round-off does not get one step more.
STEP_COUNT_SLACK = 1e-9

#: Forward-difference step of the rest-state Newton solve of the plant (m for the CoM,
#: rad for the rotation): ~sqrt(float64 eps) times the ~1 m / 1 rad scales, the usual
#: balance of truncation and round-off error.
EQUILIBRIUM_FD_STEP = 1e-7

#: ``ftol`` of SciPy's SLSQP in the tension QP and the redundancy resolution (relative
#: change of the objective, dimensionless): tight enough that the polish step, not the
#: optimiser, sets the final accuracy.
SLSQP_FTOL = 1e-12

#: A torque counts as saturated at ``|tau| >= limit * (1 - SATURATION_REL)``
#: (dimensionless): the controller clips at the limit exactly, this absorbs round-off.
SATURATION_REL = 1e-12

#: Rotation angle (rad) below which the SO(3) exponential uses its Taylor series (the
#: closed form divides by the angle); at 1e-8 rad the series' first neglected term is
#: ~1e-33. The compiled kernel tests the squared angle against SO3_TAYLOR_SQ (rad^2):
#: below it the 4-term series has error < th^6 / 5040 < 1e-22.
SO3_SMALL_ANGLE = 1e-8
SO3_TAYLOR_SQ = 1e-6

#: Levenberg-Marquardt damping of the cable forward kinematics (dimensionless, relative
#: to the Gauss-Newton matrix scale of cable lengths in m): start, floor and ceiling. The
#: start is near Gauss-Newton (good starts converge quadratically); the bounds keep the
#: damping from under- or overflowing over the iterations (/10 on success, x10 on failure).
FK_DAMPING_START = 1e-6
FK_DAMPING_MIN = 1e-12
FK_DAMPING_MAX = 1e8

#: Default slack of :func:`taut.cdpr.resolve_redundancy` on joint limits and the twist
#: residual (m/s, rad/s): ~1e-9 of the FASTKIT rates, far above LP round-off.
REDUNDANCY_TOL = 1e-9

#: Weight of the cable rates relative to the base rates in the ``least_base`` objective of
#: :func:`taut.cdpr.resolve_redundancy` (dimensionless; its square, 1e-6, multiplies the
#: cables' squared normalised rates): small, so bases move only when the cables alone
#: cannot produce the twist, yet large enough to make the minimiser unique.
LEAST_BASE_CABLE_WEIGHT = 1e-3

#: Two consecutive waypoints closer than this (m) repeat each other (a zero-length segment
#: has no direction): far below any positioning accuracy of a cable robot.
WAYPOINT_SAME = 1e-9

#: L-BFGS-B tolerances of the lift certificate's inner maximisation (relative objective
#: change, projected gradient in N): tight, because the certificate compares the maximum
#: with the weight to REFUTE_REL.
LIFT_FTOL = 1e-15
LIFT_GTOL = 1e-12

#: Width (m or rad) given to a search coordinate whose half-range is zero (differential
#: evolution needs lower < upper): the coordinate is effectively fixed.
FIXED_COORD_WIDTH = 1e-12

#: Deployment search tolerances: differential evolution's relative population ``tol``, and
#: Nelder-Mead's ``xatol`` (m and rad: 0.1 mm is below any base positioning accuracy) and
#: ``fatol`` (the capacity margin's mixed N / N m units).
DEPLOY_DE_TOL = 1e-6
DEPLOY_NM_XATOL = 1e-4
DEPLOY_NM_FATOL = 1e-6

#: Tension slack (N) before interpolated reference tensions count as outside the limits
#: and are recomputed exactly (simulation setup): the same size as EVENT_TENSION_TOL.
INTERP_TENSION_TOL = 1e-6

#: Default ``certificate_tol`` of :func:`taut.cdpr.tallest_workspace` (m): the height
#: resolution of the certified upper limit.
TALLEST_CERTIFICATE_TOL = 1e-3

#: Gauss-Newton iterations of the controller's pose estimate from measured cable lengths
#: (simulation with encoder sensing): per control step, warm-started from the previous
#: estimate (the platform moves <= 2 mm per 1 ms step, where Gauss-Newton converges
#: quadratically: two iterations leave < 1e-9 m), and at the first step from the reference.
SENSING_FK_ITERATIONS = 2
SENSING_FK_FIRST_ITERATIONS = 30

# --- mission: navigation and sites (issue 30) -------------------------------------------
#: Absolute tolerance of the navigation verifier's and the sites' clearance checks (m):
#: shapely distances of metre-sized polygons are exact to ~1e-12 m; 1e-9 m forgives their
#: round-off and nothing physical.
NAV_TOL = 1e-9

#: Bisections of the navigation verifier before an interval counts as not proved. Each
#: halves the corner travel of the interval; 12 reach 1/4096 of a 0.1 s sample's travel
#: (about 12 um at 0.5 m/s), far below any clearance a route is planned with.
NAV_PROOF_DEPTH = 12

#: Slack of the time-optimal path's rest test (taut.cdpr.mission.timing), m/s^2: the
#: platform can rest at a grid point when the LP's acceleration bounds straddle zero
#: within this (HiGHS solves to ~1e-9 feasibility).
REST_ACCEL_SLACK = 1e-9
