"""The examples' recorded outputs are reproduced (issue 10: "the diff changes no numerical
output").

* Every ``examples/**/*.expected.json`` is the complete ``taut fk --json`` document of the
  scenario file beside it, compared in full (every key, string, flag and number within
  round-off, :func:`json_compare.assert_same_document`) by
  ``tests/cli/test_fk_cli.py::test_examples_match_expected_output``, which runs every
  ``examples/sheet/*.yaml``. Here: every expected file has its scenario there, so none
  can go unchecked.
* The capacity tables of ``examples/cdpr/fastkit_motion.json`` (twist and wrench capacities
  at the example's pose, rounded to 4 decimals by the example) are recomputed.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
EXPECTED = sorted((ROOT / "examples").rglob("*.expected.json"))


def test_every_expected_file_has_its_scenario():
    assert EXPECTED, "no expected outputs found"
    for path in EXPECTED:
        src = path.with_name(path.name.replace(".expected.json", ".yaml"))
        assert src.exists(), f"{path.relative_to(ROOT)} has no scenario {src.name}"
        assert src.parent == ROOT / "examples" / "sheet", \
            f"{path.relative_to(ROOT)}: only examples/sheet/*.yaml are run by the fk test"


def test_fastkit_motion_capacity_tables_are_reproduced():
    from taut.cdpr import axis_capacities, fastkit_motion_limits, twist_capacities
    from taut.io.cdpr_model import load_cdpr_model

    doc = json.loads((ROOT / "examples/cdpr/fastkit_motion.json").read_text())
    robot = load_cdpr_model("fastkit")
    pose = np.array(doc["pose"])
    lim = fastkit_motion_limits()

    def rnd(a):
        return [round(float(x), 4) for x in np.ravel(a)]

    got = {"active_moving": twist_capacities(robot, pose, lim, "task"),
           "bases_fixed": twist_capacities(robot, pose, lim, "task", ()),
           "navigation": twist_capacities(robot, pose, lim, "navigation")}
    for key, cap in got.items():
        assert {"+": rnd(cap.positive), "-": rnd(cap.negative)} == doc["twist_capacity"][key]
    for key, tip in (("tipping", True), ("no_tipping", False)):
        cap = axis_capacities(robot, pose, tipping=tip)
        assert {"+": rnd(cap.positive), "-": rnd(cap.negative)} == doc["wrench_capacity"][key]
