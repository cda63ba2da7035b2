"""Conventions every public outcome type follows (taut._outcome): an outcome that can fail
has ``success``, ``status`` (one of ``taut._outcome.STATUSES``) and ``message``."""

from __future__ import annotations

import dataclasses
import inspect

import pytest

import taut.cdpr
import taut.plan
import taut.sheet

#: The outcome types that can answer "no" to a valid question (issue 10, "Done when").
REQUIRED = {
    "taut.sheet": ["IKResult", "SimulationResult", "FKResult", "BatchFKResult"],
    "taut.plan": ["PlanResult"],
    "taut.cdpr": ["TensionResult", "RedundancyResult", "DeploymentResult"],
}
#: Public result types that only report facts and cannot fail (no success flag needed).
FACTS_ONLY = {"TippingResult", "WorkspaceResult"}

MODULES = {"taut.sheet": taut.sheet, "taut.plan": taut.plan, "taut.cdpr": taut.cdpr}


def _public_outcomes():
    for modname, mod in MODULES.items():
        for name in getattr(mod, "__all__", []):
            obj = getattr(mod, name)
            if inspect.isclass(obj) and name.endswith("Result") and name not in FACTS_ONLY:
                yield modname, name, obj
    for modname, names in REQUIRED.items():
        for name in names:
            yield modname, name, getattr(MODULES[modname], name)


def _members(cls):
    names = {n for n, _ in inspect.getmembers(cls)}
    if dataclasses.is_dataclass(cls):
        names |= {f.name for f in dataclasses.fields(cls)}
    names |= set(getattr(cls, "__annotations__", {}))
    return names


OUTCOMES = sorted(set(_public_outcomes()), key=lambda t: (t[0], t[1]))


def test_required_outcomes_are_public():
    for modname, names in REQUIRED.items():
        for name in names:
            assert name in MODULES[modname].__all__, f"{modname}.{name}"


@pytest.mark.parametrize("modname, name, cls", OUTCOMES,
                         ids=[f"{m}.{n}" for m, n, _ in OUTCOMES])
def test_outcome_has_success_status_message(modname, name, cls):
    missing = {"success", "status", "message"} - _members(cls)
    assert not missing, f"{modname}.{name} lacks {sorted(missing)}"


@pytest.mark.parametrize("pkg", ["taut.sheet", "taut.plan", "taut.cdpr"])
def test_one_public_import_path(pkg):
    """Every name a public module's ``__all__`` lists, in any sub-folder, is the package's
    own name (one public import path per name); private modules start with an underscore."""
    import importlib
    import pkgutil

    package = importlib.import_module(pkg)
    for mod in pkgutil.walk_packages(package.__path__, prefix=f"{pkg}."):
        if any(part.startswith("_") for part in mod.name.split(".")):
            continue
        m = importlib.import_module(mod.name)
        for name in getattr(m, "__all__", ()):
            assert name in package.__all__ and getattr(package, name) is getattr(m, name), \
                f"{mod.name}.{name} is not re-exported by {pkg}"
