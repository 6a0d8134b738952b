"""`lagrangian optimize MODEL --to NAME=VALUE ... --t-final T --nodes N --bound u=-5:5 [--json]`:
an optimal trajectory by direct collocation (CasADi, IPOPT; the extra [casadi])."""

from __future__ import annotations

from typing import Annotated

import typer

from . import app
from .common import (
    FLOATING_HELP,
    GRAVITY_HELP,
    SET_HELP,
    load_system,
    print_json,
    state_assignments,
)

TO_HELP = ("The goal at t_final: STATE=VALUE (theta=pi, theta_dot=0; a ball joint's "
           "shoulder_qw..shoulder_qz and shoulder_wx..shoulder_wz); the other states are free.")
FROM_HELP = ("The start: STATE=VALUE, named as simulate --initial (default: the model's initial "
             "values; a ball joint unturned and at rest).")
BOUND_HELP = ("NAME=LOWER:UPPER on an input or a state (u=-5:5, x=-1:1; leave a side empty "
              "for no bound: x=:1). A bound on a name that is not a state makes it an input.")
INPUT_HELP = ("An input to optimise: a load, a parameter or a coordinate (a generalized force "
              "on it; a ball joint's moment shoulder_wx ..), as in linearize; repeat, or "
              "separate by commas. Default: the --bound names that are not states.")
METHOD_HELP = "trapezoidal or hermite-simpson."


@app.command()
def optimize(
    model: Annotated[str, typer.Argument(help="Model file (TOML) or built-in example name.")],
    to: Annotated[list[str], typer.Option("--to", help=TO_HELP)] = [],  # noqa: B006
    from_: Annotated[list[str], typer.Option("--from", help=FROM_HELP)] = [],  # noqa: B006
    t_final: Annotated[float, typer.Option("--t-final", help="The horizon in s.")] = 3.0,
    nodes: Annotated[int, typer.Option("--nodes", help="Collocation nodes (3 to 5000).")] = 100,
    bound: Annotated[list[str], typer.Option("--bound", help=BOUND_HELP)] = [],  # noqa: B006
    input_: Annotated[list[str], typer.Option("--input", help=INPUT_HELP)] = [],  # noqa: B006
    method: Annotated[str, typer.Option("--method", help=METHOD_HELP)] = "trapezoidal",
    set_: Annotated[list[str], typer.Option("--set", help=SET_HELP)] = [],  # noqa: B006
    gravity: Annotated[str | None, typer.Option("--gravity", help=GRAVITY_HELP)] = None,
    floating_base: Annotated[bool, typer.Option("--floating-base", help=FLOATING_HELP)] = False,
    json_: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
) -> None:
    """Minimise the effort (integral of u^2 dt) from the start to the goal by collocation."""
    import lagrangian

    from ..output.trajectory import trajectory_document, trajectory_text
    from .common import assignments, comma_separated

    system = load_system(model, set_, (), gravity, (), floating_base)
    goal = state_assignments(system, to, "--to")
    start = state_assignments(system, from_, "--from")
    states = {name for c in system.model.coordinates for name in (c.name, c.velocity.name)}
    tree = system.model.kinematic_tree
    if floating_base or getattr(tree, "quaternion_joints", ()):
        # the base's numbers (base_x .. base_wz), a ball's (shoulder_qw .. shoulder_wz) are
        # states too, judged by optimize
        dynamics = system.dynamics()
        states |= {*dynamics.coordinates, *dynamics.velocity_names}
    bounds = {}
    for name, text in assignments(comma_separated(bound), "--bound"):
        lower, sep, upper = text.partition(":")
        if not sep:
            raise lagrangian.InputError(f"expected LOWER:UPPER, got {text!r}",
                                        field=f"--bound {name}")
        bounds[name] = tuple(None if not side.strip() else
                             lagrangian.parse_quantity(side.strip(), None, f"--bound {name}")
                             for side in (lower, upper))
    named = [name.strip() for text in input_ for name in text.split(",") if name.strip()]
    inputs = named or [name for name in bounds if name not in states]
    trajectory = lagrangian.optimize(system, inputs, t_final, nodes, start=start or None,
                                     goal=goal, bounds=bounds, method=method)
    if json_:
        print_json(trajectory_document(trajectory))
    else:
        typer.echo(trajectory_text(trajectory), nl=False)
