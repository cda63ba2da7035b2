"""``--mcap FILE`` and ``--rerun FILE``: robot-viewer recordings of a command's result.

Both outputs are checked before any work (:func:`recording_paths`: the file, its
extension, not one of the command's inputs, the extra installed) and written by the
library (:func:`taut.io.write_mcap`, :func:`taut.io.write_rerun`) once the result exists.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

import typer

from ..errors import InvalidInputError, ScenarioError
from ._paths import output_path
from ._progress import working

__all__ = ["MCAP_HELP", "RERUN_HELP", "recording_paths", "write_recordings", "sheet_unit"]

MCAP_HELP = ("Also write a ROS 2 recording (MCAP; poses, paths, cables, markers, /tf; m, s) "
             "to this file (.mcap; extra mcap). Topics: docs/recordings.md.")
RERUN_HELP = ("Also write a Rerun recording with a 3D view and time series (.rrd; extra "
              "rerun).")

#: Option -> (accepted extensions, module the writer needs, extra that installs it).
_KINDS = {"--mcap": ((".mcap",), "mcap_ros2.writer", "mcap"),
          "--rerun": ((".rrd",), "rerun", "rerun")}


def recording_paths(mcap: Optional[Path], rerun: Optional[Path]
                    ) -> tuple[Optional[Path], Optional[Path]]:
    """Validate ``--mcap`` and ``--rerun`` before any work; a missing extra is one line
    naming it."""
    out = []
    for option, value in (("--mcap", mcap), ("--rerun", rerun)):
        suffixes, module, extra = _KINDS[option]
        path = output_path(value, option, suffixes)
        if path is not None:
            from ..io._recording import require_extra
            require_extra(module, extra, option)
        out.append(path)
    return out[0], out[1]


def sheet_unit(units: str | None, mcap: Optional[Path], rerun: Optional[Path]) -> str | None:
    """The scenario's length unit for a sheet recording (metres in the file); a scenario
    without ``units:`` cannot be recorded."""
    if (mcap is not None or rerun is not None) and units is None:
        raise ScenarioError("units", "missing: --mcap and --rerun record metres, so the "
                                     "scenario must say its length unit (e.g. 'units: mm')")
    if mcap is None and rerun is None:
        return None
    from ..io._recording import metres_per_unit
    try:
        metres_per_unit(units)
    except InvalidInputError as exc:
        raise ScenarioError("units", exc.problem) from None
    return units


def write_recordings(result: Any, mcap: Optional[Path], rerun: Optional[Path], *,
                     quiet: bool = False, **context: Any) -> None:
    """Write the requested recordings of ``result`` (``context``: what
    :func:`taut.io.write_mcap` needs besides the result) and say where."""
    if mcap is not None:
        from ..io.mcap import write_mcap
        with working("MCAP recording"):
            write_mcap(result, mcap, **context)
        if not quiet:
            typer.echo(f"ROS 2 recording written to {mcap}")
    if rerun is not None:
        from ..io.rerun import write_rerun
        with working("Rerun recording"):
            write_rerun(result, rerun, **context)
        if not quiet:
            typer.echo(f"Rerun recording written to {rerun}")
