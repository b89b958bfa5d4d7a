"""The interior angle of the alpha-profile, one function in two forms with the same bits.

The profile of every CCA1 step is a function of the interior angle
``theta = atan2(|cross|, -dot)`` at every vertex (``cross``, ``dot`` of the unit
edge vectors before and after it). The C library's ``atan2`` costs 16-26 ns a
call on the project's machines (glibc's correctly rounding algorithm), which was
about a sixth of a compiled CCA1 step. This is the ``atan`` of fdlibm (Sun
Microsystems' freely distributable libm, ``s_atan.c``; its notice: "Permission to
use, copy, modify, and distribute this software is freely granted, provided that
this notice is preserved"): the argument reduced to ``|t| < 7/16`` around one of
four table angles, an odd polynomial of degree 23 (11 coefficients), error below
one ulp, in about 6 ns. The angle is ``atan(|cross| / |dot|)`` as in fdlibm's
``atan2``, whose rounded ratio adds up to one ulp more where the angle lies just
below a power of two and the ratio just above it: below 1.6 ulp in all (1.51 the
worst found), against half an ulp for glibc's. The interior angle near ``pi``
(almost every vertex of a smoothed curve) is ``pi - (atan(|cross| / dot) -
pi_lo)``, fdlibm's composition, so its error is about half an ulp there. The
profile does not need more: any alpha keeps every area exact, and the kernel and
its reference share these bits.

:func:`interior_angle` is the whole-array numpy form (the N-d step, which is the
reference of the compiled kernel); :mod:`curvesmith.cca._kernel` compiles the
scalar form from the same constants and operations, in the same order (numba
compiles without fused multiply-adds), so both give the same bits: the tests
compare them and bound the error against mpmath.
"""

from __future__ import annotations

import numpy as np

#: atan(1/2), atan(1), atan(3/2), atan(inf): high and low parts (fdlibm's atanhi, atanlo).
ATAN_HI = (
    4.63647609000806093515e-01,
    7.85398163397448278999e-01,
    9.82793723247329054082e-01,
    1.57079632679489655800e00,
)
ATAN_LO = (
    2.26987774529616870924e-17,
    3.06161699786838301793e-17,
    1.39033110312309984516e-17,
    6.12323399573676603587e-17,
)
#: fdlibm's aT: atan(x) = x - x (aT0 x^2 + aT1 x^4 + ...), |x| < 7/16.
AT = (
    3.33333333333329318027e-01,
    -1.99999999998764832476e-01,
    1.42857142725034663711e-01,
    -1.11111104054623557880e-01,
    9.09088713343650656196e-02,
    -7.69187620504482999495e-02,
    6.66107313738753120669e-02,
    -5.83357013379057348645e-02,
    4.97687799461593236017e-02,
    -3.65315727442169155270e-02,
    1.62858201153657823623e-02,
)
#: pi = PI + PI_LO (fdlibm's pi, pi_lo).
PI = 3.1415926535897931160e00
PI_LO = 1.2246467991473531772e-16
HALF_PI = 0.5 * PI
#: Reduction bounds (fdlibm compares the high words; these are the same bounds).
HUGE = 2.0**66  # atan(t) = pi / 2 to the last bit from here on
TINY = 2.0**-27  # atan(t) = t to the last bit below
B0, B1, B2, B3 = 0.4375, 0.6875, 1.1875, 2.4375


def atan_nonneg(t: np.ndarray) -> np.ndarray:
    """The ``atan`` of fdlibm, of every ``t >= 0`` (NaN stays NaN), whole-array."""
    t = np.asarray(t, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        # the reduced argument of each range; every range's formula as fdlibm writes it
        x = np.select(
            [t < B0, t < B1, t < B2, t < B3],
            [t, (2.0 * t - 1.0) / (2.0 + t), (t - 1.0) / (t + 1.0), (t - 1.5) / (1.0 + 1.5 * t)],
            -1.0 / t,
        )
        idx = np.select([t < B0, t < B1, t < B2, t < B3], [-1, 0, 1, 2], 3)
        z = x * x
        w = z * z
        a0, a1, a2, a3, a4, a5, a6, a7, a8, a9, a10 = AT
        s1 = z * (a0 + w * (a2 + w * (a4 + w * (a6 + w * (a8 + w * a10)))))
        s2 = w * (a1 + w * (a3 + w * (a5 + w * (a7 + w * a9))))
        hi = np.take(ATAN_HI, np.maximum(idx, 0))
        lo = np.take(ATAN_LO, np.maximum(idx, 0))
        out = np.where(idx < 0, x - x * (s1 + s2), hi - ((x * (s1 + s2) - lo) - x))
    out = np.where(t < TINY, t, out)
    return np.where(t >= HUGE, ATAN_HI[3] + ATAN_LO[3], out)


def interior_angle(scross: np.ndarray, dot: np.ndarray) -> np.ndarray:
    """``atan2(scross, -dot)`` for ``scross >= 0``: the interior angle, in ``[0, pi]``.

    ``scross`` and ``dot`` are ``|cross|`` and the dot product of the unit edge vectors
    at each vertex. A vertex with ``dot = 0`` (of either sign) has the angle ``pi / 2``,
    or ``pi`` when ``scross`` is 0 as well (``atan2(+0, -0)``: an edge of length 0, or an
    open curve's absent wrap edge); NaN stays NaN.
    """
    y = np.asarray(scross, dtype=float)
    d = np.asarray(dot, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        z = atan_nonneg(y / np.abs(d))
    out = np.where(d > 0.0, PI - (z - PI_LO), z)
    return np.where(d == 0.0, np.where(y == 0.0, PI, np.where(y > 0.0, HALF_PI, y)), out)
