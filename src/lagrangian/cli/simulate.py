"""`lagrangian simulate MODEL --t-end 10`: integrate the equations of motion; table, plot, animation."""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Annotated

import typer

from .. import SIMULATION_METHODS as METHODS  # light: the names only, no scipy
from . import app
from .common import (
    FLOATING_HELP,
    FPS_HELP,
    GRAVITY_HELP,
    LOCK_HELP,
    ONLY_WITH_ANIMATE,
    PAYLOAD_HELP,
    SET_HELP,
    SIZE_HELP,
    load_system,
    print_json,
    state_assignments,
    warn_if_unphysical,
)


@app.command()
def simulate(
    model: Annotated[str, typer.Argument(help="Model file (TOML) or built-in example name.")],
    t_end: Annotated[str, typer.Option("--t-end", help="End time (s, or with a unit: 500ms).")],
    initial: Annotated[list[str], typer.Option("--initial", help="Initial value: NAME=VALUE (theta=30deg, theta_dot=0, t=0; a ball joint's quaternion shoulder_qw..shoulder_qz and angular velocity shoulder_wx..shoulder_wz; an MJCF free joint root_x..root_z, root_qw..root_qz, root_x_dot..root_z_dot (world axes) and root_wx..root_wz; a URDF floating joint between links hook_x..hook_qw and hook_vx..hook_wz); default: the model's initial/rate; repeat, or separate by commas.")] = [],  # noqa: B006,E501
    set_: Annotated[list[str], typer.Option("--set", help=SET_HELP)] = [],  # noqa: B006
    lock: Annotated[list[str], typer.Option("--lock", help=LOCK_HELP)] = [],  # noqa: B006
    gravity: Annotated[str | None, typer.Option("--gravity", help=GRAVITY_HELP)] = None,
    payload: Annotated[list[str], typer.Option("--payload", help=PAYLOAD_HELP)] = [],  # noqa: B006
    floating_base: Annotated[bool, typer.Option("--floating-base", help=FLOATING_HELP)] = False,
    method: Annotated[str, typer.Option("--method", help=f"Integrator: {', '.join(METHODS)}.")] = "DOP853",
    rtol: Annotated[float, typer.Option("--rtol", help="Relative tolerance.")] = 1e-9,
    atol: Annotated[float, typer.Option("--atol", help="Absolute tolerance.")] = 1e-9,
    samples: Annotated[int, typer.Option("--samples", help="Output samples, evenly spaced in time.")] = 1001,
    out: Annotated[Path | None, typer.Option("--out", help="Write the table: .csv or .parquet.")] = None,
    plot: Annotated[Path | None, typer.Option("--plot", help="Plot coordinates and energy: .png (.svg, .pdf).")] = None,  # noqa: E501
    animate: Annotated[Path | None, typer.Option("--animate", help="Animate the mechanism: .gif, .html or .mp4 (MP4 needs lagrangian[mp4]).")] = None,  # noqa: E501
    view: Annotated[str | None, typer.Option("--view", help="Viewpoint of the animation of bodies in space: AZIMUTH,ELEVATION in degrees (default 45,35.26: isometric).")] = None,  # noqa: E501
    size: Annotated[str | None, typer.Option("--size", help=SIZE_HELP)] = None,
    fps: Annotated[int | None, typer.Option("--fps", help=FPS_HELP + " Default 20.")] = None,
    stop_when: Annotated[str | None, typer.Option("--stop-when", help="Stop when a condition turns true, e.g. \"theta < 0\".")] = None,  # noqa: E501
    ignore_limits: Annotated[bool, typer.Option("--ignore-limits", help="URDF: run through the joints' position limits (by default a joint reaching one ends the run, status 'limit', and a start beyond one is refused); a start beyond one is warned.")] = False,  # noqa: E501
    clamp_start: Annotated[bool, typer.Option("--clamp-start", help="URDF: a start beyond a joint's position or velocity limit starts at the limit (with a warning) instead of being refused.")] = False,  # noqa: E501
    control: Annotated[str | None, typer.Option("--control", help="Close the loop: lqr (about --about, inputs --inputs, weights --Q, --R), computed-torque (to the configuration --about, gains --kp, --kd), or model (the model file's own [control] laws, compiled with its equations).")] = None,  # noqa: E501
    about: Annotated[list[str], typer.Option("--about", help="--control: the equilibrium (lqr) or target (computed-torque), NAME=VALUE; others solved for or at their initial values. LQR on a ball joint takes its Euler angles shoulder__x, __y, __z (R = Rx Ry Rz, as modes), computed torque its quaternion shoulder_qw..shoulder_qz.")] = [],  # noqa: B006,E501
    control_inputs: Annotated[list[str], typer.Option("--inputs", help="--control lqr: the loads, parameters or coordinates it drives (F; a ball joint's moments about its Euler hinges shoulder__x, __y, __z); repeat, or separate by commas.")] = [],  # noqa: B006,E501
    q_weight: Annotated[str, typer.Option("--Q", help="--control lqr: state weight, a number or the diagonal (x then x_dot), comma-separated.")] = "1",  # noqa: E501
    r_weight: Annotated[str, typer.Option("--R", help="--control lqr: input weight, a number or the diagonal.")] = "1",  # noqa: E501
    kp: Annotated[str, typer.Option("--kp", help="--control computed-torque: position gain (1/s^2), a number or the diagonal.")] = "100",  # noqa: E501
    kd: Annotated[str, typer.Option("--kd", help="--control computed-torque: rate gain (1/s), a number or the diagonal.")] = "20",  # noqa: E501
    along: Annotated[bool, typer.Option("--linearize-along", help="Also A(t), B(t) of x = [q; q_dot] at the saved samples (u: each coordinate's generalized force); with --json under the key linearize_along; a constrained model's through its multipliers.")] = False,  # noqa: E501
    independent: Annotated[list[str], typer.Option("--independent", help="--linearize-along on a constrained model: A(t), B(t) on the constraint manifold in these n - m coordinates (repeat, or separate by commas; auto: the best conditioned along the run).")] = [],  # noqa: B006,E501
    max_impacts: Annotated[int | None, typer.Option("--max-impacts", help="A model with [[impacts]]: stop after this many (default 1000; status 'impact_limit').")] = None,  # noqa: E501
    settle: Annotated[bool, typer.Option("--settle", help="A model with [[impacts]]: where impacts accumulate (a ball coming to rest), rest on the surface to the end time (status 'settled') instead of stopping there.")] = False,  # noqa: E501
    canonical: Annotated[bool, typer.Option("--canonical", help="Integrate Hamilton's equations in (q, p) instead of (q, q_dot); --out gains the momenta p_<q>.")] = False,  # noqa: E501
    json_: Annotated[bool, typer.Option("--json", help="Print a JSON summary.")] = False,
) -> None:
    """Integrate the equations of motion from the initial state and report, save, plot, animate."""
    from .. import SaveAt, StepControl, parse_quantity, parse_stop_condition, resolve_state
    from ..errors import InputError
    from ..output.control import controller_text, law_summary, law_text
    from ..output.files import check_output_path, partial_path
    from ..output.simulation import projection_warning, simulation_document, simulation_text

    # the writers' checks only for what was asked: a plain run loads no animation or plotting
    if animate is not None or view is not None or size is not None or fps is not None:
        from ..output.animation import (
            check_animatable,
            check_animation_path,
            check_animation_target,
            check_fps,
            check_size,
            check_view,
        )

    system = load_system(model, set_, lock, gravity, payload, floating_base)
    tree = system.model.kinematic_tree
    # q and v differ (a floating base's numbers, a ball joint's quaternion): simulate judges
    manifold = getattr(tree, "floating_base", False) or bool(getattr(tree, "quaternion_joints",
                                                                     ()))
    if not system.runs_on_tree:  # a tree's masses are checked as it is read; nothing derived
        warn_if_unphysical(system.equations_of_motion())
    end = parse_quantity(t_end, "s", "--t-end")
    # Everything the user typed is checked (by the library) before the integration starts.
    start = state_assignments(system, initial, "--initial")
    if not manifold:  # the base's (base_x .. base_wz) and a ball's names: judged by simulate
        start = resolve_state(system.model, start, field="initial")
    step_control = StepControl(method, rtol, atol)
    save_at = SaveAt(samples)
    # a floating base's condition may name base_x .. base_wz, a ball's shoulder_qw ..
    # shoulder_wz: simulate reads it (one line)
    stop = parse_stop_condition(stop_when, system.model) \
        if stop_when is not None and not manifold else stop_when
    if independent and not along:
        raise InputError("it names the coordinates of --linearize-along: give both",
                         field="--independent")
    if out is not None:
        from ..output.tables import check_table_path

        check_table_path(out)
    if plot is not None:
        from ..output.plots import check_plot_path

        check_plot_path(plot)
    _refuse_on_manifold(tree, animate)
    if animate is not None:
        check_animation_path(animate)
        check_animatable(system.model)
    if view is not None:
        check_view(view)
        if animate is None:
            raise InputError("a viewpoint is only used with --animate", field="view")
    if size is not None:
        check_size(size)
    if fps is not None:
        check_fps(fps)
    for given, field in ((size, "size"), (fps, "fps")):
        if given is not None and animate is None:
            raise InputError(f"{ONLY_WITH_ANIMATE[field]} only used with --animate", field=field)
    inputs = (Path(model),) if Path(model).exists() else ()
    for path, field in ((out, "table"), (plot, "plot"), (animate, "animation")):
        if path is not None:  # writable, not a directory, not the model: before the run
            check_output_path(path, field, inputs=inputs)
    if animate is not None:  # free, or an animation this project wrote: never another file
        check_animation_target(animate)
    controller = _controller(system, control, about, control_inputs, q_weight, r_weight, kp, kd)
    if clamp_start and ignore_limits:
        raise InputError("clamps a start to the limits that --ignore-limits ignores; give one",
                         field="--clamp-start")
    limits = "clamp" if clamp_start else not ignore_limits

    with _Progress(end) as progress:
        simulation = system.simulate(
            end, initial=start, method=step_control.method,
            rtol=step_control.rtol, atol=step_control.atol, samples=save_at.samples,
            stop_when=stop, progress=progress.update, limits=limits,
            controller=controller, **_impact_options(system, max_impacts, settle),
            **({"canonical": True} if canonical else {}),
        )
    warning = projection_warning(simulation)
    if warning:
        typer.echo(warning, err=True)

    # a partial result (failed or interrupted run) never replaces an existing file
    from ..kinds import RunStatus

    partial = simulation.status in (RunStatus.FAILED, RunStatus.INTERRUPTED)
    written = {}
    if out is not None:
        written["out"] = str(simulation.save(partial_path(out) if partial else out))
    if plot is not None:
        target = partial_path(plot) if partial else plot
        simulation.plot(target)
        written["plot"] = str(target)
    if animate is not None:
        target = partial_path(animate) if partial else animate
        with _FrameProgress() as frames:
            simulation.animate(target, view=view, progress=frames.update, size=size,
                               fps=20 if fps is None else fps)
        written["animate"] = str(target)

    kept = [name.strip() for text in independent for name in text.split(",") if name.strip()]
    linearized = None if not along else system.linearize_along(
        simulation, independent=None if not kept else "auto" if kept == ["auto"] else kept)
    if json_:
        document = simulation_document(simulation, written)
        if controller == "model":
            document["control"] = {"kind": control, **law_summary(system.model)}
        elif controller is not None:
            document["control"] = {"kind": control, **controller.summary()}
        if linearized is not None:
            document["linearize_along"] = linearized.summary()
        if system.model.impacts:
            from ..output.impacts import impacts_document

            document["impacts"] = impacts_document(simulation)
        print_json(document)
    else:
        typer.echo(simulation_text(simulation, written), nl=False)
        if system.model.impacts:
            from ..output.impacts import impacts_text

            typer.echo(impacts_text(simulation), nl=False)
        if controller is not None:
            typer.echo(law_text(system.model) if controller == "model"
                       else controller_text(controller))
            if getattr(controller, "trim", None):  # the library's trim (System.linearize)
                typer.echo(trim_text(controller.trim))
        if linearized is not None:
            size, width = linearized.B.shape[1:]
            where = "" if not linearized.dependent else (
                f" on the constraints (in {', '.join(linearized.state_names[:size // 2])}; "
                f"{', '.join(linearized.dependent)} follow)")
            typer.echo(f"linearized along the run{where}: A(t) {size} x {size}, B(t) {size} x {width} "
                       f"at {len(linearized)} samples (--json for the numbers)")
    if simulation.status == RunStatus.FAILED:
        saved = f"; partial result saved to {', '.join(written.values())}" if written else ""
        typer.echo(f"error: integration failed: {simulation.message}{saved}", err=True)
        raise SystemExit(1)  # not typer.Exit: click swallows its code outside standalone mode
    if simulation.status == RunStatus.INTERRUPTED:
        saved = f"; partial result saved to {', '.join(written.values())}" if written else ""
        typer.echo(f"{simulation.message}{saved}", err=True)
        raise SystemExit(130)


def _refuse_on_manifold(tree, animate) -> None:
    """What a run whose q and v differ does not take yet, refused in one line before it: a
    floating base's drawing (the model's bodies hold no base; a ball is drawn by its Euler
    hinges)."""
    from ..errors import InputError

    if animate is not None and getattr(tree, "floating_base", False):
        raise InputError("a floating base's run is not animated yet: --out and --plot are",
                         field="--animate")


def _impact_options(system, max_impacts, settle) -> dict:
    """--max-impacts and --settle for a model with impacts; refused for one without."""
    from ..errors import InputError

    if system.model.impacts:
        return {"max_impacts": max_impacts, "settle": settle}
    for flag, given in (("--max-impacts", max_impacts is not None), ("--settle", settle)):
        if given:
            raise InputError("the model has no [[impacts]]", field=flag)
    return {}


def _controller(system, control, about, inputs, q_weight, r_weight, kp, kd):
    """The controller --control names, built by lagrangian.control; None without --control."""
    from ..errors import InputError

    given = {"--about": about, "--inputs": inputs, "--Q": q_weight != "1", "--R": r_weight != "1",
             "--kp": kp != "100", "--kd": kd != "20"}
    used = {None: (), "lqr": ("--about", "--inputs", "--Q", "--R"),
            "computed-torque": ("--about", "--kp", "--kd"), "model": ()}
    if control not in used:
        raise InputError(f"unknown controller {control!r} (lqr, computed-torque or model)",
                         field="controller")
    stray = [flag for flag, value in given.items() if value and flag not in used[control]]
    if stray:
        raise InputError(f"{stray[0]} is not used by "
                         f"{'--control ' + control if control else 'a run without --control'}",
                         field="controller")
    if control is None:
        return None
    if control == "model":  # the file's [control] laws: simulate checks there are some
        return control
    from .. import computed_torque, lqr
    point = state_assignments(system, about, "--about") or None
    if control == "lqr":
        names = [name.strip() for text in inputs for name in text.split(",") if name.strip()]
        if not names:
            raise InputError("--control lqr needs --inputs: the loads or coordinates it drives",
                             field="inputs")
        model = system.linearize(point, inputs=names)
        return lqr(model, _numbers(q_weight, "Q"), _numbers(r_weight, "R"))
    return computed_torque(system, point or {}, _numbers(kp, "Kp"), _numbers(kd, "Kd"))


def trim_text(trim: dict[str, float]) -> str:
    """One line: the inputs' values that hold the equilibrium (the linear model's trim)."""
    values = ", ".join(f"{name} = {value:.6g}" for name, value in trim.items())
    return f"trim (the inputs' values that hold the equilibrium, SI): {values}"


def _numbers(text: str, field: str):
    """A number or a comma-separated diagonal."""
    from ..errors import InputError

    try:
        values = [float(part) for part in text.split(",")]
    except ValueError:
        raise InputError(f"expected a number or comma-separated numbers, got {text!r}",
                         field=field) from None
    return values[0] if len(values) == 1 else values


class _Progress:
    """A rich progress bar on a terminal (stderr), shown once a run has taken about a second."""

    def __init__(self, t_end: float):
        self.t_end = t_end
        self.enabled = sys.stderr.isatty()
        self.started = time.perf_counter()
        self.bar = None
        self.task = None

    def __enter__(self):
        self.started = time.perf_counter()
        return self

    def update(self, t: float) -> None:
        if not self.enabled:
            return
        if self.bar is None:
            if time.perf_counter() - self.started < 1.0:
                return
            from rich.console import Console
            from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

            self.bar = Progress(TextColumn("simulating"), BarColumn(),
                                TextColumn("t = {task.completed:.3g} / {task.total:.3g} s"),
                                TimeElapsedColumn(), console=Console(stderr=True), transient=True)
            self.bar.start()
            self.task = self.bar.add_task("simulate", total=self.t_end)
        self.bar.update(self.task, completed=t)

    def __exit__(self, *exc):
        if self.bar is not None:
            self.bar.stop()
        return False


class _FrameProgress:
    """A rich progress bar on a terminal (stderr) while the animation's frames are written."""

    def __init__(self):
        self.enabled = sys.stderr.isatty()
        self.bar = None
        self.task = None

    def __enter__(self):
        return self

    def update(self, frame: int, frames: int) -> None:
        if not self.enabled:
            return
        if self.bar is None:
            from rich.console import Console
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn

            self.bar = Progress(TextColumn("animating"), BarColumn(), MofNCompleteColumn(),
                                TextColumn("frames"), console=Console(stderr=True),
                                transient=True)
            self.bar.start()
            self.task = self.bar.add_task("animate", total=frames)
        self.bar.update(self.task, completed=frame + 1)

    def __exit__(self, *exc):
        if self.bar is not None:
            self.bar.stop()
        return False
