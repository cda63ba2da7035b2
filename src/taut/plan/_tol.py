"""Every numerical threshold of the planner, with its unit and why it has its value.

Lengths in metres, angles in radians, times in seconds (the planner's units). Thresholds
that change answers are also documented keyword arguments of the functions using them;
these are their defaults.
"""

from __future__ import annotations

#: Absolute tolerance of the geometric checks of a plan (clearances, heights), m: far
#: below any physical length of the problem, above round-off of shapely distances.
GEOMETRY_TOL = 1e-6
#: Relative tolerance (times the sheet size) for "the object is where the plan says":
#: the sheet solvers converge to ~1e-9 of the sheet size.
OBJECT_RTOL = 1e-6
#: Relative tolerance (times the sheet size) for "two sample formations differ by a rigid
#: motion" (then the rest state is carried rigidly and cannot jump).
RIGID_RTOL = 1e-9
#: Default ``sheet_margin``, m: each robot pair stays this far inside its sheet distance.
#: Two robots each within 5 mm of their planned position change their distance by at most
#: 10 mm, so with this margin 5 mm of position error never tears the sheet.
SHEET_MARGIN = 0.01
#: Default robot position accuracy the margin is sized for, m.
POSITION_ACCURACY = 0.005
#: Default largest object step between verification samples, m ("a few mm").
MAX_OBJECT_STEP = 0.005
#: Clearance to spare at every pose of a motion the SE(2) search accepts, m: the motion
#: check (conservative advancement, :mod:`taut.plan._se2_kernel`) proves every pose of the
#: continuous motion keeps the rules by at least this much; far below the robots'
#: position accuracy, above round-off of the distances.
MOTION_MARGIN = 1e-3
#: Least robot motion per step of the motion check, m: a pose with less than
#: ``MOTION_MARGIN + MIN_ADVANCE`` of clearance fails the motion, so a check never takes
#: more than its length over this many steps.
MIN_ADVANCE = 1e-3
#: Clearance a state of the SE(2) search keeps, m (a motion through it can advance).
STATE_CLEARANCE = MOTION_MARGIN + MIN_ADVANCE
#: Largest robot displacement between the samples of a returned plan, m.
SAMPLE_STEP = 0.02
#: Largest robot displacement between samples during a formation change, m (the model is
#: re-solved at each; the verifier refines further where the object moves faster).
REFORM_STEP = 0.002
#: Turns below this are treated as none, rad.
ANGLE_TOL = 1e-12
#: Graph weights below this are raised to it (scipy drops explicit zeros), s.
MIN_EDGE_COST = 1e-12
#: Relative tolerance on plan durations when comparing candidates.
DURATION_RTOL = 1e-9
#: SLSQP feasibility tolerance of the formation optimiser (normalised units).
FORMATION_FEAS_TOL = 1e-7
#: Forward-kinematics match of an optimised formation (times the sheet size).
FORMATION_MATCH_RTOL = 1e-6
#: Floor under squared lengths before a square root or a division (normalised units):
#: keeps the eq. (10) radial distances and the eq. (14) gap term finite at degenerate
#: iterates of the optimiser.
SQUARE_FLOOR = 1e-12
#: Slack (normalised units) by which every cable must be taut and every pair inside its
#: sheet distance in the optimiser (strict versions of the constraints of eq. 15c).
STRICT_SLACK = 1e-6
#: Least reduced-Hessian curvature accepted as "stable" by the optimiser (normalised).
MIN_CURVATURE = 1e-4
#: Crossing segments are extended this fraction of the disc radius beyond tangency (m/m),
#: so the disc is strictly clear of the crossed obstacle at their ends.
CROSSING_OVERSHOOT = 1e-6
#: Reflex vertices are taken from a region grown by this fraction of the disc radius, so
#: roadmap vertices lie strictly inside the free region.
VERTEX_INSET = 1e-4
#: Two roadmap points closer than this are the same point (a formation change), m.
SAME_POINT = 1e-12
#: Turns within this of the smallest are equally good (Algorithm 2 side choice), rad.
TURN_TIE = 1e-9
#: SLSQP function tolerance of the formation optimiser (its cost, normalised units); the
#: optimum is then checked by forward kinematics to FORMATION_MATCH_RTOL.
FORMATION_FTOL = 1e-10
#: Floor under the disc radius used as the rotation weight of OMPL's SE(2) distance
#: (|dp| + R |dpsi|), m: a point-sized disc still gives rotation a positive weight.
MIN_ROTATION_WEIGHT = 1e-9
#: Precision of shapely's maximum inscribed circle of the free space, as a fraction of the
#: square root of its area (m/m): ``World.width`` is only a scale that normalises and bounds
#: the passable-area term of eq. (13), so 0.1 % of it is ample.
INSCRIBED_CIRCLE_RTOL = 1e-3
#: The optimised narrow formation joins the formation library only when its narrowest width
#: is at least this much below the compact formation's, m: one barely narrower opens no
#: passage the compact one cannot pass and only adds a formation to search with.
NARROWER_BY = 0.01
