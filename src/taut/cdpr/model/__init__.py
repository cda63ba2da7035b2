"""Validated, immutable models of cable robots: the robot and its parts (bases, platform, payload, cables) and ground footprints."""
