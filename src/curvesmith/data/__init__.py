"""Small bundled sample curves used by ``curvesmith demo``, the docs and the tests.

Every file is CSV with a header ``x,y`` (or ``x,y,z``). See ``README.md`` in
this folder for the provenance of each file.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

import numpy as np

__all__ = ["load_points", "path"]


def path(name: str) -> Path:
    """Filesystem path of a bundled data file.

    Parameters
    ----------
    name : str
        File name inside ``curvesmith/data``, e.g. ``"leaf.csv"``.
    """
    p = Path(str(resources.files(__package__).joinpath(name)))
    if not p.is_file():
        from ..errors import CurveError

        raise CurveError(f"name must be a bundled data file, got {name!r}")
    return p


def load_points(name: str) -> np.ndarray:
    """Load a bundled CSV curve as an ``(N, 2)`` or ``(N, 3)`` float64 array."""
    return np.loadtxt(path(name), delimiter=",", skiprows=1, ndmin=2)
