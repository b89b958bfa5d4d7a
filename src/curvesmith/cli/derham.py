"""``curvesmith derham``: a de Rham curve with given end points, tangents and length."""

from __future__ import annotations

from typing import Literal

import click

from .. import derham
from ..errors import CurveError
from ..io import Curve
from ._common import FORMAT_OPTION, GAMMA, POSITIVE, output_option, parse_floats, write_curves

__all__ = ["derham_command"]


@click.command("derham")
@click.option("--start", required=True, metavar="X,Y", help="Start point A.")
@click.option("--start-tangent", required=True, metavar="DX,DY", help="Tangent direction at A.")
@click.option("--end", required=True, metavar="X,Y", help="End point C.")
@click.option("--end-tangent", required=True, metavar="DX,DY", help="Tangent direction at C.")
@click.option(
    "--length",
    "target",
    required=True,
    type=POSITIVE,
    help="Prescribed length, strictly between the chord AC and the polygon length AB + BC.",
)
@click.option(
    "--gamma", type=GAMMA, default=2.0, show_default=True, help="De Rham ratio 1:gamma:1, > 1."
)
@click.option(
    "--method",
    type=click.Choice(list(derham.METHODS)),
    default="accelerated",
    show_default=True,
    help="accelerated: certified Halley iteration; regula_falsi / secant: Merrien's Lemmas 4 / 5.",
)
@click.option(
    "--tol", type=POSITIVE, default=1e-9, show_default=True, help="Accuracy on the length, > 0."
)
@click.option(
    "--level",
    type=click.IntRange(0, 16),  # derham.prescribed_length's bounds (2^17 + 1 points)
    default=6,
    show_default=True,
    help="Subdivision level of the written curve (2^(level+1) + 1 points).",
)
@output_option("Output file, - for stdout.")
@FORMAT_OPTION
def derham_command(
    start: str,
    start_tangent: str,
    end: str,
    end_tangent: str,
    target: float,
    gamma: float,
    method: Literal["accelerated", "regula_falsi", "secant"],
    tol: float,
    level: int,
    dest: str,
    fmt: str | None,
) -> None:
    """Write the convex G1 de Rham curve from START to END with the given tangents and length.

    The tangent lines must meet in a point B ahead of both ends (Merrien,
    section 3). Prints the parameter x, the achieved length and its certified
    bounds (to stderr when the curve goes to stdout); exits with status 1 if
    the method does not reach the tolerance.
    """
    a = parse_floats(start, name="--start", count=2)
    ua = parse_floats(start_tangent, name="--start-tangent", count=2)
    c = parse_floats(end, name="--end", count=2)
    uc = parse_floats(end_tangent, name="--end-tangent", count=2)
    res = derham.interpolate(
        a, ua, c, uc, length=target, gamma=gamma, tol=tol, method=method, level=level
    )
    if not res.success:
        raise CurveError(f"derham {method} did not converge: {res.message}")
    props = {
        "derham_x": res.x,
        "length": res.length,
        "lower": res.lower,
        "upper": res.upper,
        "gamma": gamma,
        "method": method,
    }
    write_curves([Curve(res.points, closed=False, properties=props)], dest, fmt)
    to_err = dest == "-"
    click.echo(f"x = {res.x:.15g}", err=to_err)
    click.echo(f"length = {res.length:.15g}", err=to_err)
    click.echo(
        f"bounds = [{res.lower:.15g}, {res.upper:.15g}] "
        f"({'certified' if res.certified else 'not certified'} within tol = {tol:g})",
        err=to_err,
    )
    click.echo(f"iterations = {res.iterations}, length evaluations = {res.evaluations}", err=to_err)
