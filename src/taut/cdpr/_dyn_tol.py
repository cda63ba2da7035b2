"""Tolerances of the CDPR forward kinematics, dynamics and control simulation (one place).

Each constant carries its unit and the reason for its value. (The static CDPR analyses keep
theirs next to their code; these are the ones of the moving robot.)
"""

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

#: Width of the tanh regularisation of Coulomb and static friction, motor side, rad/s. Makes
#: friction a smooth function of speed (no sticking logic in an explicit integrator); its
#: slope tau_c / width stays below J / h for FASTKIT's rotor at 1 kHz (see winch docs).
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
