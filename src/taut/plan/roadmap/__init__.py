"""The roadmap planner of the planning paper (Sec. IV, Fig. 4): a global route of one formation and the local crossing motion (Algorithm 2)."""
