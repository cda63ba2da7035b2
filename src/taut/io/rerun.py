"""Rerun recordings (``.rrd``) of taut's results, with a blueprint.

:func:`write_rerun` writes the same results as :func:`taut.io.mcap.write_mcap` (the same
:class:`~taut.io._recording.Recording`) for the Rerun viewer (``rerun file.rrd``): a 3D view
of the team, sheet and object (or the cable robot: platform, cables, bases) under
``world/``, and one time-series view per quantity under ``plots/`` (object or platform
height, margins, tensions), on the timeline ``time`` (s). Metres and seconds; robots
numbered from 1. Needs the extra ``rerun`` (``pip install 'taut[rerun]'``).

Entities: ``world/object`` (point), ``world/robots`` (points labelled ``robot 1`` ...
or ``base 1`` ...), ``world/cables`` (taut cables), ``world/outline`` (the held corners or
the platform), ``world/sheet`` (mesh), ``world/static/<name>`` (obstacles, walls, bases),
``world/points/<name>``, ``plots/<quantity>/<column>`` (scalars).
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import numpy as np

from .._validate import as_path
from ._recording import Recording, recording_of, require_extra
from .files import atomic_path

__all__ = ["write_rerun", "TIMELINE", "entity_name"]

#: The timeline every sample is logged on (a duration, s).
TIMELINE = "time"
#: Point radius and line radius in the 3D view, m.
_POINT_M = 0.02
_LINE_M = 0.004


def entity_name(text: str) -> str:
    """A label as an entity-path part (``"cable tensions"`` -> ``"cable_tensions"``)."""
    return re.sub(r"[^A-Za-z0-9_]+", "_", text).strip("_") or "_"


def write_rerun(result: Any, path: str | os.PathLike[str], *, length_unit: Any = None,
                times: Any = None, team: Any = None, formation: Any = None,
                robot: Any = None, plan: Any = None) -> Path:
    """Write ``result`` as a Rerun recording with a blueprint (entities in the module
    docstring).

    Parameters, return value and errors are those of :func:`taut.io.mcap.write_mcap`
    (``path`` ends in ``.rrd``; the extra is ``rerun``).

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> from taut.sheet import Sheet, SheetTeam, simulate
    >>> team = SheetTeam(Sheet.regular(4, 0.5), hold_height=0.8, mass=1.0)
    >>> steps = 0.8 * Sheet.regular(4, 0.5).vertices + np.linspace(0, 0.1, 5)[:, None, None]
    >>> sim = simulate(team, steps)
    >>> out = os.path.join(tempfile.mkdtemp(), "sim.rrd")
    >>> write_rerun(sim, out, length_unit="m", times=np.arange(5.0)).name
    'sim.rrd'
    """
    rr = require_extra("rerun", "rerun", "rerun")
    rec = recording_of(result, length_unit=length_unit, times=times, team=team,
                       formation=formation, robot=robot, plan=plan)
    target = Path(as_path(path))
    with atomic_path(target) as tmp:
        stream = rr.RecordingStream("taut", recording_id=f"taut-{rec.kind}")
        stream.save(tmp, default_blueprint=_blueprint(rr, rec))
        _log_static(rr, stream, rec)
        _log_samples(rr, stream, rec)
        _log_series(rr, stream, rec)
        stream.flush()
        stream.disconnect()
    return target


def _blueprint(rr: Any, rec: Recording) -> Any:
    import rerun.blueprint as rrb

    plots = [rrb.TimeSeriesView(origin=f"plots/{entity_name(s.name)}",
                                name=f"{s.name} [{s.unit}]") for s in rec.series]
    return rrb.Blueprint(rrb.Horizontal(rrb.Spatial3DView(origin="world", name="3D [m]"),
                                        rrb.Vertical(*plots), column_shares=[3, 2]),
                         collapse_panels=True)


def _log_static(rr: Any, stream: Any, rec: Recording) -> None:
    for name, segs in rec.static_lines:
        stream.log(f"world/static/{entity_name(name)}",
                   rr.LineStrips3D(list(segs), radii=_LINE_M, colors=(110, 110, 110)),
                   static=True)
    for name, pts in rec.points:
        stream.log(f"world/points/{entity_name(name)}",
                   rr.Points3D(pts, radii=_POINT_M, labels=[name] * len(pts)), static=True)


def _log_samples(rr: Any, stream: Any, rec: Recording) -> None:
    labels = [f"{rec.robot_label} {i + 1}" for i in range(rec.robot_xyz.shape[1])]
    for k, t in enumerate(rec.times):
        stream.set_time(TIMELINE, duration=float(t))
        if np.all(np.isfinite(rec.object_xyz[k])):
            stream.log("world/object", rr.Points3D(rec.object_xyz[k][None],
                                                   radii=2 * _POINT_M, colors=(200, 40, 40)))
        else:
            stream.log("world/object", rr.Clear(recursive=False))
        stream.log("world/robots", rr.Points3D(rec.robot_xyz[k], radii=_POINT_M,
                                               labels=labels, colors=(40, 90, 200)))
        ends = rec.cable_ends[k][rec.cable_taut[k]]
        stream.log("world/cables", rr.LineStrips3D([e for e in ends if np.all(np.isfinite(e))],
                                                   radii=_LINE_M, colors=(230, 130, 20)))
        ring = np.concatenate([rec.outline[k], rec.outline[k][:1]])
        stream.log("world/outline", rr.LineStrips3D([ring], radii=_LINE_M,
                                                    colors=(50, 100, 200)))
        if rec.surface is not None and np.all(np.isfinite(rec.surface[0][k])):
            stream.log("world/sheet", rr.Mesh3D(vertex_positions=rec.surface[0][k],
                                                triangle_indices=rec.surface[1],
                                                albedo_factor=(60, 130, 230, 90)))


def _log_series(rr: Any, stream: Any, rec: Recording) -> None:
    index = [rr.TimeColumn(TIMELINE, duration=rec.times)]
    for s in rec.series:
        for j, label in enumerate(s.labels):
            stream.send_columns(f"plots/{entity_name(s.name)}/{entity_name(label)}", index,
                                rr.Scalars.columns(scalars=s.values[:, j]))
