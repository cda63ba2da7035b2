"""Forward kinematics of sheet teams: the front end, its engines (numpy, compiled, the paper's Algorithm 1) and its results."""
