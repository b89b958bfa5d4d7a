"""Exceptions raised by curvesmith.

Every error curvesmith raises on bad input is a :class:`CurveError`, which is a
:class:`ValueError`, so ``except ValueError`` keeps working for callers who do
not know curvesmith. Messages name the argument and the offending value.
"""

from __future__ import annotations

__all__ = ["CurveError", "CurveFormatError", "MissingDependencyError", "OutputSizeError"]


class CurveError(ValueError):
    """Invalid curve data or parameter.

    Examples
    --------
    >>> import curvesmith as cs
    >>> cs.signed_area([[0.0, 0.0], [1.0, 0.0]])
    Traceback (most recent call last):
    ...
    curvesmith.errors.CurveError: points must have at least 3 distinct ring points, got 2
    """


class CurveFormatError(CurveError):
    """A file or stream could not be read or written in the requested format."""


class OutputSizeError(CurveError):
    """The requested refinement would make more vertices than one call may hold.

    Raised before any work is done (see ``curvesmith._validate.check_growth`` and
    ``check_layer_growth``); the message names the most iterations that fit. Code that
    retries a failing layer feature by feature re-raises it instead: smaller calls would
    hold the same output in all.
    """


class MissingDependencyError(CurveError, ImportError):
    """An optional dependency needed for the requested feature is not installed."""


def require(module: str, extra: str, feature: str):
    """Import an optional dependency or raise a helpful error.

    Parameters
    ----------
    module : str
        Importable module name, e.g. ``"shapely"``.
    extra : str
        Name of the curvesmith extra that installs it, e.g. ``"geo"``.
    feature : str
        What the caller wanted to do, used in the message.

    Returns
    -------
    module
        The imported module.
    """
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise MissingDependencyError(
            f"{feature} needs the optional dependency {module!r}; "
            f"install it with: pip install 'curvesmith[{extra}]'"
        ) from exc
