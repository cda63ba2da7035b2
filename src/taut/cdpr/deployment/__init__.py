"""Deployment of mobile cable robots: where to park the bases, the lift certificate, the tallest workspace, a moving active base, and redundancy resolution."""
