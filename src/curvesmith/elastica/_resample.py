"""A plain chord-length equilateral resampler for :func:`curvesmith.elastica.fit`.

Walks along the polyline and puts the next vertex at the first later point of
the polyline whose straight-line distance from the current vertex is the step
``r``; stops when no later point is that far. This keeps model order and gives
segments of length exactly ``r``. It differs from the keyline rule of the paper
(Figs. 11-13: among several candidates take the one closest to the right end)
only where the circle of radius ``r`` cuts the polyline more than once ahead of
the current vertex, i.e. on features smaller than ``r``.
"""

from __future__ import annotations

import numpy as np

__all__ = ["equilateral"]


def equilateral(p: np.ndarray, step: float) -> np.ndarray:
    """Equal-chord resampling of an open polyline with chord `step` (validated input).

    Parameters
    ----------
    p : (N, 2) ndarray
        Vertices (validated, float64).
    step : float
        Chord length ``r > 0``.

    Returns
    -------
    (M, 2) ndarray
        Vertices ``A_1 = p[0], A_2, ...`` with ``|A_{j+1} - A_j| = step``.
    """
    out = [p[0].copy()]
    cur = p[0].copy()
    seg = 0  # search from this segment on
    t_min = 0.0  # and from this parameter on it
    n_seg = p.shape[0] - 1
    while seg < n_seg:
        found = False
        for i in range(seg, n_seg):
            a, b = p[i], p[i + 1]
            d = b - a
            f = a - cur
            aa = float(d @ d)
            if aa == 0.0:
                continue
            bb = 2.0 * float(f @ d)
            cc = float(f @ f) - step * step
            disc = bb * bb - 4.0 * aa * cc
            if disc < 0.0:
                continue
            root = np.sqrt(disc)
            lo = t_min if i == seg else 0.0
            hits = [t for t in ((-bb - root) / (2 * aa), (-bb + root) / (2 * aa)) if lo < t <= 1.0]
            if hits:
                t = min(hits)
                cur = a + t * d
                out.append(cur.copy())
                seg, t_min = i, t
                found = True
                break
        if not found:
            break
    return np.array(out)
