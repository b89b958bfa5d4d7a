"""The ``curvesmith`` command line.

Every command reads CSV, GeoJSON or SVG (chosen by the file suffix, ``-`` for
standard input/output with ``--format``) and writes the same formats. Exit
status: 0 success, 1 a data or numerical error (one line on stderr, no
traceback), 2 a usage error.
"""

from __future__ import annotations

import signal
import sys

import click

from .. import __version__
from ..errors import CurveError
from ._stop import (
    claim_last_line,
    end_open_line,
    exit_cleanly_on_sigterm,
    install_watchdog,
    wait_if_stopping,
)

__all__ = ["main"]


class _Group(click.Group):
    """A click group that turns every error into one line: exit 1 for data, 2 for usage.

    A usage error (a missing argument, an unknown option, a bad option value) is click's
    message plus where to find help, on one line, exit status 2; a curvesmith or OS error
    is its message, exit status 1.
    """

    def main(self, args=None, *rest, **kwargs):
        if args is None:  # the program itself (not click's test runner, not a caller's args)
            install_watchdog()
        return super().main(args, *rest, **kwargs)

    def invoke(self, ctx):
        exit_cleanly_on_sigterm()
        try:
            return super().invoke(ctx)
        except click.UsageError as exc:
            where = exc.ctx.command_path if exc.ctx is not None else ctx.command_path
            message = exc.format_message().replace("\n", " ")
            end_open_line()
            click.echo(f"Error: {message} (see '{where} --help')", err=True)
            sys.exit(exc.exit_code)
        except CurveError as exc:
            wait_if_stopping()  # caused by the watchdog removing the output: it exits
            end_open_line()
            click.echo(f"Error: {exc}", err=True)
            sys.exit(1)
        except OSError as exc:
            wait_if_stopping()
            where = f": {exc.filename}" if getattr(exc, "filename", None) else ""
            end_open_line()
            click.echo(f"Error: {exc.strerror or exc}{where}", err=True)
            sys.exit(1)
        except KeyboardInterrupt:  # "Aborted!", as click says it, unless the watchdog spoke
            if not claim_last_line():
                wait_if_stopping()
            end_open_line()
            click.echo("Aborted!", err=True)
            sys.exit(128 + signal.SIGINT)  # 130, as a shell reports a job stopped by Ctrl-C


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="curvesmith")
def main() -> None:
    """curvesmith: smooth, subdivide, fair and design discrete curves with exact guarantees.

    Input and output files are CSV (x,y[,z] with a header; an `id` column
    for several curves), GeoJSON or SVG, chosen by suffix. Use - for
    stdin/stdout together with --format.
    """


def _register() -> None:
    from .affine import affine_command
    from .basic import demo_command, measure_command, smooth_command
    from .contours import contours_command
    from .derham import derham_command
    from .fair import fair_command
    from .geo import batch_group
    from .glyphs import glyphs_command
    from .keyline import keyline_command

    commands = (
        measure_command,
        smooth_command,
        derham_command,
        affine_command,
        fair_command,
        keyline_command,
        glyphs_command,
        batch_group,
        contours_command,
        demo_command,
    )
    for command in commands:
        main.add_command(command)


_register()
