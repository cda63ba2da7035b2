"""Compiled (numba) kernels of the planner: clearance of a pose and the lattice A*. Private."""
