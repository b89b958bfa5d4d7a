"""The compiled affine arc length construction equals the Python loop it replaced, bit for bit.

The construction (section 4: each vertex the first intersection of the replacement curve
with ``det(x_{i-1} - x_{i-2}, z - x_{i-1}) = A``) runs thousands of times in the searches
for ``t_1``; it is compiled with numba (curvesmith.affine._kernel). The Python loop it
was written as is kept in tests/affine_construct_reference.py as the oracle: on open and
closed curves, convex and with inflections, at many (t_1, A), over- and under-shooting
ones included, both give the same vertices, parameters and edge counts to the last bit.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from curvesmith.affine.approximation import replacement_curve
from curvesmith.internals import AffineConstructionCurve, affine_construct

sys.path.insert(0, str(Path(__file__).parent))
from affine_construct_reference import construct as reference


def _ellipse(n: int, closed: bool) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi if closed else 2.5, n, endpoint=not closed)
    return np.c_[3 * np.cos(t), 2 * np.sin(t)]


def _wave(n: int) -> np.ndarray:
    rng = np.random.default_rng(4)
    t = np.sort(rng.uniform(0, 3.0, n))  # uneven sampling, an inflection at t = pi/2
    return np.c_[t * 100.0, 40.0 * np.sin(t) + 0.01 * rng.standard_normal(n)]


CASES = [
    ("ellipse closed", _ellipse(400, True), True),
    ("ellipse arc", _ellipse(300, False), False),
    ("uneven wave", _wave(500), False),
]


@pytest.mark.parametrize(("name", "samples", "closed"), CASES, ids=[c[0] for c in CASES])
def test_compiled_construction_is_the_python_loop(name, samples, closed):
    cv = AffineConstructionCurve(replacement_curve(samples, closed=closed))
    total = sum(cv.len)
    compared = 0
    for m in (3, 8, 25, 60):
        scale = (total / m) ** 3  # A ~ (S / n)^3
        for area in (0.3 * scale, scale, 3.0 * scale, -scale):
            for t1 in (0.05, 0.7, 1.9, 4.3, 11.0):
                for extrapolate in (True, False):
                    t_end = float(cv.n) if closed else float(cv.n) - 0.5
                    args = (cv, 0.25, t1, area, m, t_end)
                    got = affine_construct(*args, extrapolate=extrapolate)
                    want = reference(*args, extrapolate=extrapolate)
                    assert got == want, (m, area, t1, extrapolate)
                    compared += got[3]
    assert compared > 200  # vertices constructed and compared (fewer past an inflection)
