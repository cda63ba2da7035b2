"""Inverse kinematics of sheet teams: the front end, the search, the proofs of infeasibility and the results."""
