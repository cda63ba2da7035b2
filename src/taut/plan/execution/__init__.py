"""Executing a plan: one time-parameterised trajectory per robot (position and heading) for
holonomic or differential-drive robots under speed, acceleration and yaw-rate limits, timed
along the plan's path and re-verified on the executed motion."""
