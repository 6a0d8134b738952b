"""`lagrangian regressor MODEL --q ... --v ... --a ... [--parameters m1,m2] [--base]
[--floating-base]`: the torque regressor Y (tau = Y pi) at one state, and a minimal
identifiable parameter set."""

from __future__ import annotations

from typing import Annotated

import typer

from ..errors import InputError
from . import app
from .common import FLOATING_HELP, GRAVITY_HELP, LOCK_HELP, load_system, print_json
from .dynamics import _start, _vector, base_layout


@app.command()
def regressor(
    model: Annotated[str, typer.Argument(help="Model file (TOML or URDF) or built-in example name.")],
    q: Annotated[str | None, typer.Option("--q", help="Coordinates, comma-separated in the model's order (default: the initial values).")] = None,  # noqa: E501
    v: Annotated[str | None, typer.Option("--v", help="Velocities, comma-separated (default: the initial rates).")] = None,  # noqa: E501
    a: Annotated[str | None, typer.Option("--a", help="Accelerations, comma-separated (default: 0).")] = None,  # noqa: E501
    parameters: Annotated[str | None, typer.Option("--parameters", help="A model file: the parameters T and V are linear in, comma-separated (a URDF robot: 10 per body, Pinocchio's order).")] = None,  # noqa: E501
    base: Annotated[bool, typer.Option("--base", help="Also a minimal identifiable set (QR with column pivoting).")] = False,  # noqa: E501
    tolerance: Annotated[float, typer.Option("--tolerance", help="--base: |R_kk| / |R_00| below which a column is dependent.")] = 1e-8,  # noqa: E501
    lock: Annotated[list[str], typer.Option("--lock", help=LOCK_HELP)] = [],  # noqa: B006
    gravity: Annotated[str | None, typer.Option("--gravity", help=GRAVITY_HELP)] = None,
    floating_base: Annotated[bool, typer.Option("--floating-base", help=FLOATING_HELP)] = False,
    set_: Annotated[list[str], typer.Option("--set", help="Override a parameter: NAME=VALUE.")] = [],  # noqa: B006
    json_: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
) -> None:
    """Y(q, q_dot, q_ddot) with tau = Y pi (the inertial parameters pi), and with --base a
    minimal identifiable set."""
    import numpy as np  # here: --help loads no numpy

    from .. import resolve_state
    from ..output.regressor import regressor_document, regressor_text

    system = load_system(model, set_, lock, gravity, floating_base=floating_base)
    start = resolve_state(system.model)  # a ball joint's default: unturned (dynamics._start)
    names_q, names_v, base_q, base_v = base_layout(system)
    n = len(names_v)
    own = [c.name for c in system.model.coordinates]
    qs = _vector(q, names_q, "--q", _start(names_q, base_q, dict(zip(own, start.q, strict=True))))
    vs = _vector(v, names_v, "--v", _start(names_v, base_v,
                                           dict(zip(own, start.q_dot, strict=True))))
    accelerations = _vector(a, names_v, "--a", [0.0] * n)
    names = None if parameters is None else [p.strip() for p in parameters.split(",")]
    f = system.dynamics()
    try:
        Y = f.regressor(qs, vs, accelerations, parameters=names)
        values = f.inertial_parameters(names)
        found = f.base_parameters(names, tolerance=tolerance) if base else None
    except InputError as exc:  # the library's `parameters` is this command's --parameters
        if exc.field not in ("parameters", "tolerance"):
            raise
        raise InputError(exc.message, field=f"--{exc.field}") from None
    document = regressor_document(names_q, f.parameter_names(names), values, np.asarray(Y),
                                  found, velocities=names_v if names_v != names_q else None)
    if json_:
        print_json(document)
    else:
        typer.echo(regressor_text(document), nl=False)
