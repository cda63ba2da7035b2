"""Quasi-static simulation of sheet teams: the whole-trajectory front end, the stepping simulator, branch following and the results."""
