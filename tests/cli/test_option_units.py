"""One unit story (issue 29.4): every numeric option of every ``taut`` command says its unit
in its help, and that unit is the one the matching Python parameter's docstring gives (SI
for cable robots and plans, the sheet's own unit for sheets: "sheet units").

The typer app is walked, so an option added later is checked too: a numeric option (float,
int or a tuple of them) must be listed in :data:`LIBRARY` (the library parameter it feeds)
or in :data:`NO_UNIT` (a count, seed or port) -- else this test names it.
"""

from __future__ import annotations

import importlib
import inspect
import re

import pytest
import typer

from taut.cli import build_app

#: (command, option) -> ("module:object", parameter) it is passed to.
LIBRARY = {
    ("fk", "--mass"): ("taut.sheet:SheetTeam", "mass"),
    ("ik", "--mass"): ("taut.sheet:SheetTeam", "mass"),
    ("simulate", "--mass"): ("taut.sheet:SheetTeam", "mass"),
    ("ik", "--object"): ("taut.sheet:inverse_kinematics", "object_position"),
    ("ik", "--contact"): ("taut.sheet:inverse_kinematics", "contact"),
    ("ik", "--heading"): ("taut.sheet:inverse_kinematics", "heading"),
    ("plan", "--budget"): ("taut.plan:plan", "time_budget"),
    ("plan", "--sheet-margin"): ("taut.plan:plan", "sheet_margin"),
    ("plan", "--spacing"): ("taut.plan:plan", "spacing"),
    ("plan", "--robustness"): ("taut.plan:plan_robustness", "sigma"),
    ("plan", "--max-speed"): ("taut.plan:robot_trajectories", "max_speed"),
    ("plan", "--max-accel"): ("taut.plan:robot_trajectories", "max_accel"),
    ("plan", "--max-yaw-rate"): ("taut.plan:robot_trajectories", "max_yaw_rate"),
    ("plan", "--max-yaw-accel"): ("taut.plan:robot_trajectories", "max_yaw_accel"),
    ("plan", "--reform-speed"): ("taut.plan:robot_trajectories", "reform_speed"),
    ("cdpr tensions", "--pose"): ("taut.cdpr:distribute_tensions", "poses"),
    ("cdpr tensions", "--rpy"): ("taut.cdpr:distribute_tensions", "poses"),
    ("cdpr wrench-set", "--pose"): ("taut.cdpr:available_wrench_set", "poses"),
    ("cdpr wrench-set", "--rpy"): ("taut.cdpr:available_wrench_set", "poses"),
    ("cdpr wrench-set", "--external-wrench"): ("taut.cdpr:external_wrench_box", "half_widths"),
    ("cdpr workspace", "--box"): ("taut.cdpr:grid_points", "box"),
    ("cdpr workspace", "--rpy"): ("taut.cdpr:wrench_feasible_workspace", "orientations"),
    ("cdpr workspace", "--sweep"): ("taut.cdpr:wrench_feasible_workspace", "orientations"),
    ("cdpr twist-set", "--pose"): ("taut.cdpr:available_twist_set", "poses"),
    ("cdpr twist-set", "--rpy"): ("taut.cdpr:available_twist_set", "poses"),
    ("cdpr twist-set", "--base-speed"): ("taut.cdpr:MotionLimits", "base_max"),
    ("cdpr twist-set", "--yaw-rate"): ("taut.cdpr:MotionLimits", "base_max"),
    ("cdpr twist-set", "--cable-speed"): ("taut.cdpr:MotionLimits", "cable_max"),
    ("cdpr deploy", "--workspace"): ("taut.cdpr:plan_deployment", "workspace"),
    ("cdpr deploy", "--external-wrench"): ("taut.cdpr:plan_deployment", "external_wrench"),
    ("cdpr deploy", "--twist"): ("taut.cdpr:plan_deployment", "required_twist"),
    ("cdpr simulate", "--waypoints"): ("taut.cdpr:pick_and_place", "waypoints"),
    ("cdpr simulate", "--exit-error"): ("taut.cdpr:ModelErrors", "exit_offset"),
    ("cdpr simulate", "--speed"): ("taut.cdpr:pick_and_place", "speed"),
    ("cdpr simulate", "--dwell"): ("taut.cdpr:pick_and_place", "dwell"),
    ("cdpr simulate", "--control-rate"): ("taut.cdpr:simulate", "control_rate"),
    ("cdpr simulate", "--tension-gain"): ("taut.cdpr:VelocityController", "tension_gain"),
    ("cdpr simulate", "--latency"): ("taut.cdpr:Sensing", "latency"),
}
#: Numeric options without a unit: counts, seeds, ports.
NO_UNIT = {"--seed", "--iterations", "--trials", "--grid", "--mesh", "--port", "--maxiter",
           "--workers", "--limit"}

#: Unit words, longest first; each maps to its canonical spelling.
_UNITS = {"m/s^2": "m/s^2", "rad/s^2": "rad/s^2", "rad/s": "rad/s", "m/s": "m/s", "N m": "N m", "1/s": "1/s",
          "mm": "mm", "ms": "ms", "Hz": "Hz", "kg": "kg", "degrees": "deg", "deg": "deg",
          "radians": "rad", "rad": "rad", "m": "m", "s": "s", "N": "N",
          "sheet units": "sheet units", "scenario units": "sheet units",
          "same length unit as the sheet": "sheet units"}
_UNIT = re.compile(r"(?:(?<=^)|(?<=[\s(\[,;]))(" + "|".join(re.escape(u) for u in _UNITS)
                   + r")(?=$|[\s)\],.;:])")


def units(text: str) -> set[str]:
    """The canonical units named in ``text``."""
    return {_UNITS[m.group(1)] for m in _UNIT.finditer(" ".join(text.split()))}


def _param_doc(target: str, name: str) -> str:
    """The docstring block of parameter ``name`` (``name : type`` and its indented lines)
    of ``module:object``; the whole docstring when it has no such block."""
    mod, obj = target.split(":")
    doc = inspect.getdoc(getattr(importlib.import_module(mod), obj)) or ""
    lines = doc.splitlines()
    for i, line in enumerate(lines):
        head = line.split(" : ")[0] if " : " in line else ""
        if name in [h.strip() for h in head.split(",")] and not line.startswith(" "):
            block = [line.split(" : ", 1)[1]]
            for nxt in lines[i + 1:]:
                if nxt and not nxt.startswith(" "):
                    break
                block.append(nxt)
            return "\n".join(block)
    return doc


def _options():
    root = typer.main.get_command(build_app())

    def walk(cmd, path):
        if hasattr(cmd, "commands"):
            for name, sub in cmd.commands.items():
                yield from walk(sub, path + [name])
            return
        for p in cmd.params:
            if type(p).__name__.endswith("Option"):
                yield " ".join(path), p

    return list(walk(root, []))


OPTIONS = _options()


def _numeric(param) -> bool:
    return re.search(r"\b(float|int)\b", str(param.bare_type())) is not None


def test_units_parser():
    assert units("Std. dev. of exit errors, m (default: the library's)") == {"m"}
    assert units("FX FY FZ (N) MX MY MZ (N m)") == {"N", "N m"}
    assert units("Rotation (radians, counter-clockwise)") == {"rad"}
    assert units("(m/s, rad/s)") == {"m/s", "rad/s"}
    assert units("a robot's mass") == set()


def test_every_numeric_option_is_registered():
    missing = [f"{cmd} {p.opts[0]}" for cmd, p in OPTIONS
               if (_numeric(p) and (cmd, p.opts[0]) not in LIBRARY
                   and p.opts[0] not in NO_UNIT)]
    assert not missing, ("numeric options with neither a library parameter (LIBRARY) nor "
                         f"a reason to have no unit (NO_UNIT): {missing}")


def test_registered_options_exist():
    have = {(cmd, p.opts[0]) for cmd, p in OPTIONS}
    assert not set(LIBRARY) - have


#: Option-name endings that would be a unit (``--max-speed-mps``, ``--latency-ms``).
_UNIT_ENDINGS = re.compile(r"-(m|mm|cm|s|ms|rad|deg|degrees|n|nm|kg|hz|mps|mps2|radps|"
                           r"m-s|rad-s|sheet-units|units)$")


def test_option_names_carry_no_unit():
    """One rule for every command (docs/conventions.md, Units): the name says what, the
    help says the unit, so ``--max-speed 0.2`` (m/s) like ``--latency 0.002`` (s)."""
    named = sorted({o for _, p in OPTIONS for o in p.opts if _UNIT_ENDINGS.search(o.lower())})
    assert not named, f"options naming a unit (say it in the help instead): {named}"
    assert _UNIT_ENDINGS.search("--max-speed-mps") and not _UNIT_ENDINGS.search("--max-speed")


@pytest.mark.parametrize("key", sorted(LIBRARY), ids=[" ".join(k) for k in sorted(LIBRARY)])
def test_option_unit_is_the_library_parameters(key):
    help_text = next(p.help or "" for cmd, p in OPTIONS if (cmd, p.opts[0]) == key)
    said = units(help_text)
    assert said, f"{' '.join(key)}: help names no unit: {help_text!r}"
    target, name = LIBRARY[key]
    documented = units(_param_doc(target, name))
    assert documented, f"{target} {name}: docstring names no unit"
    assert said <= documented, (f"{' '.join(key)} says {sorted(said)}, {target}({name}=) "
                                f"documents {sorted(documented)}")
