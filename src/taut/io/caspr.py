"""Read CASPR robot definitions (a ``*_bodies.xml`` and a ``*_cables.xml`` file, as in the
CASPR toolbox's ``data/model_config/models``) into a :class:`taut.cdpr.CableRobot`.

Supported: one rigid moving link (``link_rigid num="1"``) with a spatial or translational
joint, attached to the ground (link 0) by ideal cables (``cable_ideal``) with two
attachments each (one on link 0: the exit point; one on link 1: the attachment point),
``force_min`` / ``force_max`` tension limits (N), mass (kg), centre of mass and inertia.
Locations with ``attachment_reference="com"`` are shifted to the link frame. The joint's
``q_min`` / ``q_max`` position part becomes the frame ``bounds`` (m). Units are SI, as in
CASPR. Multi-link (serial) bodies and other cable types raise
:class:`taut.errors.ScenarioError` naming the element, as does every bad input (a missing,
unreadable, oversized or malformed file, a non-integer link number, text where numbers
belong); the model then passes the same physical ranges as every model file
(:func:`taut.io.cdpr_model.physical_ranges`).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np

from ..cdpr.model.robot import Base, Cable, CableRobot, Platform
from ..errors import ScenarioError, TautError
from .cdpr_model import physical_ranges
from .files import MAX_FILE_BYTES

__all__ = ["load_caspr_model"]

_JOINTS = ("SPATIAL_EULER_XYZ", "SPATIAL_QUATERNION", "SPATIAL", "TRANSLATIONAL_XYZ")


def _parse(path: Any, field: str) -> ET.Element:
    if not isinstance(path, (str, Path)):
        raise ScenarioError(field, "must be a file path")
    path = Path(path)
    if not path.is_file():
        raise ScenarioError(field, f"file not found: {path}")
    try:
        if path.stat().st_size > MAX_FILE_BYTES:
            raise ScenarioError(field, f"{path.name} is larger than "
                                       f"{MAX_FILE_BYTES // 2**20} MiB")
        data = path.read_bytes()
    except OSError as exc:
        raise ScenarioError(field, f"cannot read {path} ({exc.strerror or exc})") from None
    try:
        return ET.fromstring(data)
    except ET.ParseError as exc:
        raise ScenarioError(field, f"{path.name} is not valid XML: {exc}") from None
    except RecursionError:
        raise ScenarioError(field, f"{path.name} is nested too deeply") from None


def _vec(el: ET.Element | None, field: str, n: int = 3) -> np.ndarray:
    if el is None or el.text is None:
        raise ScenarioError(field, "missing")
    try:
        v = np.array([float(x) for x in el.text.split()])
    except (ValueError, OverflowError):
        raise ScenarioError(field, f"not {n} numbers: {el.text!r}") from None
    if v.shape != (n,) or not np.all(np.isfinite(v)):
        raise ScenarioError(field, f"must be {n} finite numbers, got {el.text!r}")
    return v


def _index(el: ET.Element | None, field: str) -> int:
    """An integer element (a link number): ``1.7`` is an error, not 1."""
    text = "" if el is None or el.text is None else el.text.strip()
    try:
        return int(text)
    except ValueError:
        raise ScenarioError(field, f"must be an integer link number, got {text!r}") from None


def _numbers(text: str | None, field: str) -> np.ndarray:
    try:
        return np.array([float(x) for x in (text or "").split()] or [np.nan])
    except ValueError:
        raise ScenarioError(field, f"must be numbers, got {text!r}") from None


def _link(bodies: ET.Element) -> tuple[ET.Element, ET.Element]:
    links = bodies.findall("./links/link_rigid")
    if len(links) != 1:
        raise ScenarioError("bodies.links", f"one rigid link is supported, found {len(links)}")
    joint = links[0].find("joint")
    if joint is None or joint.get("type") not in _JOINTS:
        raise ScenarioError("bodies.links.joint", "joint type must be one of "
                                                  + ", ".join(_JOINTS))
    return links[0], joint


def load_caspr_model(bodies: str | Path, cables: str | Path, *, cable_set: str | None = None,
                     name: str | None = None) -> CableRobot:
    """Build a fixed-frame :class:`CableRobot` from CASPR's XML files.

    Parameters
    ----------
    bodies, cables : path
        The ``*_bodies.xml`` and ``*_cables.xml`` files.
    cable_set : str, optional
        Which ``cable_set`` to use (default: the file's ``default_cable_set``).
    name : str, optional
        Model name (default: the link's ``name`` attribute).

    Examples
    --------
    >>> from pathlib import Path
    >>> d = Path("examples/cdpr/caspr")
    >>> robot = load_caspr_model(d / "CoGiRo_bodies.xml", d / "CoGiRo_cables.xml")
    >>> robot.m, robot.dof, float(robot.platform.mass), robot.t_max[0]
    (8, 6, 91.058, np.float64(5000.0))
    """
    try:
        return _load(bodies, cables, cable_set, name)
    except TautError:
        raise
    except (ValueError, TypeError, KeyError, IndexError) as exc:   # a malformed element
        raise ScenarioError("caspr", f"malformed model ({exc.__class__.__name__}: "
                                     f"{str(exc)[:200]})") from None


def _load(bodies: Any, cables: Any, cable_set: str | None, name: str | None) -> CableRobot:
    b_root = _parse(bodies, "bodies")
    c_root = _parse(cables, "cables")
    link, joint = _link(b_root)
    phys = link.find("physical")
    if phys is None:
        raise ScenarioError("bodies.physical", "missing")
    mass = float(_vec(phys.find("mass"), "bodies.physical.mass", 1)[0])
    com = _vec(phys.find("com_location"), "bodies.physical.com_location")
    I = phys.find("inertia")
    names = ("Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz")
    iv = [float(_vec(None if I is None else I.find(k), f"bodies.physical.inertia.{k}", 1)[0])
          for k in names]
    inertia = np.array([[iv[0], iv[3], iv[4]], [iv[3], iv[1], iv[5]], [iv[4], iv[5], iv[2]]])
    wanted = cable_set or c_root.get("default_cable_set")
    sets = {s.get("id"): s for s in c_root.findall("cable_set")}
    if wanted not in sets:
        raise ScenarioError("cables.cable_set", f"no cable set {wanted!r} (sets: "
                                                + ", ".join(map(str, sets)) + ")")
    exits, attach, cabs = {}, {}, []
    for i, c in enumerate(sets[wanted]):
        f = f"cables.cable_set[{wanted}][{i}]"
        if c.tag != "cable_ideal":
            raise ScenarioError(f, f"only cable_ideal is supported, got {c.tag}")
        cname = c.get("name") or f"cable {i + 1}"
        pts = c.findall("./attachments/attachment")
        where = {_index(a.find("link"), f"{f}.link"): _vec(a.find("location"),
                                                            f"{f}.location")
                 for a in pts}
        if len(pts) != 2 or set(where) != {0, 1}:
            raise ScenarioError(f, "a cable needs one attachment on link 0 and one on link 1")
        loc = where[1] + (com if c.get("attachment_reference") == "com" else 0.0)
        exits[cname], attach[cname] = where[0], loc
        props = c.find("properties")
        lo = _vec(None if props is None else props.find("force_min"), f"{f}.force_min", 1)[0]
        hi = _vec(None if props is None else props.find("force_max"), f"{f}.force_max", 1)[0]
        cabs.append(Cable(cname, "frame", cname, cname, float(lo), float(hi)))
    qmin = _numbers(joint.get("q_min"), "bodies.links.joint.q_min")
    qmax = _numbers(joint.get("q_max"), "bodies.links.joint.q_max")
    bounds = (np.stack([qmin[:3], qmax[:3]]) if qmin.size >= 3 and qmax.size >= 3
              and np.all(np.isfinite(qmin[:3])) and np.all(np.isfinite(qmax[:3])) else None)
    return physical_ranges(CableRobot((Base("frame", exits),),
                                      Platform(attach, mass=mass, com=com, inertia=inertia),
                                      tuple(cabs), bounds=bounds,
                                      name=name or link.get("name") or "caspr"))
