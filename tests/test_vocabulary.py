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
