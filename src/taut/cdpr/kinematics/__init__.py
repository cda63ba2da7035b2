"""Kinematics of cable robots: cable geometry and the wrench matrix, forward kinematics from cable lengths, first-order (velocity) kinematics, operating modes, cable interference."""
