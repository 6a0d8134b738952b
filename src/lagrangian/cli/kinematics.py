"""`lagrangian kinematics MODEL --q ... --frame NAME [--reference ...] [--v ...]
[--centroidal] [--json]`: a frame's placement and Jacobian and the centre of mass of a URDF robot
(its links and joints) or a model file (its particles and bodies) at one configuration; with
--v also J_dot q_dot, with --centroidal the centroidal momentum matrix (and with --v the
momentum h_g = A_g q_dot)."""

from __future__ import annotations

from typing import Annotated

import typer

from . import app
from .common import FLOATING_HELP, load_system, print_json
from .dynamics import LOCK_HELP, _start, _vector, base_layout


@app.command()
def kinematics(
    model: Annotated[str, typer.Argument(help="URDF robot or model file (file or built-in example name).")],
    frame: Annotated[str | None, typer.Option("--frame", help="A link or joint frame, or a model file's particle or body (default: the last).")] = None,  # noqa: E501
    q: Annotated[str | None, typer.Option("--q", help="Coordinates, comma-separated in the model's order (default: the initial values).")] = None,  # noqa: E501
    v: Annotated[str | None, typer.Option("--v", help="Velocities, comma-separated: also print J_dot q_dot, the frame's acceleration at q_ddot = 0.")] = None,  # noqa: E501
    centroidal: Annotated[bool, typer.Option("--centroidal", help="Also print the centroidal momentum matrix A_g (and with --v the momentum A_g q_dot).")] = False,  # noqa: E501
    reference: Annotated[str, typer.Option("--reference", help="The Jacobian's frame: local_world_aligned (the origin's velocity in world axes), local or world, as Pinocchio's.")] = "local_world_aligned",  # noqa: E501
    lock: Annotated[list[str], typer.Option("--lock", help=LOCK_HELP)] = [],  # noqa: B006
    floating_base: Annotated[bool, typer.Option("--floating-base", help=FLOATING_HELP)] = False,
    set_: Annotated[list[str], typer.Option("--set", help="Override a parameter: NAME=VALUE.")] = [],  # noqa: B006
    json_: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
) -> None:
    """A frame's placement (4 x 4) and Jacobian (6 x n), the centre of mass and its Jacobian."""
    from .. import resolve_state, state_kinematics
    from ..output.kinematics import kinematics_document, kinematics_text

    system = load_system(model, set_, lock, floating_base=floating_base)
    names, velocities, base_q, _ = base_layout(system)
    start = resolve_state(system.model)  # a ball joint's default: unturned (dynamics._start)
    qs = _vector(q, names, "--q", _start(names, base_q, dict(zip(start.coordinates, start.q,
                                                                  strict=True))))
    robot = system.dynamics().kinematics
    name = frame if frame is not None else robot.frames[-1]
    vs = None if v is None else _vector(v, velocities, "--v", [])
    values = state_kinematics(robot, qs, name, reference, vs, centroidal)
    velocities = velocities if velocities != names else None  # a floating base, a ball
    if json_:
        print_json(kinematics_document(names, name, reference, values, velocities))
    else:
        typer.echo(kinematics_text(names, name, reference, values, velocities), nl=False)
