"""The physics extra's MuJoCo bounds are the versions the physics tests ran with (issue 31):
the installed MuJoCo must satisfy the bounds pyproject.toml states, so the suite cannot
pass on a version the extra does not allow (or the extra allow one nothing ran)."""

import tomllib
from importlib.metadata import version
from pathlib import Path

import pytest
from packaging.requirements import Requirement

pytest.importorskip("mujoco")

PYPROJECT = Path(__file__).resolve().parents[2] / "pyproject.toml"


def test_installed_mujoco_is_within_the_physics_extra():
    extra = tomllib.loads(PYPROJECT.read_text())["project"]["optional-dependencies"]["physics"]
    (req,) = [Requirement(r) for r in extra if Requirement(r).name == "mujoco"]
    assert req.specifier, "the physics extra must bound MuJoCo's version"
    assert req.specifier.contains(version("mujoco")), (version("mujoco"), str(req))
    # An upper bound below the next minor release: MjSpec's API changes between minors.
    assert any(s.operator == "<" for s in req.specifier), str(req)
