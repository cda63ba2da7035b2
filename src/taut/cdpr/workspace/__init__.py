"""Workspaces over grids of poses: wrench-feasible, wrench-closure, and inside the exits box."""
