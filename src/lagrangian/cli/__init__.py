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
from . import statics as _statics  # noqa: E402,F401
from .common import in_flags  # noqa: E402


def main(argv: list[str] | None = None) -> None:
    """Console entry point: usage errors exit 2 (click's standalone mode); library errors
    (bad model, bad values, singular system) print one line and exit 2 as well."""
    try:
        app(args=argv, prog_name="lagrangian")
    except (LagrangianError, FileExistsError) as exc:
        typer.echo(f"error: {in_flags(exc) if isinstance(exc, LagrangianError) else exc}",
                   err=True)
        sys.exit(2)
