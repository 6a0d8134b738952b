"""The `lagrangian` command line. Every bad input ends with a one-line error and exit status 2."""

from __future__ import annotations

import sys
from typing import Annotated

import typer

from ..errors import LagrangianError

app = typer.Typer(
    name="lagrangian",
    help="Derive, check, analyse and simulate equations of motion by Lagrange's method.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    # click's plain help: rich's help formatter alone doubles the start-up of `--help`
    rich_markup_mode=None,
    context_settings={"max_content_width": 100},
)



def _version(show: bool) -> None:
    if show:
        import lagrangian

        typer.echo(f"lagrangian {lagrangian.__version__}")
        raise typer.Exit()


@app.callback()
def _main(version: Annotated[bool, typer.Option(
        "--version", help="Print the version and exit.", callback=_version,
        is_eager=True)] = False) -> None:
    """Derive, check, analyse and simulate equations of motion by Lagrange's method."""


# Each command lives in its own module and registers itself on `app` when imported. The modules
# import sympy, scipy, matplotlib and pandas inside the commands, never at the top: `--help` and
# `examples` start in a fraction of a second (tests/cli/test_startup.py). A command named on the
# command line loads its own module only, and typer builds that command alone (building all of
# them from their signatures, and compiling their modules, was 0.1-0.2 s of every small command,
# issue 38); the group's help, --version and an unknown name load them all. The modules in the
# order the help lists them; tests/cli/test_startup.py checks the names against the commands.
COMMAND_MODULES = {
    "check": "check", "crosscheck": "check", "units": "check", "codegen": "codegen",
    "conserved": "conserved", "cycle": "cycle", "derive": "derive", "dynamics": "dynamics",
    "equilibria": "equilibria", "examples": "examples", "export": "export", "forces": "forces",
    "kinematics": "kinematics", "modes": "modes", "optimize": "optimize",
    "regressor": "regressor", "report": "report", "simulate": "simulate", "speeds": "speeds",
    "statics": "statics", "sweep": "sweep",
}
_ORDER = {module: i for i, module in enumerate(dict.fromkeys(COMMAND_MODULES.values()))}


def command_name(info) -> str:
    """A registered command's name on the command line, as typer names it."""
    from typer.main import get_command_name

    return info.name or get_command_name(info.callback.__name__)


def _app_for(words: list[str]) -> typer.Typer:
    """The app that runs ``words``: the command they name, alone, or every command."""
    import copy
    from importlib import import_module

    name = words[0] if words else None
    for module in [COMMAND_MODULES[name]] if name in COMMAND_MODULES else _ORDER:
        import_module(f"{__name__}.{module}")
    # the help's order whatever order the modules came in (a test process runs many commands)
    app.registered_commands.sort(key=lambda info: _ORDER.get(
        info.callback.__module__.rpartition(".")[2], len(_ORDER)))
    if name not in COMMAND_MODULES:
        return app
    alone = copy.copy(app)  # the same group (callback, settings), with the one command
    alone.registered_commands = [i for i in app.registered_commands if command_name(i) == name]
    return alone


from .common import TerminalText, flush_warnings, in_flags, reset_warnings  # noqa: E402


def main(argv: list[str] | None = None) -> None:
    """Console entry point. Every bad input ends with one line `error: ...` and exit status 2:
    the library's errors (bad model, bad values, singular system), the command line's own
    (unknown option, bad or missing value: typer's 6-line box before) and files that cannot be
    written. Everything printed passes through TerminalText: no control character from a
    model file reaches the terminal."""
    import warnings

    streams = sys.stdout, sys.stderr
    reset_warnings()
    sys.stdout, sys.stderr = TerminalText(sys.stdout), TerminalText(sys.stderr)
    shown = warnings.showwarning
    warnings.showwarning = _one_line_warnings(shown)
    try:
        _run(argv)
    finally:
        sys.stdout, sys.stderr = streams
        warnings.showwarning = shown


def _one_line_warnings(shown):
    """The library's own warnings (a backend that gave way to numpy, states without dynamics)
    as one line `warning: ...` each, not Python's file:line and source; others as before."""
    from ..errors import BackendWarning, DynamicsWarning, ModelWarning, one_line

    def show(message, category, filename, lineno, file=None, line=None):
        if issubclass(category, BackendWarning | DynamicsWarning | ModelWarning):
            typer.echo(f"warning: {one_line(str(message))}", err=True)
        else:
            shown(message, category, filename, lineno, file, line)

    return show


def _run(argv: list[str] | None) -> None:
    """The command, its errors as one line `error: ...` and its exit status."""
    try:
        try:
            words = sys.argv[1:] if argv is None else list(argv)
            code = _app_for(words)(args=words, prog_name="lagrangian", standalone_mode=False)
        except SystemExit as exc:  # a command's own status: warnings only with a success
            if exc.code in (0, None):
                flush_warnings()
            raise
    except LagrangianError as exc:
        _fail(str(in_flags(exc)))
    except typer.Abort:  # end of input or Ctrl-C at a prompt
        _fail("aborted", 130)
    except typer.TyperException as exc:  # click's usage errors
        if type(exc).__name__ == "NoArgsIsHelpError":  # bare `lagrangian`: the help, as before
            typer.echo(exc.format_message(), err=True)
            sys.exit(2)
        _fail(_usage_message(exc))
    except RecursionError:  # sympy recurses once per level of nesting (a chain of ~1000 bodies)
        _fail("the model is nested too deeply for the symbolic engine (Python's recursion limit): "
              "split the chain, or use fewer bodies in one tree")
    except MemoryError:
        _fail("the model needs more memory than this machine has")
    except OSError as exc:  # a file that passed the checks but could not be written after all
        where = f"{exc.filename}: " if exc.filename else ""
        _fail(f"{where}{exc.strerror or exc}")
    flush_warnings()  # after a success only: a refusal or a failure is one `error:` line
    sys.exit(code if isinstance(code, int) else 0)  # as click's standalone mode did


def _usage_message(exc: typer.TyperException) -> str:
    """click's message on one line, with the command to ask for help."""
    message = " ".join(exc.format_message().split()).rstrip(".")
    message = message[:1].lower() + message[1:]
    context = getattr(exc, "ctx", None)
    command = context.command_path if context is not None else "lagrangian"
    return f"{message} (see '{command} --help')"


def _fail(message: str, code: int = 2) -> None:
    typer.echo(f"error: {message}", err=True)
    sys.exit(code)
