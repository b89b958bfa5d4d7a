"""``curvesmith demo``: run every capability on bundled data, write figures and a summary.

Each capability contributes one section module in this package with a
``TITLE`` string and a function ``run(ctx: DemoContext) -> None`` that draws its
figures with ``ctx.figure`` and records its measured numbers with
``ctx.number``. :func:`run_demo` runs the sections listed in :data:`SECTIONS`
in order and writes ``summary.md`` and ``summary.json`` beside the PNGs.
"""

from __future__ import annotations

import importlib
import json
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = ["SECTIONS", "DemoContext", "run_demo", "show_section"]

#: Section modules of this package, in the order they appear in the summary.
SECTIONS: list[str] = [
    "subdivision",
    "cca",
    "derham",
    "affine",
    "curves",
    "elastica",
    "keyline",
    "geo",
    "network",
]


@dataclass
class DemoContext:
    """What a demo section writes to: figures, numbers and prose, collected per section.

    Attributes
    ----------
    outdir : Path
        Output directory (exists).
    section : str
        Name of the running section.
    close : bool
        Close each figure once saved (default); the documentation gallery keeps them open
        so that sphinx-gallery can show them.
    """

    outdir: Path
    section: str = ""
    close: bool = True
    figures: list[dict[str, str]] = field(default_factory=list)
    numbers: dict[str, Any] = field(default_factory=dict)
    texts: list[str] = field(default_factory=list)

    def figure(self, fig, name: str, caption: str) -> Path:
        """Save a matplotlib figure as ``OUTDIR/<name>.png`` (150 dpi), close it, record it.

        Parameters
        ----------
        fig : matplotlib.figure.Figure
            The figure; it is closed after saving.
        name : str
            File stem, prefixed with the section name by convention, e.g. ``"cca_profile"``.
        caption : str
            One-sentence caption for ``summary.md``.
        """
        import matplotlib.pyplot as plt

        path = self.outdir / f"{name}.png"
        fig.savefig(path, dpi=150, bbox_inches="tight")
        if self.close:
            plt.close(fig)
        self.figures.append({"file": path.name, "caption": caption})
        return path

    def number(self, key: str, value: Any, description: str = "") -> None:
        """Record a measured number (float, int, str, or a list/dict of them)."""
        self.numbers[key] = {"value": _jsonable(value), "description": description}

    def text(self, markdown: str) -> None:
        """Add a paragraph of Markdown to this section of the summary."""
        self.texts.append(markdown.strip())


def _jsonable(value):
    import numpy as np

    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_jsonable(v) for v in value]
    return value


def _fmt(value) -> str:
    if isinstance(value, float):
        return f"{value:.10g}"
    if isinstance(value, list) and len(value) > 8:
        return f"[{len(value)} values]"
    return str(value)


def run_demo(outdir, *, sections: list[str] | None = None, progress=None) -> dict[str, Any]:
    """Run the demo sections and write PNG figures, ``summary.md`` and ``summary.json``.

    Parameters
    ----------
    outdir : str or Path
        Output directory, created if needed.
    sections : list of str, optional
        Subset of :data:`SECTIONS` to run (default: all).
    progress : callable, optional
        Called with a one-line message as each section starts.

    Returns
    -------
    dict
        The summary written to ``summary.json``.
    """
    from ..errors import CurveError, MissingDependencyError

    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    names = list(SECTIONS if sections is None else sections)
    unknown = [n for n in names if n not in SECTIONS]
    if unknown:
        raise CurveError(f"sections must be among {SECTIONS}, got {unknown}")
    import matplotlib

    matplotlib.use("Agg")
    summary: dict[str, Any] = {"sections": []}
    md = ["# curvesmith demo", ""]
    for name in names:
        module = importlib.import_module(f"{__name__}.{name}")
        if progress is not None:
            progress(f"{name}: {module.TITLE}")
        ctx = DemoContext(outdir=outdir, section=name)
        t0 = time.perf_counter()
        try:
            module.run(ctx)
        except MissingDependencyError as exc:
            # A section of an optional extra: say what to install, run the others.
            ctx.text(f"**Not run:** {exc}")
            if progress is not None:
                progress(f"{name}: not run: {exc}")
        seconds = time.perf_counter() - t0
        summary["sections"].append(
            {
                "name": name,
                "title": module.TITLE,
                "seconds": round(seconds, 3),
                "figures": ctx.figures,
                "numbers": ctx.numbers,
                "text": ctx.texts,
            }
        )
        md += [f"## {module.TITLE}", ""]
        md += [t + "\n" for t in ctx.texts]
        if ctx.numbers:
            md += ["| quantity | value | meaning |", "|---|---|---|"]
            md += [
                f"| `{k}` | {_fmt(v['value'])} | {v['description']} |"
                for k, v in ctx.numbers.items()
            ]
            md.append("")
        for f in ctx.figures:
            md += [f"![{f['caption']}]({f['file']})", "", f"*{f['caption']}*", ""]
    (outdir / "summary.md").write_text("\n".join(md), encoding="utf-8")
    (outdir / "summary.json").write_text(json.dumps(summary, indent=2), encoding="utf-8")
    return summary


def show_section(name: str, outdir=None) -> DemoContext:
    """Run one demo section with its figures left open, and print its numbers.

    This is what the documentation gallery runs: each example script shows one section, and
    sphinx-gallery collects the open matplotlib figures.

    Parameters
    ----------
    name : str
        One of :data:`SECTIONS`.
    outdir : str or Path, optional
        Where the PNGs go (default: a temporary directory).

    Returns
    -------
    DemoContext
        The section's figures, numbers and texts.
    """
    import tempfile

    from .._validate import as_choice

    as_choice(name, SECTIONS, name="name")
    module = importlib.import_module(f"{__name__}.{name}")
    folder = Path(tempfile.mkdtemp(prefix=f"curvesmith-{name}-")) if outdir is None else outdir
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    ctx = DemoContext(outdir=folder, section=name, close=False)
    module.run(ctx)
    for text in ctx.texts:
        print(text)
    for key, entry in ctx.numbers.items():
        print(f"{key} = {_fmt(entry['value'])}  ({entry['description']})")
    return ctx
