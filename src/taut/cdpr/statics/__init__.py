"""Statics of cable robots: tension distribution, tipping and sliding of mobile bases."""
