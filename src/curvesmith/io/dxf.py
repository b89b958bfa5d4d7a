"""DXF output for CAD users: each curve as a 3D polyline (``POLYLINE`` with 3D vertices).

Written with `ezdxf <https://ezdxf.mozman.at/>`_ (DXF R2010). 2D curves get ``z = 0``.
Closed curves are written as closed polylines. A curve's ``properties["id"]`` (if any)
names its layer. DXF is written, not read, so it is not a registered format of
:func:`curvesmith.io.read_curves` (registering it would change the format lists that
other commands print); ``curvesmith fair -o faired.dxf`` calls :func:`write_dxf`.

Examples
--------
>>> import io
>>> from curvesmith.io import Curve
>>> from curvesmith.io.dxf import write_dxf
>>> buf = io.StringIO()
>>> write_dxf([Curve([[0, 0, 0], [1, 0, 2], [2, 1, 2]], closed=False)], buf)
>>> "POLYLINE" in buf.getvalue()
True
"""

from __future__ import annotations

import io as _stdio
import re

from ._core import _check_curves, _write_text

__all__ = ["write_dxf"]


def write_dxf(curves, dest) -> None:
    """Write curves as 3D polylines to a DXF file (or text stream).

    Parameters
    ----------
    curves : iterable of Curve
    dest : str or path-like or text file object

    Raises
    ------
    CurveFormatError
        Nothing to write, or the file cannot be written.
    """
    import ezdxf

    out = _check_curves(curves)
    doc = ezdxf.new("R2010")
    msp = doc.modelspace()
    for i, c in enumerate(out):
        pts = c.points
        xyz = pts if pts.shape[1] == 3 else [(x, y, 0.0) for x, y in pts.tolist()]
        name = str(c.properties.get("id", f"curve_{i}"))
        layer = re.sub(r"[^A-Za-z0-9_-]", "_", name) or f"curve_{i}"
        if layer not in doc.layers:
            doc.layers.add(layer)
        line = msp.add_polyline3d([tuple(map(float, p)) for p in xyz], dxfattribs={"layer": layer})
        if c.closed:
            line.close(True)
    buf = _stdio.StringIO()
    doc.write(buf)
    _write_text(dest, buf.getvalue())
