"""Wrench and twist sets: the available wrench set, wrench closure, the available twist set, and the batched polytopes and zonotopes behind them."""
