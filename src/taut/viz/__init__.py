"""Figures (matplotlib). Only the CLI and users import this package; solvers never do."""
