"""`lagrangian dynamics MODEL --q 0.1,0.2 --v 0,1 [--a ... | --tau ...]`: M, bias, gravity,
inverse or forward dynamics and the energies at one state."""

from __future__ import annotations

from typing import Annotated

import typer

from ..errors import InputError
from . import app
from .common import (
    FLOATING_HELP,
    GRAVITY_HELP,
    PAYLOAD_HELP,
    load_system,
    print_json,
    warn,
    warn_bare_angles,
)

LOCK_HELP = "URDF: freeze a joint at a value, NAME=VALUE (30deg, 0.02m); repeatable."
WRENCH_HELP = ("URDF: a wrench on a frame, FRAME=fx,fy,fz,mx,my,mz (N, N m; world axes, at the "
               "frame's origin), acting in --a and --tau; repeatable.")
WRENCH = ("fx", "fy", "fz", "mx", "my", "mz")
ARMATURE_HELP = "URDF: a joint's rotor inertia, JOINT=VALUE (kg m^2, or kg); repeatable."


def _wrenches(texts: list[str]) -> dict[str, list[float]]:
    """--wrench FRAME=fx,fy,fz,mx,my,mz as {frame: six numbers}."""
    from .common import assignments

    return {name: _vector(value, WRENCH, f"--wrench {name}", [])
            for name, value in assignments(texts, "--wrench")}


def _vector(text: str | None, names, flag: str, default: list[float] | None) -> list[float] | None:
    """A comma-separated vector in the model's coordinate order (each entry may carry a unit);
    ``names`` the library's names of its entries, listed when the count is wrong."""
    from .. import parse_quantity

    if text is None:
        return default
    parts = [p.strip() for p in text.split(",")]
    if len(parts) != len(names):
        raise InputError(f"expected {len(names)} comma-separated values "
                         f"({', '.join(names)}), got {len(parts)}", field=flag)
    return [parse_quantity(p, None, flag) for p in parts]


_LINK_UNITS = {"mass": "kg", "com_x": "m", "com_y": "m", "com_z": "m"}


def _link_settings(settings: list[str]) -> tuple[list[str], dict[str, float | str]]:
    """--set entries split: the model's parameters (NAME=VALUE), and a link's inertial
    (LINK.FIELD=VALUE, read in SI by the field's unit; a name the library refuses by itself)."""
    from .. import parse_quantity
    from .common import assignments, comma_separated

    own, inertials = [], {}
    for setting in comma_separated(settings):
        name = setting.partition("=")[0].strip()
        if "." not in name:
            own.append(setting)
            continue
        ((name, text),) = assignments([setting], "--set")
        field = name.rpartition(".")[2]
        unit = _LINK_UNITS.get(field, "kg*m^2" if field[:1] == "i" and len(field) == 3 else None)
        inertials[name] = parse_quantity(text, unit, f"--set {name}") if unit else text
    return own, inertials


@app.command()
def dynamics(
    model: Annotated[str, typer.Argument(help="Model file (TOML or URDF) or built-in example name.")],
    q: Annotated[str | None, typer.Option("--q", help="Coordinates, comma-separated in the model's order (a ball joint: its quaternion w,x,y,z; an MJCF free joint: MuJoCo's x,y,z,qw,qx,qy,qz; default: the initial values, a ball unturned).")] = None,  # noqa: E501
    v: Annotated[str | None, typer.Option("--v", help="Velocities, comma-separated (default: the initial rates).")] = None,  # noqa: E501
    a: Annotated[str | None, typer.Option("--a", help="Accelerations: print the inverse dynamics tau.")] = None,  # noqa: E501
    tau: Annotated[str | None, typer.Option("--tau", help="Generalized forces on top of the model's loads: print the forward dynamics q_ddot.")] = None,  # noqa: E501
    lock: Annotated[list[str], typer.Option("--lock", help=LOCK_HELP)] = [],  # noqa: B006
    gravity: Annotated[str | None, typer.Option("--gravity", help=GRAVITY_HELP)] = None,
    payload: Annotated[list[str], typer.Option("--payload", help=PAYLOAD_HELP)] = [],  # noqa: B006
    floating_base: Annotated[bool, typer.Option("--floating-base", help=FLOATING_HELP)] = False,
    set_: Annotated[list[str], typer.Option("--set", help="Override a parameter: NAME=VALUE; a URDF link's inertial LINK.mass, LINK.com_x (y, z), LINK.ixx (ixy, ixz, iyy, iyz, izz), SI.")] = [],  # noqa: B006,E501
    wrench: Annotated[list[str], typer.Option("--wrench", help=WRENCH_HELP)] = [],  # noqa: B006
    actuators: Annotated[bool, typer.Option("--actuators", help="URDF: add each joint's <dynamics> damping (viscous) and friction (Coulomb) to the bias forces.")] = False,  # noqa: E501
    armature: Annotated[list[str], typer.Option("--armature", help=ARMATURE_HELP)] = [],  # noqa: B006
    coriolis: Annotated[bool, typer.Option("--coriolis", help="Also print C(q, q_dot), the matrix of the Coriolis and centrifugal terms (M_dot - 2C skew).")] = False,  # noqa: E501
    derivatives: Annotated[bool, typer.Option("--derivatives", help="With --a: d tau/dq and d tau/dq_dot; with --tau: d q_ddot/dq, d q_ddot/dq_dot and d q_ddot/d tau.")] = False,  # noqa: E501
    json_: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
) -> None:
    """Mass matrix, bias forces C q_dot + g, gravity, inverse or forward dynamics, energies."""
    from .. import resolve_state, state_dynamics, state_layout
    from ..output.dynamics import dynamics_document, dynamics_text

    if a is not None and tau is not None:
        raise InputError("--a (inverse dynamics) and --tau (forward dynamics) ask for two "
                         "things; give one")
    if wrench and a is None and tau is None:
        raise InputError("a wrench acts in inverse (--a) or forward (--tau) dynamics; give one",
                         field="--wrench")
    if derivatives and a is None and tau is None:
        raise InputError("needs --a (inverse dynamics) or --tau (forward dynamics) to "
                         "differentiate", field="--derivatives")
    if derivatives and (wrench or actuators or armature):
        raise InputError("the derivatives are the rigid body's: without --wrench, --actuators "
                         "or --armature (not yet)", field="--derivatives")
    from .. import parse_quantity
    from .common import assignments

    wrenches = _wrenches(wrench)
    rotors = {name: parse_quantity(text, None, f"--armature {name}")
              for name, text in assignments(armature, "--armature")}
    own, inertials = _link_settings(set_)
    system = load_system(model, own, lock, gravity, payload, floating_base)
    coordinates = system.model.coordinates
    start = resolve_state(system.model)  # the model's own initial state (the library's defaults)
    # the names of q's and v's entries (a floating base's and a ball joint's differ)
    layout = state_layout(system)
    names_q, names_v = list(layout.q), list(layout.v)
    base_q, base_v = list(layout.base_q), list(layout.base_v)
    own = [c.name for c in coordinates]
    qs = _vector(q, names_q, "--q", _start(names_q, base_q, dict(zip(own, start.q, strict=True))))
    if q is not None:  # --q 30,0 means 30 rad for an angle (a ball's quaternion: no angle)
        from .. import state_units

        given = [(name, part.strip()) for name, part in zip(names_q, q.split(","), strict=True)
                 if name in own]
        joints = {name: value for name, value in zip(names_q, qs, strict=True) if name in own}
        warn_bare_angles("--q", given, state_units(system.model), joints)
        from .. import limit_warnings

        for line in limit_warnings(system.model, joints, "--q"):
            warn(line)
    vs = _vector(v, names_v, "--v", _start(names_v, base_v, dict(zip(own, start.q_dot, strict=True))))
    # a link's inertial (--set fore.mass=3) is a runtime parameter of the robot's dynamics
    f = system.dynamics(parameters=inertials or None, actuators=actuators,
                        armature=rotors or None)
    # the library evaluates and judges the numbers (a state without dynamics: NaN, said in one
    # line; an overflow: refused); the command prints them
    found = state_dynamics(f, qs, vs, a=_vector(a, names_v, "--a", None),
                           tau=_vector(tau, names_v, "--tau", None), f_ext=wrenches or None,
                           derivatives=derivatives, coriolis=coriolis)
    for line in found.warnings:
        warn(line)
    values, constraints = found.values, found.constraints
    velocities = names_v if names_v != names_q else None  # a floating base, a ball joint
    extra = {}
    if wrenches:
        extra["wrenches"] = wrenches
    if actuators or rotors:
        extra["actuators"] = f.actuators
    if json_:
        print_json({**dynamics_document(names_q, values, system.joint_names, velocities,
                                        constraints), **extra})
    else:
        typer.echo(dynamics_text(names_q, values, velocities, extra, constraints), nl=False)


def _start(names, base, joints) -> list[float]:
    """The default vector: a floating base's numbers, then each joint's initial value (rate),
    a ball joint's quaternion unturned (w = 1) and its angular velocity 0."""
    return list(base) + [joints.get(name, 1.0 if name.endswith("_qw") else 0.0)
                         for name in names[len(base):]]


def base_layout(system):
    """The names of q and v, and a floating base's default numbers before the joints' (none for
    a fixed base), as the library's state_layout gives them."""
    from .. import state_layout

    layout = state_layout(system)
    return list(layout.q), list(layout.v), list(layout.base_q), list(layout.base_v)
