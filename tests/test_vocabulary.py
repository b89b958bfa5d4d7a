"""One vocabulary (docs/vocabulary.rst), checked over every public signature.

Every public function, method and class of the capability modules is inspected: no keyword
of the banned spellings, no two keywords of one signature that differ only in case, and
``workers`` only where it means Dask worker processes (batch).
"""

from __future__ import annotations

import importlib
import inspect

import pytest

MODULES = [
    "curvesmith.geometry",
    "curvesmith.subdivision",
    "curvesmith.cca",
    "curvesmith.derham",
    "curvesmith.affine",
    "curvesmith.curves",
    "curvesmith.glyphs",
    "curvesmith.elastica",
    "curvesmith.keyline",
    "curvesmith.geo",
    "curvesmith.batch",
    "curvesmith.io",
    "curvesmith.plot",
]

#: spelling -> the vocabulary's word
BANNED = {
    "center": "centre",
    "max_iter": "max_iterations",
    "maxiter": "max_iterations",
    "n_iter": "iterations",
    "num_samples": "samples / per_segment",
    "n_samples": "samples / per_segment",
    "nsamples": "samples / per_segment",
}


def _signatures():
    seen = set()
    for name in MODULES:
        module = importlib.import_module(name)
        for attr in getattr(module, "__all__", []):
            obj = getattr(module, attr)
            targets = [obj]
            if inspect.isclass(obj):
                targets = [obj] + [
                    m
                    for _, m in inspect.getmembers(obj, inspect.isfunction)
                    if not _.startswith("_")
                ]
            for target in targets:
                if not callable(target) or id(target) in seen:
                    continue
                seen.add(id(target))
                try:
                    sig = inspect.signature(target)
                except (TypeError, ValueError):  # builtins, numba dispatchers
                    continue
                yield f"{name}.{attr}" + ("" if target is obj else f".{target.__name__}"), sig


SIGNATURES = list(_signatures())


def test_the_check_sees_the_public_api():
    names = {n for n, _ in SIGNATURES}
    assert len(SIGNATURES) > 150
    assert {
        "curvesmith.cca.smooth",
        "curvesmith.elastica.fit",
        "curvesmith.batch.smooth_file",
    } <= names


@pytest.mark.parametrize("banned", sorted(BANNED))
def test_no_banned_spelling(banned):
    bad = [n for n, sig in SIGNATURES if banned in sig.parameters]
    assert not bad, f"{banned!r} is spelled {BANNED[banned]!r} in this library: {bad}"


def test_no_keywords_differing_only_in_case():
    bad = []
    for n, sig in SIGNATURES:
        lowered = [p.lower() for p in sig.parameters]
        if len(set(lowered)) != len(lowered):
            bad.append((n, list(sig.parameters)))
    assert not bad, bad


def test_workers_means_dask_processes():
    users = [n for n, sig in SIGNATURES if "workers" in sig.parameters]
    assert users and all(n.startswith("curvesmith.batch.") for n in users), users
    threads = [n for n, sig in SIGNATURES if "threads" in sig.parameters]
    assert "curvesmith.cca.smooth" in threads


# every enumerated option: a call with a bad value, the function and the keyword
_SQUARE = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.0, 0.5]]
_ELASTICA = (0.0, 0.0, 0.1, 0.0, 0.0, 0.0, 0.5)
_CHOICES = [
    ("curvesmith.geometry", "resample_equilateral", "rule", lambda f, v: f(_SQUARE, 0.3, rule=v)),
    ("curvesmith.affine", "approximate", "search", lambda f, v: f(_SQUARE, vertices=8, search=v)),
    ("curvesmith.affine", "osculating_conic", "kind", lambda f, v: f(_SQUARE, 2, kind=v)),
    ("curvesmith.elastica", "fit", "method", lambda f, v: f(_SQUARE, method=v)),
    ("curvesmith.elastica", "sample", "case", lambda f, v: f(_ELASTICA, 5, case=v)),
    ("curvesmith.elastica", "invariants", "case", lambda f, v: f(_ELASTICA, case=v)),
    ("curvesmith.elastica", "exact_curvature", "case", lambda f, v: f(_ELASTICA, 5, case=v)),
    (
        "curvesmith.derham",
        "interpolate",
        "method",
        lambda f, v: f((0, 0), (1, 0), (1, 1), (0, 1), length=2.0, gamma=2.0, method=v),
    ),
    ("curvesmith.io", "read_geojson", "others", lambda f, v: f("unused.geojson", others=v)),
    (
        "curvesmith.glyphs",
        "refit_glyph",
        "rounding",
        lambda f, v: f(None, "a", tolerance=1.0, rounding=v),
    ),
    ("curvesmith.methods", "get", "name", lambda f, v: f(v)),
]


@pytest.mark.parametrize(
    ("module", "function", "keyword", "call"), _CHOICES, ids=[f"{c[1]}.{c[2]}" for c in _CHOICES]
)
def test_enumerated_options_are_literal_and_checked_by_one_helper(module, function, keyword, call):
    """The annotation lists the values, and a bad value gets as_choice's message with the same."""
    import typing

    from curvesmith import CurveError, methods

    f = getattr(importlib.import_module(module), function)
    hint = typing.get_type_hints(f)[keyword]
    if function == "get":  # takes any string; the table's names are typed as MethodName
        hint = methods.MethodName
    values = _literal_values(hint)
    assert values, f"{function}({keyword}=...) is not annotated with a Literal: {hint!r}"
    with pytest.raises(CurveError) as info:
        call(f, "no-such-value")
    word = "method" if function == "get" else keyword
    assert str(info.value) == (
        f"{word} must be one of {', '.join(map(repr, values))}, got 'no-such-value'"
    )


def _literal_values(hint) -> tuple:
    import typing

    if typing.get_origin(hint) is typing.Literal:
        return typing.get_args(hint)
    out: tuple = ()
    for a in typing.get_args(hint):  # a union: None (optional) comes first in the messages
        out = (None, *out) if a is type(None) else out + _literal_values(a)
    return out


def test_the_method_literals_are_the_table():
    import typing

    from curvesmith import methods

    assert typing.get_args(methods.MethodName) == tuple(methods.METHODS)
    assert typing.get_args(methods.GisMethod) == methods.gis_names()


# ------------------------------------------------------------------ tests reach only the internal API

_NAMEDTUPLE = {"_replace", "_asdict", "_fields", "_make", "_field_defaults"}


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__") and name not in _NAMEDTUPLE


def _reaches(path) -> list[str]:
    """Every place a test file uses a private curvesmith name other than through internals."""
    import ast

    tree = ast.parse(path.read_text(), filename=str(path))
    bound: set[str] = set()  # names that refer to curvesmith modules or objects
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name.split(".")[0] == "curvesmith":
                    if any(_private(part) for part in a.name.split(".")):
                        found.append(f"line {node.lineno}: import {a.name}")
                    bound.add((a.asname or a.name).split(".")[0])
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("curvesmith"):
            parts = node.module.split(".")
            if any(_private(p) for p in parts):
                found.append(f"line {node.lineno}: from {node.module} import ...")
            for a in node.names:
                if _private(a.name):
                    found.append(f"line {node.lineno}: from {node.module} import {a.name}")
                bound.add(a.asname or a.name)
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and _private(node.attr):
            root = node.value
            while isinstance(root, ast.Attribute):
                root = root.value
            if isinstance(root, ast.Name) and root.id in bound:
                found.append(f"line {node.lineno}: {ast.unparse(node)}")
        if (
            isinstance(node, ast.Call)
            and ast.unparse(node.func).endswith("setattr")
            and len(node.args) >= 2
            and isinstance(node.args[1], ast.Constant)
            and isinstance(node.args[1].value, str)
            and _private(node.args[1].value)
        ):
            target = node.args[0]
            while isinstance(target, ast.Attribute):
                target = target.value
            if isinstance(target, ast.Name) and target.id in bound:
                found.append(f"line {node.lineno}: setattr(..., {node.args[1].value!r})")
    return found


def test_tests_use_only_the_internal_api(tmp_path):
    """No test reaches a private name (``_x``) except through ``curvesmith.internals``."""
    from pathlib import Path

    here = Path(__file__).parent
    files = sorted(here.glob("*.py")) + sorted((here / "qgis").glob("*.py"))
    bad = {f.name: hits for f in files if (hits := _reaches(f))}
    assert not bad, f"private names reached outside curvesmith.internals: {bad}"
    # and the check sees a reach when there is one
    probe = tmp_path / "probe_private.py"
    probe.write_text(
        "from curvesmith.geo._io import x\nfrom curvesmith import cca\ncca._api\n"
        "import curvesmith\nmonkeypatch.setattr(curvesmith, '_LAZY', ())\n"
    )
    assert len(_reaches(probe)) == 3


def test_every_public_parameter_is_annotated():
    """Array inputs ArrayLike, options Literal, ...: mypy checks the bodies, this the surface."""
    missing = []
    for name in [*MODULES, "curvesmith.methods"]:
        module = importlib.import_module(name)
        for attr in getattr(module, "__all__", []):
            obj = getattr(module, attr)
            fns = [(attr, obj)] if inspect.isfunction(obj) else []
            if inspect.isclass(obj):
                fns = [
                    (f"{attr}.{k}", v)
                    for k, v in vars(obj).items()
                    if inspect.isfunction(v) and not k.startswith("_")
                ]
            for label, f in fns:
                for p in inspect.signature(f).parameters.values():
                    if p.name in ("self", "cls") or p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD):
                        continue
                    if p.annotation is inspect.Parameter.empty:
                        missing.append(f"{name}.{label}({p.name})")
    assert not missing, missing
