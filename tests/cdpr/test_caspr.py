"""CASPR XML import: the shipped models (examples/cdpr/caspr, BSD-3 from the CASPR
toolbox) against a structure matrix built by hand from the XML."""

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from taut.cdpr import cable_state, rotation_matrices
from taut.errors import ScenarioError
from taut.io.caspr import load_caspr_model

DIR = Path(__file__).resolve().parents[2] / "examples" / "cdpr" / "caspr"
MODELS = ("IPAnema_1", "CoGiRo")


def _by_hand(name, pose):
    """W (6, m) from the XML: u_i = (a_i - (p + R b_i)) / |.|, columns [u; (R b_i) x u]."""
    root = ET.parse(DIR / f"{name}_cables.xml").getroot()
    cset = [s for s in root.findall("cable_set") if s.get("id") == root.get("default_cable_set")]
    R = rotation_matrices(np.array([pose[3:]]))[0]
    cols, lims = [], []
    for c in cset[0].findall("cable_ideal"):
        loc = {int(a.find("link").text): np.array(a.find("location").text.split(), float)
               for a in c.findall("./attachments/attachment")}
        r = R @ loc[1]
        v = loc[0] - (pose[:3] + r)
        u = v / np.linalg.norm(v)
        cols.append(np.r_[u, np.cross(r, u)])
        lims.append((float(c.find("./properties/force_min").text),
                     float(c.find("./properties/force_max").text)))
    return np.array(cols).T, np.array(lims)


@pytest.mark.parametrize("name", MODELS)
def test_structure_matrix_equals_hand_built(name):
    robot = load_caspr_model(DIR / f"{name}_bodies.xml", DIR / f"{name}_cables.xml")
    g = np.random.default_rng(1)
    lo, hi = robot.bounds
    for _ in range(5):
        pose = np.r_[g.uniform(lo + 0.3 * (hi - lo), hi - 0.3 * (hi - lo)),
                     g.uniform(-0.2, 0.2, 3)]
        W, lims = _by_hand(name, pose)
        np.testing.assert_allclose(cable_state(robot, pose).W, W, atol=1e-12)
    np.testing.assert_array_equal(robot.t_min, lims[:, 0])
    np.testing.assert_array_equal(robot.t_max, lims[:, 1])
    body = ET.parse(DIR / f"{name}_bodies.xml").getroot().find("./links/link_rigid/physical")
    assert robot.platform.mass == float(body.find("mass").text)


def test_caspr_errors(tmp_path):
    with pytest.raises(ScenarioError) as exc:
        load_caspr_model(tmp_path / "none.xml", DIR / "CoGiRo_cables.xml")
    assert exc.value.field == "bodies"
    with pytest.raises(ScenarioError, match="no cable set"):
        load_caspr_model(DIR / "CoGiRo_bodies.xml", DIR / "CoGiRo_cables.xml",
                         cable_set="nope")
    bad = tmp_path / "b.xml"
    bad.write_text("<bodies_system><links></links></bodies_system>")
    with pytest.raises(ScenarioError, match="one rigid link"):
        load_caspr_model(bad, DIR / "CoGiRo_cables.xml")
