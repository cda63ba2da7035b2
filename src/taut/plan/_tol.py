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
#: check (conservative advancement, :mod:`taut.plan._kernels.clearance`) proves every pose of the
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
#: Most bisections of one sample interval when proving the geometric rules between samples
#: (:mod:`taut.plan.checks._geometry`), a count: a piece is proved when its ends' slacks
#: (m, the tolerance ``GEOMETRY_TOL`` included) add up to its robot travel, so an interval
#: of ``SAMPLE_STEP`` still unproved after 16 halvings (pieces of 0.3 um) comes within
#: 0.3 um of breaking a rule even with the tolerance: it is refused as unproved.
PROOF_DEPTH = 16
#: Most poses that proof inserts in all (and that the search for the least clearance
#: measures), a count: bounds its time to about two seconds for 8 robots and 4 obstacles
#: (~40 us a pose). A plan keeping 1 mm of slack needs about 20 poses per 2 cm interval
#: where it keeps so little; one needing more keeps micrometres over a long stretch.
MAX_PROOF_POSES = 50_000
#: Squeezed formations (:mod:`taut.plan.formations._squeezed`): the object rests at least this much
#: above the ground safety height ``team.height_safety``, m, so that the robots' position
#: error (``POSITION_ACCURACY``) does not lower it under the safety height at once.
SQUEEZE_HEIGHT_MARGIN = 5e-3
#: A slack cable of a squeezed formation is at least this much shorter than the sheet
#: between its vertex and the contact point, m: far below the robots' position accuracy
#: (the design is still checked by forward kinematics), above round-off, so the taut set the
#: optimiser designs is the one forward kinematics finds.
SQUEEZE_SLACK = 1e-3
#: Forward-difference step of the squeezed-formation program's Jacobian (normalised units:
#: times the sheet size): about the square root of float64's epsilon times the O(1)
#: normalised coordinates.
SQUEEZE_FD_STEP = 1e-7
#: A linear system of the squeezed-formation program (the rest state of a taut set, in
#: normalised units with O(1) entries) with a smaller determinant is taken as singular.
SQUEEZE_SINGULAR = 1e-12
#: Margin by which a cut of the squeezed-formation program removes an unwanted stable rest
#: state (a weight or curvature this far below zero, or a slack cable this far over its
#: length, in normalised units): far above the FK solver's tolerances (~1e-9).
SQUEEZE_CUT_MARGIN = 1e-3
#: Minimising the width of a squeezed formation stops when it is within this of the lower
#: bound ``2 * inset`` (any polygon holding a disc of radius ``inset`` is at least that
#: wide), m: on the seed-2024 suite the last 3 cm cost several times the search's time, and
#: the team is then narrower than its robots' footprints plus two clearances (~0.5 m).
SQUEEZE_WIDTH_TOL = 3e-2
#: Accuracy of the least robot clearance a verification reports, m: it is a lower bound
#: within this of the continuous motion's least clearance, so it does not depend on how
#: finely the motion is sampled (far below the robots' position accuracy; a few
#: bisections of a turning interval reach it).
CLEARANCE_ACCURACY = 1e-7
#: Room a squeezed formation leaves in the passage it is designed for, m (its width is
#: the passage less two clearances and this): the lattice and the sampling search need
#: some room to find a way through, and robots some room for their position error.
SQUEEZE_ROOM = 0.06
#: Farthest the object of a squeezed formation may move when every robot is off by up to
#: ``POSITION_ACCURACY``, m (:mod:`taut.plan.formations._squeeze_robust`: about the 90th percentile of
#: what the all-taut formations of the seed-2024 suite move).
SQUEEZE_MAX_SHIFT = 0.05
#: Weight of the time spent in a squeezed formation in the lattice search's cost (1: none):
#: the paper's all-taut formations share the load between every robot, so the search keeps
#: them wherever they fit and squeezes only where a passage needs it.
SQUEEZED_WEIGHT = 1.5
#: Least curvature of the potential at a squeezed formation's rest state (the reduced
#: Hessian's smallest eigenvalue, normalised by the sheet size): a stiffer pocket moves the
#: object less under the robots' position error. With the threshold of the all-taut
#: optimiser (``MIN_CURVATURE``) the search found pockets so flat that most failed the
#: robustness check; with 0.05 every seed-2024 scenario needing a squeezed formation gets
#: one that passes it (0.01 and 0.2 leave some without).
SQUEEZE_MIN_CURVATURE = 0.05

# ---------------------------------------------------------------- accepted ranges
# Each option's accepted range, defined once (validated by :mod:`taut.plan._options`, and
# for ``sheet_margin`` by every function taking one).

#: Largest ``sheet_margin``, m: a margin is an allowance for the robots' position error
#: (millimetres to centimetres); a metre is far beyond any robot's.
MAX_SHEET_MARGIN_M = 1.0
#: Largest ``time_budget`` (the optional wall-clock cap of each search), s: one hour.
MAX_TIME_BUDGET_S = 3600.0
#: Largest ``iterations`` (samples per RRT-Connect run; the whole search draws
#: ``taut.plan.se2._search.TOTAL_RUNS`` times this): a few minutes of search per run.
MAX_ITERATIONS = 200_000
#: Accepted lattice ``spacing``, m: finer than the robots' position accuracy
#: (``_tol.POSITION_ACCURACY``) buys nothing, and the lattice is bounded by its node count.
MIN_SPACING_M = 0.005
#: Coarser than a metre, the lattice misses every passage a team of metre-sized sheets
#: could use.
MAX_SPACING_M = 1.0
#: Largest robot position error ``sigma`` of the robustness analysis, m.
MAX_POSITION_ERROR_M = 1.0
#: Most Monte Carlo trials of the robustness analysis (each replays the whole plan).
MAX_TRIALS = 100_000
#: Largest ``correlation`` time of the robustness analysis's position error, s (one hour:
#: longer than any plan, so the error is then constant along it).
MAX_CORRELATION_S = 3600.0

# ---------------------------------------------------------------- executed trajectories
# Per-robot trajectories of a plan (:mod:`taut.plan.execution`).

#: Fastest any robot moves during a formation change, m/s: the planner's model is
#: quasi-static (the object is taken at rest at every instant), so changes are driven
#: slowly enough that the object settles. At 5 cm/s a robot moves 0.05 m in the ~1 s it
#: takes a metre-sized sheet's pendulum (period 2 pi sqrt(L / g) ~ 1.4-2 s) to swing once,
#: and the formation changes of the shipped plans move robots 0.1-0.5 m.
REFORM_MAX_SPEED = 0.05
#: A differential-drive robot whose direction of motion turns by more than this between
#: two samples stops (with the whole team) and turns in place, rad; smaller turns are
#: steered while moving (the heading changes linearly over the sample interval, so it is
#: never further than this from the direction of motion).
TURN_IN_PLACE = 0.1
#: Default largest yaw acceleration of a robot's trajectory, rad/s^2
#: (:func:`~taut.plan.execution.trajectories.robot_trajectories`' ``max_yaw_accel``): a
#: turn in place of pi/2 then takes at least sqrt(2 (pi/2) / 2) = 1.25 s, about what a
#: small differential-drive base (wheel torque, the sheet's pull) turns in.
MAX_YAW_ACCEL = 2.0
#: Rounds of :func:`~taut.plan.execution._timing.time_path`'s tightening (speeds of the
#: intervals next to a sample whose acceleration exceeds a limit are lowered each round).
TIMING_ROUNDS = 200
#: A robot moving less than this over a sample interval is standing still (its heading is
#: kept), m: a differential drive then slips sideways by at most this much.
STANDING_STILL = 1e-6
#: Largest accepted ``max_speed`` (m/s), ``max_yaw_rate`` (rad/s), ``max_accel`` (m/s^2),
#: ``max_yaw_accel`` (rad/s^2) and ``reform_speed`` (m/s) of a robot: far beyond any mobile robot's.
MAX_ROBOT_LIMIT = 100.0

# ---------------------------------------------------------------- feedback on the object
# The object-feedback controller and its simulation (:mod:`taut.plan.checks.feedback`).

#: Default standard deviation of the object measurement per axis, m (a camera or motion
#: capture tracking the object: about a millimetre).
MEASUREMENT_NOISE = 0.001
#: Default gain of the controller: the fraction of the measured object error the robots
#: correct per plan sample (an integrator; 0.5 at the plans' ~12 Hz samples settles in
#: a few tenths of a second, faster than the 1 s drift of the robot errors).
FEEDBACK_GAIN = 0.5
#: Default damping of the damped least squares (dimensionless, as the Jacobian): keeps
#: corrections along poorly controllable directions (the object's height, mostly) small.
FEEDBACK_DAMPING = 0.1
#: A correction step moves the robots by at most this fraction of the state's
#: ``taut_margin`` (Frobenius norm), so the linearisation's taut set is kept.
FEEDBACK_MARGIN_FRACTION = 0.5
#: Largest accepted measurement noise, m, and gain / damping (dimensionless).
MAX_MEASUREMENT_NOISE_M = 1.0
MAX_FEEDBACK_GAIN = 1.0
MAX_FEEDBACK_DAMPING = 10.0
#: Largest correction step of the object-feedback controller per robot and plan sample, m
#: (applied as this times sqrt(N) to the Frobenius norm over the robots): 3 mm per ~0.08 s
#: sample follows the robustness errors' drift (up to 10 mm/s) with room.
FEEDBACK_MAX_STEP = 0.003
#: Controller steps at the plan's first sample before the team moves off (the object is
#: lifted, measured and corrected first; at ~12 Hz about 1.7 s).
FEEDBACK_SETTLE = 20
#: Halvings of the object-feedback correction before it is dropped, when a commanded
#: robot pair would come closer to its sheet distance than the plan's own slack or
#: twice the robot error plus ``SHEET_MARGIN`` (whichever is less).
FEEDBACK_HALVINGS = 6
