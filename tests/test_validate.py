import numpy as np
import pytest

from curvesmith import CurveError
from curvesmith.internals import as_float, as_int, as_points


def test_as_points_converts_and_copies():
    src = [[0, 0], [1, 2]]
    p = as_points(src)
    assert p.dtype == np.float64 and p.shape == (2, 2) and p.flags.c_contiguous
    arr = np.array([[0.0, 0.0], [1.0, 2.0]])
    q = as_points(arr)
    q[0, 0] = 9
    assert arr[0, 0] == 0.0


def test_closed_ring_drops_repeated_vertex_once():
    ring = [[0, 0], [1, 0], [1, 1], [0, 0]]
    assert as_points(ring, closed=True).shape == (3, 2)
    assert as_points(ring, closed=False).shape == (4, 2)
    # Only once: a doubly repeated closing vertex leaves a zero-length closing edge.
    twice = [[0, 0], [1, 0], [1, 1], [0, 0], [0, 0]]
    assert as_points(twice, closed=True).shape == (4, 2)
    with pytest.raises(CurveError, match="zero-length"):
        as_points(twice, closed=True, distinct=True)


@pytest.mark.parametrize(
    ("value", "kwargs", "match"),
    [
        ([[0, np.nan], [1, 1]], {}, r"points must be finite, got \[0.0, nan\] at row 0"),
        ([[0, 0], [1, np.inf], [2, -np.inf]], {}, r"at row 1 \(2 rows with NaN or inf\)"),
        ([1.0, 2.0, 3.0], {}, r"must have shape \(N, 2\), got \(3,\)"),
        (np.zeros((4, 3)), {}, r"must have shape \(N, 2\), got \(4, 3\)"),
        (np.zeros((4, 4)), {"dim": (2, 3)}, r"\(N, 2\) or \(N, 3\), got \(4, 4\)"),
        ([[0, 0], [1, 1]], {"min_points": 3}, "at least 3 points, got 2"),
        ([[0, 0], [1, 1], [0, 0]], {"min_points": 3, "closed": True}, "at least 3 distinct ring"),
        ([["a", "b"]], {}, "numeric"),
        ([[0, 0], [1, 1], [1, 1]], {"distinct": True}, r"zero-length edge: vertices 1 and 2"),
    ],
)
def test_as_points_rejects(value, kwargs, match):
    with pytest.raises(CurveError, match=match):
        as_points(value, **kwargs)


def test_custom_name_in_message():
    with pytest.raises(CurveError, match="^samples must"):
        as_points([1, 2], name="samples")


def test_as_int_and_as_float():
    assert as_int(3.0, name="n") == 3
    with pytest.raises(CurveError, match="n must be an integer, got 2.5"):
        as_int(2.5, name="n")
    with pytest.raises(CurveError, match="n must be an integer, got True"):
        as_int(True, name="n")
    with pytest.raises(CurveError, match=r"in \[1, 3\], got 4"):
        as_int(4, name="k", minimum=1, maximum=3)
    assert as_float(np.float32(0.25), name="alpha", low=0, high=1 / 3) == 0.25
    with pytest.raises(CurveError, match="alpha must be a real number, got '0.25'"):
        as_float("0.25", name="alpha")
    with pytest.raises(CurveError, match=r"alpha must be in \(0, 0.333333\), got 0.5"):
        as_float(0.5, name="alpha", low=0, high=1 / 3)
    with pytest.raises(CurveError, match="tol must be finite, got nan"):
        as_float(float("nan"), name="tol", low=0)
    with pytest.raises(CurveError, match="tol must be a real number"):
        as_float("abc", name="tol")
    assert as_float(0, name="x", low=0, low_open=False) == 0.0


def test_huge_finite_values_pass_the_finiteness_check():
    # The fast path sums the coordinates; an overflowing sum must fall back to the exact check.
    p = as_points([[1e308, 1e308], [1e308, -1.0]])
    assert p[0, 0] == 1e308
    with pytest.raises(CurveError, match="row 1"):
        as_points([[1e308, 1e308], [np.inf, -1.0]])


def test_complex_input_is_refused_not_truncated():
    with pytest.raises(CurveError, match="points must be real coordinates, got a complex array"):
        as_points(np.array([[0, 0], [1, 1]]) + 1j)


def test_as_bool_and_growth_limit():
    from curvesmith.internals import as_bool, check_growth

    assert as_bool(np.True_, name="closed") is True
    for bad in (None, "no", 1, 0.0):
        with pytest.raises(CurveError, match="closed must be True or False"):
            as_bool(bad, name="closed")
    check_growth(10, 3, lambda n: 3 * n, limit=270)  # 30, 90, 270: at the limit is fine
    with pytest.raises(CurveError, match=r"at most 269 output vertices, got 3 \(step 3 alone"):
        check_growth(10, 3, lambda n: 3 * n, limit=269)


def test_as_choice_lists_the_choices_and_keeps_bools_apart():
    from curvesmith.internals import as_choice

    assert as_choice("secant", ("accelerated", "secant"), name="method") == "secant"
    assert as_choice(2010, [2010, 2016], name="year") == 2010
    with pytest.raises(CurveError, match=r"^year must be one of 2010, 2016, got 1999$"):
        as_choice(1999, [2010, 2016], name="year")
    # True == 1 in Python; an option that takes "auto", True or False refuses 1
    assert as_choice(True, ("auto", True, False), name="continuation") is True
    with pytest.raises(CurveError, match="continuation must be one of 'auto', True, False, got 1"):
        as_choice(1, ("auto", True, False), name="continuation")
    with pytest.raises(CurveError, match=r"got array\(\[1, 2\]\)"):
        as_choice(np.array([1, 2]), (1, 2), name="n")
    with pytest.raises(CurveError, match=r"got \['cca'\]"):
        as_choice(["cca"], ("cca", "chaikin"), name="method")
