"""`lagrangian codegen MODEL --lang c --out DIR`: standalone C99 (.c and .h) of the dynamics."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ..errors import InputError, ModelError
from ..output.files import write_c
from . import app
from .common import FLOATING_HELP, GRAVITY_HELP, PAYLOAD_HELP, load_system

LANGUAGES = ("c",)


@app.command()
def codegen(
    model: Annotated[str, typer.Argument(help="Model file (TOML or URDF) or built-in example name.")],
    out: Annotated[str, typer.Option("--out", help="Directory for <name>.c and <name>.h.")],
    lang: Annotated[str, typer.Option("--lang", help="Language: c (C99, libm only).")] = "c",
    name: Annotated[str | None, typer.Option("--name", help="Prefix of the functions and files (default: from the model's name).")] = None,  # noqa: E501
    lock: Annotated[list[str], typer.Option("--lock", help="URDF: freeze a joint, NAME=VALUE.")] = [],  # noqa: B006
    gravity: Annotated[str | None, typer.Option("--gravity", help=GRAVITY_HELP)] = None,
    payload: Annotated[list[str], typer.Option("--payload", help=PAYLOAD_HELP)] = [],  # noqa: B006
    floating_base: Annotated[bool, typer.Option("--floating-base", help=FLOATING_HELP)] = False,
    set_: Annotated[list[str], typer.Option("--set", help="Override a parameter: NAME=VALUE.")] = [],  # noqa: B006
) -> None:
    """Write M(q), bias C q_dot + g, gravity, inverse and forward dynamics and the energies as
    standalone C (no Python, no allocation, libm only) for embedding in a controller; a URDF
    or MJCF robot's frames too (placements, Jacobians, J_dot v, centre of mass), its ball and
    free joints with q of <NAME>_NQ numbers and v of <NAME>_N; a model file's [control] laws as
    <name>_control and <name>_control_forces."""
    if lang.lower() not in LANGUAGES:
        raise InputError(f"unknown language {lang!r}: use c", field="--lang")
    directory = Path(out)
    if directory.exists() and not directory.is_dir():
        raise InputError("exists and is not a directory", field=f"--out {out}")
    system = load_system(model, set_, lock, gravity, payload, floating_base)
    if any(v is None for v in system.parameters.values()):
        missing = [k for k, v in system.parameters.items() if v is None]
        raise InputError(f"parameters without a value: {', '.join(missing)} (give them with --set)",
                         field="--set")
    try:
        code = system.to_c(name)
    except ModelError as exc:
        raise InputError(exc.message, field={"prefix": "--name", "lang": "--lang"}.get(
            exc.field or "", exc.field)) from None
    for path in write_c(code, directory):
        typer.echo(f"wrote {path}")
