"""Discrete affine geometry of polylines (Käferböck, sections 2 and 3).

Implements the affine polyline coordinates (eq. 1), reconstruction from them
(eq. 2), the discrete affine lengths ``L_2`` (eq. 3) and ``L_n`` (eq. 8), the
affine normals, curvatures (eq. 4) and evolute (eq. 5) of affine arc length
polylines, and their outer, inner and middle osculating conics (Theorem 2,
eq. 7).

Index conventions
-----------------
For an open polyline ``x_0 .. x_{N-1}`` (``N`` rows) with edges
``v_i = x_{i+1} - x_i`` the paper's quantities live at interior positions; the
arrays returned here start at the first defined one:

* ``A[j] = A_{j+1} = det(v_j, v_{j+1})``, ``j = 0 .. N-3``;
* ``B[j] = B_{j+1} = det(v_j, v_{j+2})``, ``j = 0 .. N-4``;
* ``normals(...)[j] = n_{j+1} = x_j - 2 x_{j+1} + x_{j+2}``;
* ``curvature(...)[j] = k_{j+1}``, the curvature of the quadruple
  ``x_j .. x_{j+3}`` (``N - 3`` values).

For a closed polygon (``closed=True``, ``N`` distinct vertices) every array has
``N`` entries and index ``i`` is the paper's index ``i`` taken cyclically.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from .._validate import as_choice, as_float, as_int, as_points
from ..errors import CurveError
from ..geometry import det2

__all__ = [
    "Conic",
    "affine_length",
    "affine_length_elements",
    "coordinates",
    "curvature",
    "evolute",
    "is_affine_arc_length",
    "normals",
    "osculating_conic",
    "osculating_curvatures",
    "reconstruct",
]


def _coords(p: np.ndarray, closed: bool) -> tuple[np.ndarray, np.ndarray]:
    if closed:
        v = np.roll(p, -1, axis=0) - p  # v_i = x_{i+1} - x_i
        vm = np.roll(v, 1, axis=0)  # v_{i-1}
        return det2(vm, v), det2(vm, np.roll(v, -1, axis=0))
    v = np.diff(p, axis=0)
    return det2(v[:-1], v[1:]), det2(v[:-2], v[2:])


def coordinates(points: ArrayLike, *, closed: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Affine polyline coordinates ``A_i, B_i`` (Käferböck, eq. 1).

    ``A_i = det(v_{i-1}, v_i)`` and ``B_i = det(v_{i-1}, v_{i+1})`` with
    ``v_i = x_{i+1} - x_i``. Both are invariant under equiaffine maps
    (``x -> M x + c``, ``det M = 1``); together with three starting vertices they
    determine the polyline (:func:`reconstruct`).

    Parameters
    ----------
    points : (N, 2) array_like
        Vertices, ``N >= 3`` (open) or ``N >= 3`` distinct ring vertices (closed;
        a repeated closing vertex is dropped).
    closed : bool, optional
        Treat the points as a closed polygon (cyclic indices).

    Returns
    -------
    A : (N - 2,) ndarray, or (N,) if closed
        ``A[j] = A_{j+1}`` (open) or ``A[i] = A_i`` (closed).
    B : (N - 3,) ndarray, or (N,) if closed
        ``B[j] = B_{j+1}`` (open) or ``B[i] = B_i`` (closed).

    Examples
    --------
    >>> A, B = coordinates([[0, 0], [1, 0], [2, 1], [2, 3]])
    >>> A.tolist(), B.tolist()
    ([1.0, 2.0], [2.0])
    """
    p = as_points(points, closed=closed, min_points=3)
    return _coords(p, closed)


def reconstruct(A: ArrayLike, B: ArrayLike, start: ArrayLike) -> np.ndarray:
    """Rebuild an open polyline from its affine coordinates and three vertices (eq. 2).

    Uses ``B_i v_i = A_{i+1} v_{i-1} + A_i v_{i+1}`` solved for ``v_{i+1}``.
    That is the Cramer identity of three plane vectors, so it holds for every
    polyline; solving it needs ``A_i != 0`` (the paper's side condition
    "as long as ``B_i != 0``" is the condition for solving it for ``v_i``
    instead; verified in the tests by reconstructing polylines with ``B_i = 0``).

    Parameters
    ----------
    A : (M,) array_like
        ``A_1 .. A_M`` (all non-zero).
    B : (M - 1,) array_like
        ``B_1 .. B_{M-1}``.
    start : (3, 2) array_like
        ``x_0, x_1, x_2``; must satisfy ``det(x_1 - x_0, x_2 - x_1) = A_1``
        (relative tolerance 1e-9).

    Returns
    -------
    (M + 2, 2) ndarray
        ``x_0 .. x_{M+1}``.

    Examples
    --------
    >>> reconstruct([1, 2], [2], [[0, 0], [1, 0], [2, 1]]).tolist()
    [[0.0, 0.0], [1.0, 0.0], [2.0, 1.0], [2.0, 3.0]]
    """
    a = np.asarray(A, dtype=float).ravel()
    b = np.asarray(B, dtype=float).ravel()
    s = as_points(start, name="start", min_points=3)
    if s.shape[0] != 3:
        raise CurveError(f"start must have shape (3, 2), got ({s.shape[0]}, 2)")
    if a.size < 1 or b.size != a.size - 1:
        raise CurveError(f"B must have len(A) - 1 = {a.size - 1} entries, got {b.size}")
    if not (np.isfinite(a).all() and np.isfinite(b).all()):
        raise CurveError("A and B must be finite")
    if np.any(a == 0):
        raise CurveError(f"A must be non-zero, got A_{int(np.flatnonzero(a == 0)[0]) + 1} = 0")
    a1 = float(det2(s[1] - s[0], s[2] - s[1]))
    if abs(a1 - a[0]) > 1e-9 * max(abs(a[0]), abs(a1)):
        raise CurveError(f"start must satisfy det(x1 - x0, x2 - x1) = A_1 = {a[0]:g}, got {a1:g}")
    out = np.empty((a.size + 2, 2))
    out[:3] = s
    vm, v = s[1] - s[0], s[2] - s[1]
    for i in range(1, a.size):  # paper index i: v_{i+1} from v_{i-1}, v_i
        vn = (b[i - 1] * v - a[i] * vm) / a[i - 1]
        out[i + 2] = out[i + 1] + vn
        vm, v = v, vn
    return out


def _signed_root(x: np.ndarray, exponent: float) -> np.ndarray:
    return np.sign(x) * np.abs(x) ** exponent


def _volume_elements(p: np.ndarray, closed: bool) -> np.ndarray:
    d = p.shape[1]
    v = (np.roll(p, -1, axis=0) - p) if closed else np.diff(p, axis=0)
    m = v.shape[0] if closed else v.shape[0] - d + 1
    idx = (np.arange(m)[:, None] + np.arange(d)[None, :]) % v.shape[0]
    return np.linalg.det(v[idx]) if d > 2 else det2(v[idx[:, 0]], v[idx[:, 1]])


def affine_length_elements(points: ArrayLike, *, closed: bool = False) -> np.ndarray:
    """Discrete affine length elements ``L_n(x_i, .., x_{i+n})`` in ``R^n`` (eq. 8).

    ``L_n = det(dx_i, .., dx_{i+n-1})^(2 / (n (n + 1)))`` where ``n`` is the
    dimension (number of columns); in the plane ``L_2(x_{i-1}, x_i, x_{i+1}) =
    A_i^(1/3)``. The root is taken with the sign of the determinant
    (``sign(D) |D|^e``) so that negatively oriented elements (inflections, or a
    clockwise curve) have negative length rather than no real value.

    Parameters
    ----------
    points : (N, n) array_like
        Vertices in ``R^n``, ``n >= 2``, ``N >= n + 1`` (open) or ``N >= n + 1``
        ring vertices (closed).
    closed : bool, optional
        Closed polygon: all ``N`` cyclic elements.

    Returns
    -------
    (N - n,) ndarray, or (N,) if closed
        One length per run of ``n + 1`` consecutive vertices.

    Examples
    --------
    >>> affine_length_elements([[0, 0], [1, 0], [2, 1], [2, 9]]).tolist()
    [1.0, 2.0]
    """
    p = as_points(points, closed=closed, min_points=3, dim=None)
    d = p.shape[1]
    if d < 2:
        raise CurveError(f"points must have dimension n >= 2, got {d}")
    if p.shape[0] < d + 1:
        raise CurveError(f"points in R^{d} must have at least {d + 1} points, got {p.shape[0]}")
    return _signed_root(_volume_elements(p, closed), 2.0 / (d * (d + 1)))


def affine_length(points: ArrayLike, *, closed: bool = False) -> float:
    """Discrete affine length: ``L_2`` (eq. 3) in the plane, ``L_n`` (eq. 8) in ``R^n``.

    The sum of :func:`affine_length_elements`. It is invariant under equiaffine
    maps, kept by Chaikin subdivision (section 2.5) and, in ``R^n``, by one
    Lane–Riesenfeld step of degree ``n`` (Theorem 5).

    Parameters
    ----------
    points : (N, n) array_like
        Vertices in ``R^n``, ``n >= 2``.
    closed : bool, optional
        Closed polygon.

    Returns
    -------
    float

    Examples
    --------
    >>> affine_length([[0, 0], [1, 0], [2, 1], [2, 9]])
    3.0
    """
    return float(np.sum(affine_length_elements(points, closed=closed)))


def is_affine_arc_length(points: ArrayLike, *, closed: bool = False, rtol: float = 1e-8) -> bool:
    """Whether a polyline is an affine arc length polyline (eq. 9: all ``A_i`` equal, non-zero).

    Parameters
    ----------
    points : (N, n) array_like
        Vertices in ``R^n``, ``n >= 2``.
    closed : bool, optional
        Closed polygon (the elements across the seam count too).
    rtol : float, optional
        Allowed relative spread ``max |D_i - mean D| <= rtol |mean D|`` of the
        volume elements ``D_i = det(dx_i, .., dx_{i+n-1})``.

    Returns
    -------
    bool

    Examples
    --------
    >>> is_affine_arc_length([[0, 0], [1, 1], [2, 4], [3, 9]])
    True
    >>> is_affine_arc_length([[0, 0], [1, 1], [2, 4], [3, 10]])
    False
    """
    rtol = as_float(rtol, name="rtol", low=0.0, low_open=False)
    p = as_points(points, closed=closed, min_points=3, dim=None)
    if p.shape[0] < p.shape[1] + 1:
        raise CurveError(
            f"points in R^{p.shape[1]} must have at least {p.shape[1] + 1} points, got {p.shape[0]}"
        )
    dets = _volume_elements(p, closed)
    mean = float(np.mean(dets))
    return bool(mean != 0.0 and np.max(np.abs(dets - mean)) <= rtol * abs(mean))


def normals(points: ArrayLike, *, closed: bool = False) -> np.ndarray:
    """Discrete affine normals ``n_i = x_{i-1} - 2 x_i + x_{i+1}`` (section 2.3).

    Parameters
    ----------
    points : (N, 2) array_like
        Vertices.
    closed : bool, optional
        Closed polygon.

    Returns
    -------
    (N - 2, 2) ndarray, or (N, 2) if closed
        ``normals[j] = n_{j+1}`` (open) or ``n_i`` (closed).

    Examples
    --------
    >>> normals([[0, 0], [1, 1], [2, 4]]).tolist()
    [[0.0, 2.0]]
    """
    p = as_points(points, closed=closed, min_points=3)
    if closed:
        return np.roll(p, 1, axis=0) - 2.0 * p + np.roll(p, -1, axis=0)
    return p[:-2] - 2.0 * p[1:-1] + p[2:]


def _checked_area(p: np.ndarray, closed: bool, rtol: float) -> tuple[float, np.ndarray]:
    a, b = _coords(p, closed)
    mean = float(np.mean(a))
    spread = float(np.max(np.abs(a - mean))) if a.size else 0.0
    if mean == 0.0 or spread > rtol * abs(mean):
        rel = spread / abs(mean) if mean != 0.0 else float("inf")
        raise CurveError(
            "points must be an affine arc length polyline (all A_i equal and non-zero), "
            f"got relative spread {rel:.3g} of A_i > rtol = {rtol:g}"
        )
    return mean, b


def curvature(points: ArrayLike, *, closed: bool = False, rtol: float = 1e-6) -> np.ndarray:
    """Discrete affine curvatures ``k_i`` of an affine arc length polyline (eq. 4).

    ``k_i`` is defined by ``d^3 x_{i-1} + k_i dx_i = 0``; equivalently
    ``x_{i+2} - x_{i-1} = (3 - k_i)(x_{i+1} - x_i)``, ``k_i = det(n_i, n_{i+1}) / A``
    and ``k_i = 2 - B_i / A``. The last form is computed; the tests check that all
    four agree. The middle osculating conic has affine curvature ``k_i A^(-2/3)``
    (eq. 7).

    Parameters
    ----------
    points : (N, 2) array_like
        An affine arc length polyline, ``N >= 4``.
    closed : bool, optional
        Closed polygon (cyclic ``k_i``).
    rtol : float, optional
        Tolerance of the affine arc length test (see :func:`is_affine_arc_length`).

    Returns
    -------
    (N - 3,) ndarray, or (N,) if closed
        ``k[j] = k_{j+1}`` for the quadruple ``x_j .. x_{j+3}`` (open), or ``k_i``
        for ``x_{i-1} .. x_{i+2}`` (closed).

    Raises
    ------
    CurveError
        If the ``A_i`` are not constant within `rtol`.

    Examples
    --------
    An affinely regular hexagon (a regular one) has constant ``k = 2 - 2 cos(pi/3) = 1``:

    >>> t = np.arange(6) * np.pi / 3
    >>> np.round(curvature(np.c_[np.cos(t), np.sin(t)], closed=True), 12).tolist()
    [1.0, 1.0, 1.0, 1.0, 1.0, 1.0]
    """
    rtol = as_float(rtol, name="rtol", low=0.0, low_open=False)
    p = as_points(points, closed=closed, min_points=4)
    area, b = _checked_area(p, closed, rtol)
    return 2.0 - b / area


def evolute(points: ArrayLike, *, closed: bool = False, rtol: float = 1e-6) -> np.ndarray:
    """Discrete affine evolute ``xi_i = x_i + n_i / k_i`` of an affine arc length polyline (eq. 5).

    ``xi_i`` is the intersection of the consecutive affine normal lines at
    ``x_i`` and ``x_{i+1}``; eq. (5) also gives ``xi_i = x_{i+1} + n_{i+1} / k_i``
    (checked in the tests).

    Parameters
    ----------
    points : (N, 2) array_like
        An affine arc length polyline, ``N >= 4``.
    closed : bool, optional
        Closed polygon.
    rtol : float, optional
        Tolerance of the affine arc length test.

    Returns
    -------
    (N - 3, 2) ndarray, or (N, 2) if closed
        Aligned with :func:`curvature`.

    Raises
    ------
    CurveError
        If some ``k_i`` is zero (the evolute point is at infinity: the
        osculating conics are parabolas), or the polyline is not affine arc length.

    Examples
    --------
    The evolute of an affinely regular polygon is its centre:

    >>> t = np.arange(7) * 2 * np.pi / 7
    >>> bool(np.abs(evolute(np.c_[2 + np.cos(t), np.sin(t)], closed=True) - [2, 0]).max() < 1e-12)
    True
    """
    rtol = as_float(rtol, name="rtol", low=0.0, low_open=False)
    p = as_points(points, closed=closed, min_points=4)
    area, b = _checked_area(p, closed, rtol)
    k = 2.0 - b / area
    scale = np.max(np.abs(b)) / abs(area) if b.size else 1.0
    zero = np.abs(k) <= 1e-13 * max(1.0, scale)
    if zero.any():
        i = int(np.flatnonzero(zero)[0])
        raise CurveError(
            f"evolute point {i} is at infinity: k = {k[i]:.3g} (parabolic quadruple); "
            "the osculating conics there are parabolas"
        )
    if closed:
        return p + (np.roll(p, 1, axis=0) - 2.0 * p + np.roll(p, -1, axis=0)) / k[:, None]
    return p[1:-2] + (p[:-3] - 2.0 * p[1:-2] + p[2:-1]) / k[:, None]


# --------------------------------------------------------------------------- conics


@dataclass(frozen=True)
class Conic:
    """A plane conic ``[x, y, 1] M [x, y, 1]^T = 0`` (an osculating conic of Theorem 2).

    Attributes
    ----------
    matrix : (3, 3) ndarray
        Symmetric matrix ``M``, scaled to unit Frobenius norm.
    kind : str
        ``"ellipse"``, ``"parabola"`` or ``"hyperbola"``.
    centre : (2,) ndarray or None
        Centre (``None`` for a parabola).
    affine_curvature : float
        The conic's constant smooth affine curvature: ``(a b)^(-2/3)`` for an
        ellipse with semi-axes ``a, b``, ``-(a b)^(-2/3)`` for a hyperbola with
        semi-axes ``a, b``, 0 for a parabola.
    """

    matrix: np.ndarray
    kind: str
    centre: np.ndarray | None
    affine_curvature: float

    def evaluate(self, points: ArrayLike) -> np.ndarray:
        """Value of the quadratic form at points (zero on the conic).

        Parameters
        ----------
        points : (M, 2) array_like
            Points.

        Returns
        -------
        (M,) ndarray
        """
        p = np.atleast_2d(np.asarray(points, dtype=float))
        h = np.c_[p, np.ones(len(p))]
        return np.einsum("ij,jk,ik->i", h, self.matrix, h)

    def sample(self, t: ArrayLike, *, branch: int = 1) -> np.ndarray:
        """Points of the conic for parameters `t`.

        Ellipse: ``centre + U (cos t, sin t)``; hyperbola: ``centre + U (branch cosh t,
        sinh t)``; parabola: the point whose coordinate across the axis is `t`
        (in units of the matrix's eigenvector frame).

        Parameters
        ----------
        t : (M,) array_like
            Parameters.
        branch : {1, -1}, optional
            Hyperbola branch.

        Returns
        -------
        (M, 2) ndarray
        """
        t = np.asarray(t, dtype=float)
        q, b, c0 = self.matrix[:2, :2], self.matrix[:2, 2], self.matrix[2, 2]
        lam, vec = np.linalg.eigh(q)
        if self.kind == "parabola":
            i = int(np.argmax(np.abs(lam)))
            w, u = vec[:, i], vec[:, 1 - i]
            bu = float(b @ u)
            tau = -(lam[i] * t**2 + 2.0 * t * float(b @ w) + c0) / (2.0 * bu)
            return t[:, None] * w + tau[:, None] * u
        assert self.centre is not None
        level = -(c0 + b @ self.centre)  # (x - c)^T Q (x - c) = level
        s = lam / level
        if self.kind == "ellipse":
            local = np.c_[np.cos(t) / np.sqrt(s[0]), np.sin(t) / np.sqrt(s[1])]
        else:
            ip = int(np.argmax(s))
            im = 1 - ip
            local = np.zeros((t.size, 2))
            local[:, ip] = branch * np.cosh(t) / np.sqrt(s[ip])
            local[:, im] = np.sinh(t) / np.sqrt(-s[im])
        return self.centre + local @ vec.T


def _conic_from_matrix(m: np.ndarray) -> Conic:
    m = 0.5 * (m + m.T)
    m = m / np.linalg.norm(m)
    q = m[:2, :2]
    dq = float(np.linalg.det(q))
    if abs(dq) <= 1e-12 * float(np.sum(q * q)):
        return Conic(matrix=m, kind="parabola", centre=None, affine_curvature=0.0)
    centre = -np.linalg.solve(q, m[:2, 2])
    level = -(m[2, 2] + m[:2, 2] @ centre)
    kappa = float(np.sign(dq) * np.cbrt(abs(dq) / level**2))
    if dq > 0 and np.sign(level) != np.sign(q[0, 0]):
        raise CurveError("osculating conic is an imaginary ellipse (no real points)")
    return Conic(
        matrix=m, kind="ellipse" if dq > 0 else "hyperbola", centre=centre, affine_curvature=kappa
    )


def _null_vector(rows: np.ndarray) -> np.ndarray:
    return np.linalg.svd(rows)[2][-1]


def _sym(v: np.ndarray) -> np.ndarray:
    q11, q12, q22, b1, b2, c0 = v
    return np.array([[q11, q12, b1], [q12, q22, b2], [b1, b2, c0]])


def osculating_conic(
    points: ArrayLike,
    index: int,
    *,
    kind: Literal["middle", "outer", "inner"] = "middle",
    closed: bool = False,
    rtol: float = 1e-6,
) -> Conic:
    """Outer, inner or middle osculating conic of the quadruple at `index` (Theorem 2).

    All three have the affine evolute point ``xi_i`` as centre (a point at
    infinity, i.e. a parabola, when ``k_i = 0``):

    * outer: through ``x_{i-1}, x_i, x_{i+1}, x_{i+2}``;
    * inner: tangent to the edges ``x_{i-1}x_i``, ``x_i x_{i+1}``, ``x_{i+1}x_{i+2}``;
    * middle: the geometric mean of the two (scaling about the centre by
      ``(1 - k_i/4)^(1/4)`` from the outer one; for a parabola the translation
      half way to the inner one).

    Each conic is found by linear algebra (a null vector of the point/tangent and
    centre conditions), independently of eq. (7), so the tests can check eq. (7)
    against the conics' own affine curvatures (they agree to 1e-8; the proof's
    inner radius "``r cos(lambda/2) = sqrt(1 - k_i/4)``" lacks the factor ``r``,
    which does not affect the scaling factor it derives).

    Parameters
    ----------
    points : (N, 2) array_like
        An affine arc length polyline.
    index : int
        Index into :func:`curvature` (open: the quadruple ``x_index .. x_{index+3}``;
        closed: the quadruple ``x_{index-1} .. x_{index+2}``).
    kind : {"middle", "outer", "inner"}, optional
        Which conic.
    closed : bool, optional
        Closed polygon.
    rtol : float, optional
        Tolerance of the affine arc length test.

    Returns
    -------
    Conic

    Examples
    --------
    >>> t = np.arange(8) * np.pi / 4
    >>> c = osculating_conic(np.c_[3 * np.cos(t), np.sin(t)], 2, kind="outer", closed=True)
    >>> c.kind, round(c.affine_curvature, 12) == round(3 ** (-2 / 3), 12)
    ('ellipse', True)
    """
    as_choice(kind, ("middle", "outer", "inner"), name="kind")
    p = as_points(points, closed=closed, min_points=4)
    area, b = _checked_area(p, closed, as_float(rtol, name="rtol", low=0.0, low_open=False))
    count = b.size
    index = as_int(index, name="index", minimum=0, maximum=count - 1)
    quad = p[np.arange(index - 1, index + 3) % p.shape[0]] if closed else p[index : index + 4]
    k = 2.0 - float(b[index]) / area
    # work in a local frame (centroid, unit scale) for conditioning
    origin = quad.mean(axis=0)
    scale = float(np.max(np.abs(quad - origin)))
    y = (quad - origin) / scale
    n = y[0] - 2.0 * y[1] + y[2]
    centre_h = np.r_[k * y[1] + n, k]  # homogeneous evolute point, eq. (5)
    centre_h = centre_h / np.linalg.norm(centre_h)
    hx, hy, hw = centre_h
    outer = None
    if kind in ("outer", "middle"):
        rows = [[x * x, 2 * x * z, z * z, 2 * x, 2 * z, 1.0] for x, z in y]
        rows += [[hx, hy, 0, hw, 0, 0], [0, hx, hy, 0, hw, 0]]
        outer = _sym(_null_vector(np.array(rows)))
    inner = None
    if kind in ("inner", "middle"):
        lines = [np.cross(np.r_[y[j], 1.0], np.r_[y[j + 1], 1.0]) for j in range(3)]
        rows = [
            [l1 * l1, 2 * l1 * l2, l2 * l2, 2 * l1 * l3, 2 * l2 * l3, l3 * l3]
            for l1, l2, l3 in lines
        ]
        # centre = pole of the line at infinity: D e3 parallel to centre_h
        # D e3 = (b1, b2, c0) in the dual unknowns; cross((b1, b2, c0), centre_h) = 0
        rows += [
            [0, 0, 0, 0, hw, -hy],
            [0, 0, 0, -hw, 0, hx],
            [0, 0, 0, hy, -hx, 0],
        ]
        inner = np.linalg.inv(_sym(_null_vector(np.array(rows))))
    if kind == "outer":
        m_local = outer
    elif kind == "inner":
        m_local = inner
    else:
        assert outer is not None and inner is not None  # both built for "middle"
        m_local = _middle(outer, inner)
    t = np.array(
        [[1.0 / scale, 0.0, -origin[0] / scale], [0.0, 1.0 / scale, -origin[1] / scale], [0, 0, 1]]
    )
    return _conic_from_matrix(t.T @ m_local @ t)


def _middle(outer: np.ndarray, inner: np.ndarray) -> np.ndarray:
    qo, qi = outer[:2, :2], inner[:2, :2]
    inner = inner * (np.sum(qo * qi) / np.sum(qi * qi))  # same quadratic part
    dq = float(np.linalg.det(qo))
    if abs(dq) <= 1e-12 * float(np.sum(qo * qo)):
        return 0.5 * (outer + inner)  # parabola: half the translation
    centre = -np.linalg.solve(qo, outer[:2, 2])
    lo = -(outer[2, 2] + outer[:2, 2] @ centre)
    li = -(inner[2, 2] + inner[:2, 2] @ centre)
    level = np.sign(lo) * np.sqrt(lo * li)
    m = np.empty((3, 3))
    m[:2, :2] = qo
    m[:2, 2] = m[2, :2] = -qo @ centre
    m[2, 2] = centre @ qo @ centre - level
    return m


def osculating_curvatures(points: ArrayLike, *, closed: bool = False, rtol: float = 1e-6):
    """Affine curvatures of the outer, inner and middle osculating conics (eq. 7).

    ``kappa^o = A^(-2/3) k (1 - k/4)^(1/3)``, ``kappa^i = A^(-2/3) k (1 - k/4)^(-1/3)``,
    ``kappa^m = A^(-2/3) k``, with ``A^(-2/3) = |A|^(-2/3)``. Eq. (7) is checked in
    the tests against the curvatures of the conics built by :func:`osculating_conic`.

    Parameters
    ----------
    points : (N, 2) array_like
        An affine arc length polyline.
    closed : bool, optional
        Closed polygon.
    rtol : float, optional
        Tolerance of the affine arc length test.

    Returns
    -------
    kappa_o, kappa_i, kappa_m : ndarray
        Each aligned with :func:`curvature`.

    Examples
    --------
    >>> t = np.arange(10) * np.pi / 5
    >>> ko, ki, km = osculating_curvatures(np.c_[np.cos(t), np.sin(t)], closed=True)
    >>> round(float(ko[0]), 12)
    1.0
    """
    p = as_points(points, closed=closed, min_points=4)
    area, b = _checked_area(p, closed, as_float(rtol, name="rtol", low=0.0, low_open=False))
    k = 2.0 - b / area
    if np.any(k >= 4.0):
        raise CurveError(
            f"curvatures k_i must be < 4 for real osculating conics, got max {k.max():g}"
        )
    s = abs(area) ** (-2.0 / 3.0)
    f = np.cbrt(1.0 - k / 4.0)
    return s * k * f, s * k / f, s * k
