"""`taut cdpr`: the command line answers what the library answers.

* `deploy` with the optimiser stubbed: the CLI maps a verified placement to exit 0 and a
  failed search to exit 1 (pinned, not "either"), in seconds instead of minutes.
* `tensions` at every shipped cable-robot pose of the README and the examples: the CLI's
  verdict (JSON ``feasible``, exit code, message) is `distribute_tensions`' with the
  library's defaults, and so is the web app's `/api/cdpr/state`.
"""

from __future__ import annotations

import json
import re
import shlex
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import taut.cdpr
from taut.app.catalog import Catalog
from taut.app.cdpr_api import CdprAPI
from taut.cdpr import distribute_tensions
from taut.cli import main
from taut.errors import InfeasiblePoseError
from taut.io import load_cdpr_model
from taut.io.cdpr_model import PRESETS

ROOT = Path(__file__).resolve().parents[2]

BOX = ["-1", "1", "-0.05", "0.05", "0.4", "0.9"]


def _fake(feasible: bool, calls: list):
    def plan_deployment(robot, box, **kw):
        calls.append((np.asarray(box).tolist(), kw))
        n = 4
        return SimpleNamespace(
            success=feasible, status="ok" if feasible else "budget_exhausted",
            refuted=False, robot=robot,
            base_poses={"active": np.array([-3.0, 0.1, 0.0]),
                        "passive": np.array([3.0, -0.1, 3.14])},
            margin=0.5 if feasible else -0.25, twist_margin=None,
            points=np.zeros((n, 3)), point_feasible=np.array([feasible] * n),
            point_margin=np.zeros(n), workspace=np.asarray(box), evaluations=7,
            message="verified" if feasible else "budget exhausted: 3 of 4 points infeasible",
            lift_bound=None)
    return plan_deployment


@pytest.mark.parametrize("feasible, code", [(True, 0), (False, 1)])
def test_deploy_exit_code_is_pinned(capsys, monkeypatch, feasible, code):
    calls: list = []
    monkeypatch.setattr(taut.cdpr, "plan_deployment", _fake(feasible, calls))
    assert main(["cdpr", "deploy", "fastkit", "--workspace", *BOX, "--json",
                 "--seed", "3", "--maxiter", "2"]) == code
    doc = json.loads(capsys.readouterr().out)
    assert doc["feasible"] is feasible and doc["evaluations"] == 7
    assert calls[0][0] == [[-1.0, -0.05, 0.4], [1.0, 0.05, 0.9]]      # XMIN XMAX ... order
    assert calls[0][1]["seed"] == 3 and calls[0][1]["maxiter"] == 2
    assert main(["cdpr", "deploy", "fastkit", "--workspace", *BOX]) == code
    text = capsys.readouterr().out
    assert ("FEASIBLE" if feasible else "NOT FOUND") in text.splitlines()[0]
    if not feasible:
        assert "budget exhausted" in text


# --- the CLI, the library and the app agree on every shipped pose ---------------------------

#: Poses of the Python snippets (README.md, examples/cdpr/README.md; model, x y z r p y).
SNIPPET_POSES = [("fastkit", (0, 0, 1.2, 0, 0, 0)), ("fastkit", (1, 0, 0.8, 0, 0, 0.1)),
                 ("fastkit", (0, 0, 0.6, 0, 0, 0)), ("fastkit", (-1, 0, 0.8, 0, 0, 0.1)),
                 ("fastkit", (2, 0, 1.8, 0, 0, 0))]


def _shipped_poses() -> list[tuple[str, tuple[float, ...], str | None]]:
    """(preset, pose, method or None) of every `taut cdpr tensions|wrench-set|twist-set
    PRESET --pose ...` command in the README and the examples' Markdown, the snippet poses
    and the pose of examples/cdpr/fastkit_motion.json."""
    out = [(m, tuple(map(float, p)), None) for m, p in SNIPPET_POSES]
    docs = [ROOT / "README.md", *sorted((ROOT / "examples").rglob("*.md"))]
    for doc in docs:
        for line in doc.read_text(encoding="utf-8").splitlines():
            found = re.search(r"taut cdpr (?:tensions|wrench-set|twist-set) .*", line)
            if not found:
                continue
            words = shlex.split(found.group(0).split("#")[0])
            model = words[3]
            if model not in PRESETS or "--pose" not in words:
                continue
            k = words.index("--pose")
            rpy = words[words.index("--rpy") + 1:words.index("--rpy") + 4] \
                if "--rpy" in words else ["0", "0", "0"]
            method = words[words.index("--method") + 1] if "--method" in words else None
            out.append((model, tuple(float(v) for v in words[k + 1:k + 4] + rpy), method))
    motion = json.loads((ROOT / "examples/cdpr/fastkit_motion.json").read_text())
    out.append(("fastkit", tuple(float(v) for v in motion["pose"]), None))
    return sorted(set(out), key=str)


SHIPPED = _shipped_poses()


def test_the_shipped_poses_are_found():
    assert ("fastkit", (0.0, 0.0, 1.2, 0.0, 0.0, 0.0), None) in SHIPPED    # README's CLI line
    assert any(m == "ipanema" for m, _, _ in SHIPPED) and len(SHIPPED) >= 10


@pytest.fixture(scope="module")
def app_api():
    return CdprAPI(Catalog(ROOT / "examples"))


@pytest.mark.parametrize("model, pose, method", SHIPPED, ids=[f"{m}-{p}-{k}" for m, p, k in
                                                            SHIPPED])
def test_cli_library_and_app_agree_on_feasibility(capsys, app_api, model, pose, method):
    argv = ["cdpr", "tensions", model, "--pose", *map(str, pose[:3]), "--rpy",
            *map(str, pose[3:])] + (["--method", method] if method else [])
    body = {"model": app_api.load({"example": model})["model"], "pose": list(pose)}
    if method:
        body["method"] = method
    robot = load_cdpr_model(model)
    try:
        want = distribute_tensions(robot, pose, **({"method": method} if method else {}))
    except InfeasiblePoseError:                     # outside the frame: an input error
        assert main(argv + ["--json"]) == 2
        assert app_api.state(body)["in_frame"] is False
        return
    code = main(argv + ["--json"])
    doc = json.loads(capsys.readouterr().out)
    assert code == (0 if want.success else 1)
    assert doc["feasible"] is bool(want.success)
    assert (doc["binding"], doc["message"]) == (want.binding, want.message)
    assert main(argv) == code
    assert capsys.readouterr().out.splitlines()[-1] == want.message
    got = app_api.state(body)
    assert got["feasible"] is bool(want.success)
    assert (got["binding"], got["message"]) == (want.binding, want.message)


def test_readme_pose_tips_the_bases(capsys):
    """`taut cdpr tensions fastkit --pose 0 0 1.2` (README): exit 1, the bases tip (it used
    to say "feasible: yes" with the tipping constraints off); --no-tipping asks the tension
    limits alone."""
    assert main(["cdpr", "tensions", "fastkit", "--pose", "0", "0", "1.2"]) == 1
    last = capsys.readouterr().out.splitlines()[-1]
    assert last.startswith("not wrench-feasible: mobile bases active, passive tip over")
    assert main(["cdpr", "tensions", "fastkit", "--pose", "0", "0", "1.2", "--no-tipping"]) == 0
    assert "feasible: yes" in capsys.readouterr().out


def test_options_left_out_take_the_library_defaults(capsys, monkeypatch):
    """The command line passes only what the user gave: no second copy of a default."""
    calls: list = []
    real = taut.cdpr.distribute_tensions

    def spy(robot, poses, **kw):
        calls.append(kw)
        return real(robot, poses, **kw)

    monkeypatch.setattr(taut.cdpr, "distribute_tensions", spy)
    main(["cdpr", "tensions", "fastkit", "--pose", "0", "0", "0.6"])
    main(["cdpr", "tensions", "fastkit", "--pose", "0", "0", "0.6", "--no-tipping",
          "--method", "qp_min_norm"])
    assert calls == [{}, {"method": "qp_min_norm", "tipping": False}]
    limits: list = []
    real_caps = taut.cdpr.twist_capacities

    def caps_spy(robot, poses, lim, *args, **kw):
        limits.append(lim)
        return real_caps(robot, poses, lim, *args, **kw)

    monkeypatch.setattr(taut.cdpr, "twist_capacities", caps_spy)
    assert main(["cdpr", "twist-set", "fastkit", "--pose", "1", "0", "0.8", "--json"]) == 0
    want = taut.cdpr.fastkit_motion_limits()
    for got in limits:
        for name in ("base_min", "base_max", "cable_min", "cable_max"):
            np.testing.assert_array_equal(getattr(got, name), getattr(want, name))
    capsys.readouterr()


# --- the set budget: presets pass, models past it fail in one line ---------------------------

def _ring(m: int) -> dict:
    """A fixed frame of ``m`` cables (exits on a top and a bottom ring, 6-DoF platform)."""
    a = 2 * np.pi * np.arange(m) / m
    return {"name": f"ring of {m}",
            "bases": [{"name": "frame", "mobile": False, "exit_points": {
                f"A{i}": [2 * np.cos(x), 2 * np.sin(x), 3.0 * (i % 2)] for i, x in enumerate(a)}}],
            "platform": {"mass": 2.0, "attachment_points": {
                f"B{i}": [0.15 * np.cos(x), 0.15 * np.sin(x), 0.1 - 0.2 * (i % 2)]
                for i, x in enumerate(a)}},
            "cables": [{"name": f"C{i}", "exit": f"frame.A{i}", "attachment": f"B{i}",
                        "t_min": 10.0, "t_max": 1500.0} for i in range(m)]}


@pytest.mark.parametrize("model", PRESETS)
def test_presets_pass_the_set_budget(capsys, model):
    """wrench-set and twist-set (every base moving) on each preset answer (exit 0 or 1)."""
    robot = load_cdpr_model(model)
    pose = ["--pose", "0", "0", "1.0"]
    assert main(["cdpr", "wrench-set", model, *pose]) in (0, 1)
    moving = [f"--moving={b.name}" for b in robot.bases if b.mobile]
    assert main(["cdpr", "twist-set", model, *pose, *moving]) in (0, 1)
    assert "error" not in capsys.readouterr().err


@pytest.mark.parametrize("m, command, ok", [(16, "wrench-set", False), (13, "wrench-set", False),
                                            (16, "twist-set", True)])
def test_set_past_its_budget_is_one_line(tmp_path, capsys, m, command, ok):
    """A wrench set of 13 or 16 cables is refused in one line (exit 2) naming the cable
    count and the budget; the twist set of the same frame (no moving base) is small."""
    from taut._validate import MAX_SET_NUMBERS
    path = tmp_path / "ring.json"
    path.write_text(json.dumps(_ring(m)))
    code = main(["cdpr", command, str(path), "--pose", "0", "0", "1.5"])
    err = capsys.readouterr().err
    if ok:
        assert code in (0, 1) and "error" not in err
        return
    assert code == 2
    assert err.count("\n") == 1
    assert err.startswith(f"taut: error: cables: {m} cables give ")
    assert err.rstrip().endswith(f"at most {MAX_SET_NUMBERS:,} numbers")
