"""The SE(2) search over a formation library: validity of a pose, the lattice A*, RRT-Connect, OMPL, and the timed samples of its motion."""
