"""The `lagrangian` command line. Every bad input ends with a one-line error and exit status 2."""

from __future__ import annotations

import sys

import typer

from ..errors import LagrangianError

app = typer.Typer(
    name="lagrangian",
    help="Derive, check, analyse and simulate equations of motion by Lagrange's method.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)

# Each command lives in its own module and registers itself on `app` when imported.
from . import check as _check  # noqa: E402,F401
from . import derive as _derive  # noqa: E402,F401
from . import equilibria as _equilibria  # noqa: E402,F401
from . import examples as _examples  # noqa: E402,F401
from . import forces as _forces  # noqa: E402,F401
from . import modes as _modes  # noqa: E402,F401
from . import simulate as _simulate  # noqa: E402,F401


def main(argv: list[str] | None = None) -> int:
    """Console entry point: run the app, turning library errors into exit status 2."""
    try:
        app(args=argv, prog_name="lagrangian", standalone_mode=False)
    except LagrangianError as exc:
        typer.echo(f"error: {exc}", err=True)
        return _exit(2)
    except FileExistsError as exc:
        typer.echo(f"error: {exc}", err=True)
        return _exit(2)
    except typer.Exit as exc:
        return _exit(exc.exit_code)
    except (typer.Abort, KeyboardInterrupt):
        typer.echo("aborted", err=True)
        return _exit(130)
    except Exception as exc:  # click usage errors carry their own exit code
        import click

        if isinstance(exc, click.ClickException):
            exc.show()
            return _exit(exc.exit_code)
        raise
    return _exit(0)


def _exit(code: int | None) -> int:
    sys.exit(int(code or 0))
