"""Tolerances and numerical settings of taut.physics, each with its unit and reason.

Lengths marked "spacings" are multiples of the mesh spacing; the simulation itself runs in
metres with the sheet scaled to :data:`SIM_DIAMETER` (statics of an inextensible, massless
sheet are scale-free, so answers are scaled back to the scenario's unit).
"""

#: Interior lattice nodes keep this far from every side (spacings): closer ones would
#: make sliver triangles against the boundary nodes.
INTERIOR_MARGIN = 0.45
#: A third node this close to a pair's segment (spacings) makes the pair redundant.
ON_SEGMENT = 0.05
#: Nodes closer than this to the contact node are dropped (spacings).
CONTACT_CLEARANCE = 0.5
#: A contact point this close to a corner (spacings) is that corner.
SNAP = 0.05
#: Triangles with a smaller area (spacings squared) are dropped (collinear boundary nodes).
SLIVER = 1e-6
#: Node pairs at most this far apart in the flat sheet (spacings) get an inextensibility
#: tendon.
TENDON_REACH = 4.5
#: Most tendons a sheet model may have (issue 24), counted before it is built
#: (:func:`taut.physics._mesh.sheet_model_size`: pairs within ``TENDON_REACH`` plus the
#: corner tendons; an upper bound, 0.6-1x the built count). Peak memory of ``taut
#: physics`` is ~0.15 GB plus ~3.3-4.2 kB a counted tendon over its first states, whether
#: robots (corner tendons) or the mesh dominate, and creeps up over later states (370
#: robots, mesh 10: 0.79 GB after 90 s, 0.98 GB after 300 s), hence the margin below
#: 1 GB. Measured (`/usr/bin/time`, peak RSS, regular n-gon teams, runs capped at 90-120
#: s, i.e. the first 1-6 states; load 2-3.5): 300 robots mesh 10 (135,283 tendons)
#: 0.67 GB; 12 robots mesh 60 (146,588) 0.70 GB; 350 robots mesh 10 (177,857) 0.80 GB;
#: 370 robots mesh 10 (196,065) 0.79 GB; 400 robots mesh 10 (225,833) 0.89 GB; 30 robots
#: mesh 58 (198,884) 0.87 GB; 30 robots mesh 60 (212,014) 0.91 GB; before the limit, 600
#: robots mesh 10 (475,927) 1.94 GB and 1,000 robots over 3 GB. Near the limit, longer:
#: 310 robots mesh 11 (148,688) 0.84 GB over 240 s (15 of 318 states, ~15 s a state);
#: 12 robots mesh 60 (146,588) 0.87 GB over 420 s (1 of 15 states: minutes a state).
MAX_SHEET_TENDONS = 150_000

#: The sheet's largest vertex distance in the simulation, m (the scenario is scaled to it).
SIM_DIAMETER = 1.0
#: Time step, s (the recipe: about 4 ms with implicitfast and Newton).
TIMESTEP = 0.004
#: Node mass per squared time step, kg/s^2: node mass 3 g at 4 ms for a ball of
#: ``BALL_MASS``. Kept constant when the step changes so the constraint impedance (set by
#: mass / dt^2) stays the same; scaled with the ball's mass so the motion does not depend
#: on the load. It also keeps the soft limits' stretch under a given force (set by the
#: time constant squared over the node mass) when the step changes: halving the step
#: alone does not stiffen them (examples/physics/stiffness.py).
NODE_MASS_PER_DT2 = 0.003 / 0.004 ** 2
#: Damping time constant of the nodes' slide joints, s (light: much slower than a step).
NODE_DAMPING_TIME = 0.02
#: Ball mass when the team has no object mass, kg. FK of the massless inextensible sheet
#: does not depend on the mass; with node masses scaled to the ball's, neither does the
#: simulated motion (every force scales with the load: MuJoCo's soft constraints act in
#: acceleration space).
BALL_MASS = 1.0
#: Damping time constant of the ball's free joint, s.
BALL_DAMPING_TIME = 0.15
#: Soft-constraint reference (time constant s, damping ratio) of tendon limits and contacts:
#: stiff (two time steps) and critically damped.
SOLREF = (2 * TIMESTEP, 1.0)
#: Soft-constraint impedance (dmin, dmax, width m, midpoint, power): nearly hard.
SOLIMP = (0.99, 0.9999, 0.001, 0.5, 2.0)
#: Flex collision radius as a fraction of the spacing (0.02 let a small released ball
#: tunnel through the sheet when it rolled away fast). The objects that fell through in
#: issue 31 did not tunnel: they were put outside the pocket a point load folds (see
#: ``_release_over`` in sheet.py); with the ball held while the sheet forms, no release
#: left the sheet on 65 states of 22 teams (examples/physics/README.md).
FLEX_RADIUS = 0.05
#: Default ball radius, spacings: small, so the ball rests where a point would (a ball of
#: radius r in a cone of taut cables sits about r (1/sin(half-angle) - 1) too high).
BALL_RADIUS = 0.05
#: Shrink factor of the flat starting copy (its tendons start slack).
START_SHRINK = 0.98
#: Corners are ramped from the flat copy to the robots over this time, s (gravity off).
RAMP_TIME = 0.3
#: Settled when the ball and every node move slower than this, m/s (sim scale).
SETTLE_SPEED = 2e-3
#: Stricter rest criterion for the tied phase, m/s: the sheet's pull on the contact node
#: (which decides "held") is read there, and residual motion at 2e-3 m/s left pulls of up
#: to 0.2 mg at well-conditioned stable states (0.002 mg at 2e-4).
TIED_SETTLE_SPEED = 2e-4
#: A node farther than this from every robot's holding point, m (sim scale, two sheet
#: diameters), makes a run ``diverged``: an inextensible sheet keeps every point within
#: one diameter (its flat distance) of a held corner.
ESCAPE_DISTANCE = 2.0 * SIM_DIAMETER
#: Settling is checked every this many seconds of simulated time.
CHECK_INTERVAL = 0.1
#: Longest simulated settling time of one phase, s.
MAX_SETTLE_TIME = 6.0
#: Longest simulated time after release, s: only the released ball's rest position comes
#: from it (a ball rolling off a non-equilibrium can run for long: one released near a
#: corner of a 3-robot sheet, 41 mm above the lowest state, rolled along the valley for
#: 4.3 s before it came to rest, tests/physics/test_release.py).
RELEASE_TIME = 6.0
#: The object counts as held when the sheet's net sideways pull on it at the contact point
#: is at most this fraction of its weight, as the check reads the pull with corner tendons
#: (the default): the rigid statics of the corner tendons the simulation has taut
#: (``sliding_force`` in _run.py). Measured on issue 31's 30-team sample (seed 2026, mesh
#: 10, 86 states; examples/physics/README.md, "Hold resolution"): the 47 stable states
#: read at most 1.1e-13, the 39 non-equilibria at least 0.00103 (team 13's {1,5,7,8};
#: each reads taut's own pull to 3 digits where the simulation has taut's cables taut,
#: more where it has fewer). 1e-4 leaves a factor of 10 below the smallest
#: non-equilibrium and 1e9 above the stable states; a non-equilibrium pulled by less
#: than 1e-4 of the weight (none in the sample) would be held.
HOLD_FRACTION = 1e-4
#: The same tolerance when the pull is read from MuJoCo's tendon forces (without corner
#: tendons, ``corner_tendons=False``): those forces come from soft limits whose stretch
#: grows with the force and moves the contact node 0.4-2 mm off the point where the
#: cables hang, so stable states read up to 0.05 of the weight at any mesh (0.01-0.05 on
#: the FK paper's Example 1, 0.039-0.051 on the 30-team sample from mesh 10 to 28) and
#: non-equilibria pulled by less are not told apart from them.
FORCE_HOLD_FRACTION = 0.05
#: Weight of the force-balance rows (dimensionless, both sides in N) when the least pull of
#: a statically indeterminate contact node is found by non-negative least squares
#: (``sliding_force`` in _run.py): the balance then holds to about 1e-6 of the weight
#: while the pull is minimised.
BALANCE_WEIGHT = 1e3
#: Unbalanced resultant (fraction of the weight) above which taut cables cannot carry the
#: weight with non-negative tensions: a balance that can be met leaves at most
#: |pull| / BALANCE_WEIGHT^2 (about 1e-6), a weight outside the cables' cone far more.
BALANCE_SLACK = 1e-4
#: Stopping tolerance of the bounded least squares behind that pull (relative change of
#: the cost): far below any pull the checks compare.
LSQ_TOL = 1e-14
#: A cable counts as taut at the rigid point load when it is at least this fraction of its
#: length short of slack (``_taut_cable_pull`` in _run.py): above the lowest point's
#: accuracy (SLSQP, ``POINT_LOAD_FTOL``), far below the slack of a cable that the
#: simulation has at its limit but that is taut only at a non-equilibrium 0.35 mm away
#: (1.1e-4 of its length at team 9's stable {1,4,6} and team 13's {1,5,7} of issue 31's
#: sample: 0.037 and 0.046 mm).
TAUT_LENGTH = 1e-7
#: Samples along the straight path between two rest states when the rim of a basin is
#: bounded (``barrier`` in _statics.py): 40 steps of the contact point.
BARRIER_SAMPLES = 41
#: SLSQP's tolerance on the object's height (scenario units) in the lowest point load.
POINT_LOAD_FTOL = 1e-12

# --- mobile cable robot (taut.physics.replay_tipping) ---
#: Time step of the cable-robot simulation, s.
CDPR_TIMESTEP = 0.002
#: Simulated time after which the bases are judged, s (a base tips within a fraction of
#: a second when its tipping moment is clearly positive).
CDPR_DURATION = 1.0
#: Coulomb friction coefficient of wheels and feet on the floor (rubber on concrete ~0.6).
FLOOR_FRICTION = 0.6
#: Radius of the contact spheres at the support-polygon vertices, m.
FOOT_RADIUS = 0.02
#: A base whose vertical axis tilts by more than this has tipped, degrees.
TIP_ANGLE = 1.0
#: A base whose origin moves horizontally by more than this (without tipping) slid, m.
SLIDE_DISTANCE = 0.005
#: Damping time constant of the platform's free joint, s: slows the drift of a platform
#: under constant tensions (unstable for most poses) while the bases are watched.
PLATFORM_DAMPING_TIME = 0.05

# --- formerly inline thresholds (issue 10: one home per core) ---------------------------
#: |2D cross product| (scenario units squared, scaled mesh) below which a sheet triangle
#: is degenerate in plan view and skipped by the vertical ray cast: far below any triangle
#: of a mesh with SPACING-sized elements.
FLAT_TRIANGLE = 1e-15
#: Barycentric slack (dimensionless) of the vertical ray cast, so a point on a shared edge
#: is inside both triangles rather than neither.
BARYCENTRIC_SLACK = 1e-9
#: Height slack (scenario units) of "the sheet point lies below the query point".
BELOW_SLACK = 1e-12
#: Segment parameter slack (dimensionless): nodes within 1e-9 of a segment's ends are its
#: endpoints, not interior points.
SEGMENT_END = 1e-9
#: Floor on the platform mass (kg) and on its inertia diagonal (kg m^2) of the MuJoCo
#: model: MuJoCo rejects a massless free body; 1e-6 is negligible next to FASTKIT's 12 kg.
MIN_BODY_MASS = 1e-6
MIN_BODY_INERTIA = 1e-6
