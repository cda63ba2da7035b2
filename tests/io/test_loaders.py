"""One safe loader for every file (issue 24): CASPR XML errors are TautErrors naming the
element, and model files pass the CLI's physical ranges in the loader itself, so the
library, the CLI and the app accept the same files."""

import copy
from pathlib import Path

import pytest

from taut.errors import InvalidModelError, ScenarioError, TautError
from taut.io import cdpr_model_from_mapping, read_mapping
from taut.io.caspr import load_caspr_model
from taut.io.cdpr_model import preset_path

CASPR = Path(__file__).resolve().parents[2] / "examples" / "cdpr" / "caspr"
BODIES, CABLES = CASPR / "CoGiRo_bodies.xml", CASPR / "CoGiRo_cables.xml"


def edited(tmp_path, source, old, new, count=1):
    text = source.read_text()
    assert old in text
    out = tmp_path / source.name
    out.write_text(text.replace(old, new, count))
    return out


def test_caspr_shipped_model_still_loads():
    robot = load_caspr_model(BODIES, CABLES)
    assert robot.m == 8


@pytest.mark.parametrize("old, new, field", [
    ("<link>1</link>", "<link>1.7</link>", "link"),        # read as 1 before
    ("<link>1</link>", "<link>one</link>", "link"),
    ("<link>0</link>", "<link></link>", "link"),
    ("<force_max>", "<force_max>abc ", "force_max"),
])
def test_caspr_bad_cables_name_the_element(tmp_path, old, new, field):
    with pytest.raises(ScenarioError) as err:
        load_caspr_model(BODIES, edited(tmp_path, CABLES, old, new))
    assert field in err.value.field


def test_caspr_bad_files_are_scenario_errors(tmp_path):
    for bodies, cables in ((tmp_path, CABLES), (BODIES, tmp_path / "missing.xml"),
                           (BODIES, 12), (edited(tmp_path, BODIES, "<", "<<"), CABLES)):
        with pytest.raises(ScenarioError):
            load_caspr_model(bodies, cables)


def test_caspr_joint_limits_must_be_numbers(tmp_path):
    text = BODIES.read_text()
    start = text.index('q_min="') + len('q_min="')
    bad = tmp_path / BODIES.name
    bad.write_text(text[:start] + "x " + text[start:])
    with pytest.raises(ScenarioError, match="q_min"):
        load_caspr_model(bad, CABLES)


def test_caspr_huge_mass_is_out_of_range(tmp_path):
    text = BODIES.read_text()
    start = text.index("<mass>") + len("<mass>")
    end = text.index("</mass>")
    bad = tmp_path / BODIES.name
    bad.write_text(text[:start] + "1e308" + text[end:])
    with pytest.raises(InvalidModelError, match="exceeds the accepted range"):
        load_caspr_model(bad, CABLES)


@pytest.fixture(scope="module")
def fastkit():
    return read_mapping(preset_path("fastkit"))


def test_model_mass_range_is_the_loader_s(fastkit):
    m = copy.deepcopy(fastkit)
    m["platform"]["mass"] = 1e308
    with pytest.raises(InvalidModelError, match="exceeds the accepted range 1e\\+06 kg"):
        cdpr_model_from_mapping(m)


def test_model_exit_range_is_the_loader_s(fastkit):
    m = copy.deepcopy(fastkit)
    base = m["bases"][0]
    key = next(iter(base["exit_points"]))
    base["exit_points"][key] = [1e300, 0.0, 2.4]
    with pytest.raises(TautError, match="exceeds the accepted range 1000 m"):
        cdpr_model_from_mapping(m)


def test_cli_and_app_refuse_the_same_model(fastkit, tmp_path, capsys):
    import json

    from taut.cli import main
    m = copy.deepcopy(fastkit)
    m["platform"]["mass"] = 1e308
    path = tmp_path / "m.json"
    path.write_text(json.dumps(m))
    assert main(["cdpr", "tensions", str(path), "--pose", "0", "0", "1"]) == 2
    cli_line = capsys.readouterr().err.removeprefix("taut: error: ").strip()
    pytest.importorskip("starlette")
    from taut.app.cdpr_api import CdprAPI
    from taut.app.catalog import Catalog
    with pytest.raises(TautError) as err:
        CdprAPI(Catalog()).load({"model": m})
    assert str(err.value) == cli_line


def test_model_dynamics_section_is_numbers_only(fastkit):
    """The `dynamics:` section was free-form (any nested data, walked in full by the
    boolean scan); now it is a flat mapping of numbers, its keys checked by its loader."""
    m = copy.deepcopy(fastkit)
    m["dynamics"] = {"cable_stiffness": {"nested": [[1, 2], [3, 4]]}}
    with pytest.raises(ScenarioError) as err:
        cdpr_model_from_mapping(m)
    assert err.value.field == "dynamics.cable_stiffness"


def test_model_file_with_a_bomb_in_its_dynamics_is_refused_fast(fastkit, tmp_path):
    """The issue's 5.8 KB model file: a real model whose `dynamics:` section holds an
    alias bomb (9 levels of 9 aliases: 387 million values). Refused by the parser's alias
    budget in well under a second, with the file named, by the loader and the CLI."""
    import time

    from taut.cli import main
    from taut.io import load_cdpr_model

    levels = "\n".join(f"  l{k}: &l{k} [" + ", ".join([f"*l{k - 1}"] * 9) + "]"
                       for k in range(1, 10))
    import yaml

    model = {k: v for k, v in fastkit.items() if k != "dynamics"}
    text = (yaml.safe_dump(model) + "dynamics:\n  l0: &l0 [" + ", ".join(["1.0"] * 9)
            + "]\n" + levels + "\n")
    path = tmp_path / "model.yaml"
    path.write_text(text)
    assert path.stat().st_size < 10_000
    t0 = time.perf_counter()
    with pytest.raises(ScenarioError, match="YAML aliases add more than") as err:
        load_cdpr_model(path)
    assert time.perf_counter() - t0 < 1.0
    assert err.value.field == str(path)
    assert main(["cdpr", "tensions", str(path), "--pose", "0", "0", "1"]) == 2
