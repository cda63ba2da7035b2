"""Formations of a sheet team for planning: the optimal formation (planning paper eqs. 11-15), the squeezed one (some cables slack), and the library the SE(2) search uses."""
