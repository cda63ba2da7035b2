"""The unit of every number in taut's JSON documents, said once (docs/conventions.md, Units).

Every JSON document a ``taut ... --json`` command prints (and the ``--out`` files of
``taut plan`` and ``taut cdpr simulate``) says the unit of each of its numbers in one of
three ways:

* the key carries its unit as a suffix (``time_s``, ``duration_s``, ``object_m``,
  ``max_speed_mps``, ``min_tension_margin_N``, ``pose_m_rad``; :data:`SUFFIXES`) --
  the form of keys the writers add;
* the key is a result's field name, kept as in Python, and the document's top-level
  ``"units"`` object maps its dotted path to the unit (``"equilibria.tensions": "N"``;
  lists are not part of a path; a path covers every key below it). Sheet lengths are in
  the scenario's unit, which a key suffix cannot name: the ``units`` object says it
  (``"mm"`` from the scenario's ``units:``, ``"sheet units"`` when it gives none);
* the key is in :data:`UNITLESS`: a count, index, flag, ratio, fraction or probability.

``tests/io/test_json_units.py`` runs every command, walks the JSON and fails on a number
that none of the three covers, and on a ``units`` entry that names no key.
"""

from __future__ import annotations

from typing import Mapping

#: Key suffixes that name a unit (case-sensitive; the writers' spelling).
SUFFIXES = ("_s", "_m", "_mm", "_rad", "_N", "_Nm", "_mps", "_mps2", "_radps", "_m_rad",
            "_kg", "_Hz")

#: Keys whose numbers have no unit, wherever they appear, with the reason.
UNITLESS: Mapping[str, str] = {
    # indices (0-based in JSON, docs/conventions.md) and 1-based site numbers
    "taut": "robot indices of the taut set", "taut_before": "robot indices",
    "taut_after": "robot indices", "step": "time-step index", "index": "cable or edge index",
    "site": "site number (1-based)", "reached": "robot indices of the state reached",
    # counts
    "dof": "degrees of freedom", "grid": "grid points per axis", "points": "count",
    "feasible_points": "count", "evaluations": "count", "facets": "count",
    "trials": "count", "mesh": "mesh cells per side", "turns_in_place": "count",
    "combinations": "count", "form_closure": "count", "cqp_feasible": "count",
    "height_feasible": "count", "force_closure": "count",
    # 0/1 flags per grid point
    "feasible": "0/1 per grid point", "feasible_tipping": "0/1 per grid point",
    "closure": "0/1 per grid point",
    # ratios, fractions, probabilities
    "weights": "barycentric weights of the contact point (sum 1)",
    "fraction": "fraction of the time step", "speedup": "ratio of two times",
    "coverage": "fraction of grid points", "coverage_tipping": "fraction of grid points",
    "coverage_sliding": "fraction of grid points",
    "coverage_inside_exits": "fraction of grid points",
    "coverage_closure": "fraction of grid points",
    "sliding": "fraction of the object's weight",
    "predicted_sliding": "fraction of the object's weight",
    "hold_tolerance": "fraction of the object's weight",
    "tear_probability": "probability", "drop_probability": "probability",
    "contact_probability": "probability", "collision_probability": "probability",
    "failure_probability": "probability", "unsafe_probability": "probability",
    # unit normals
    "H": "unit facet normals of the wrench set (H w <= h)",
}

#: Placeholder for the sheet's length unit in :data:`DOCUMENTS`.
SHEET = "<sheet>"
_POSE = "m (x, y, z), rad (roll, pitch, yaw)"
_WRENCH = "N (fx, fy, fz), N m (mx, my, mz)"
_TWIST = "m/s (vx, vy, vz), rad/s (wx, wy, wz)"

#: Per document kind: dotted key path -> unit of every number under it.
DOCUMENTS: Mapping[str, Mapping[str, str]] = {
    "fk": {"equilibria.object": SHEET, "equilibria.contact": SHEET,
           "equilibria.tensions": "N", "equilibria.cable_lengths": SHEET},
    "ik": {"formation": SHEET, "object": SHEET, "contact": SHEET, "angles": "rad",
           "tensions": "N", "cable_lengths": SHEET, "curvature": f"1/{SHEET}",
           "spacing": SHEET},
    "simulation": {"time": "s", "object": SHEET, "contact": SHEET, "tensions": "N",
                   "events.object_before": SHEET, "events.object_after": SHEET,
                   "events.drop": SHEET},
    "plan": {"times": "s", "robots": "m", "object": "m", "path_length": "m",
             "duration": "s", "sheet_margin": "m", "margins": "m"},
    "robustness": {"sigma": "m", "worst_extension": "m", "worst_height_margin": "m",
                   "worst_clearance": "m"},
    "tensions": {"pose": _POSE, "residual": "N, N m (max |W t + w_e|)", "tensions": "N",
                 "tipping_moments": "N m"},
    "wrench_set": {"pose": _POSE,
                   **{f"{mode}.{key}": unit
                      for mode in ("tension_limits_only", "with_tipping")
                      for key, unit in (("capacity_positive", _WRENCH),
                                        ("capacity_negative", _WRENCH),
                                        ("capacity_margin", "N / N m (mixed)"),
                                        ("halfspaces.h", "N / N m (per facet)"))}},
    "workspace": {"box": "m", "orientations": "rad (roll, pitch, yaw)"},
    "twist_set": {"pose": _POSE, "positive": _TWIST, "negative": _TWIST,
                  "bases_fixed": _TWIST},
    "deployment": {"workspace": "m", "base_poses": "m (x, y), rad (yaw)",
                   "margin": "N / N m (mixed)", "twist_margin": "m/s, rad/s (mixed)",
                   "lift_bound.height": "m", "lift_bound.bound": "N",
                   "lift_bound.required": "N", "lift_bound.weight": "N",
                   "lift_bound.per_cable": "N"},
    "physics": {"ball_radius": SHEET, "states.predicted": SHEET, "states.tied": SHEET,
                "states.settled": SHEET, "states.difference": SHEET,
                "states.tied_difference": SHEET, "states.basin": SHEET,
                "states.moved": SHEET},
    "control": {"times": "s", "poses": _POSE, "reference": _POSE, "tracking_error": "m",
                "orientation_error": "rad", "tensions": "N", "motor_torques": "N m",
                "motor_speeds": "rad/s", "tipping_margin": "N m",
                "base_poses": "m (x, y), rad (theta)", "t_min": "N", "t_max": "N",
                "slack_time": "s", "worst_over_tension": "N", "worst_under_tension": "N",
                "events.start": "s", "events.end": "s",
                "events.worst": "N (tension), N m (tipping, torque), rad/s (speed)",
                "events.limit": "N (tension), N m (tipping, torque), rad/s (speed)",
                "controller.length_gain": "1/s", "controller.tension_gain": "1/s",
                "controller.position_stiffness": "1/s^2",
                "controller.position_damping": "1/s",
                "controller.rotation_stiffness": "1/s^2",
                "controller.rotation_damping": "1/s",
                "controller.joint_damping": "N m s/rad"},
    "monte_carlo": {"max_tracking_error": "m", "rms_tracking_error": "m",
                    "min_tension": "N", "max_tension": "N", "slack_time": "s",
                    "worst_over_tension": "N", "min_tipping_margin": "N m"},
}


def units_of(kind: str, length_unit: str | None = None) -> dict[str, str]:
    """The ``"units"`` object of a document of ``kind`` (a key of :data:`DOCUMENTS`);
    ``length_unit`` names the sheet's unit (``"sheet units"`` when None)."""
    unit = length_unit or "sheet units"
    return {k: v.replace(SHEET, unit) for k, v in DOCUMENTS[kind].items()}


def has_unit_suffix(key: str) -> bool:
    """Whether ``key`` ends in one of :data:`SUFFIXES` (``duration_s``, ``speed_mps``)."""
    return any(key.endswith(s) for s in SUFFIXES)
