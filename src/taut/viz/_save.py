"""Saving figures and animations atomically: drawn into a temporary file in the target's
folder and renamed over the target once complete (:func:`taut.io.atomic_path`), so an
interrupted or failed save never leaves half a PNG or GIF, nor destroys the old one."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..io.files import atomic_path


def save_figure(fig: Any, path: str | Path, *, dpi: int) -> None:
    """``fig.savefig(path, dpi=dpi)``, atomically (the format follows the suffix)."""
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi)


def save_animation(anim: Any, path: str | Path, *, fps: int) -> None:
    """An animated GIF of ``anim`` at ``fps`` frames per second (Pillow), atomically."""
    from matplotlib.animation import PillowWriter

    with atomic_path(path) as tmp:
        anim.save(str(tmp), writer=PillowWriter(fps=fps))
