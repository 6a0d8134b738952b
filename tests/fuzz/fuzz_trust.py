"""Hostile inputs for the seams of issue 39, shared by tests/fuzz/test_fuzz_trust.py (a few
hundred a surface in CI) and by this file's campaign (``python tests/fuzz/fuzz_trust.py
--inputs 100000``, a count per surface): [control] laws of model files (the reader), LQR
options (Q and R as numbers, diagonals, matrices and the command line's text), class folders
(hostile file names, links to the answer key, FIFOs, folders named *.toml), report options
(--size, --fps, --t-end, --out), codegen names (--name), MJCF documents (parse_mjcf) and
[[impacts]] tables (the model file's reader). Every surface runs in-process, in milliseconds an
input: the CLI runs that compile are the older campaigns' (fuzz_seams.py).

The contract: an answer, or the project's one-line error (a LagrangianError); never another
exception, never numpy's RuntimeWarning, never a hang; and the surface's own promise (a C
prefix that is an identifier, a linked file never read, a name printed on one line).
"""

from __future__ import annotations

import functools
import os
import sys
import warnings
from pathlib import Path

from hypothesis import strategies as st

sys.path.insert(0, str(Path(__file__).resolve().parent))

from fuzz_inputs import HOSTILE_NUMBERS, LagrangianError, expressions, run_input  # noqa: E402
from fuzz_seams import C_SEQUENCES, control_models, special_names  # noqa: E402

SECRET = "KEY_SECRET_7f3a"  # in the answer key: no message may quote it


class Broke(AssertionError):
    """The surface broke its promise (not a refusal)."""


def quiet(action):
    """``action`` with numpy's warnings turned into failures: none may leak into a line."""
    def run():
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            return action()
    return run


# -- [control] laws in model files ----------------------------------------------------------

def read_control(text: str) -> None:
    import lagrangian

    model = lagrangian.parse_model(text)
    for name, law in model.control:  # each law read by the whitelist parser: a sympy expression
        if not hasattr(law, "free_symbols"):
            raise Broke(f"law {name!r} is {type(law).__name__}, not an expression")


# -- LQR options --------------------------------------------------------------------------

_NUMBER = st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                    st.sampled_from([0.0, -0.0, 1.0, -1.0, 1e308, -1e308, 1e-320, 1e100, 1e101,
                                     float("nan"), float("inf"), 10.0, 1e-12]))


def weights() -> st.SearchStrategy:
    """A weight as Python gives it: a number, a diagonal (right size or not), a matrix (square,
    not, symmetric or not), text, None, nested lists."""
    positive = st.floats(1e-6, 1e6)
    return st.one_of(
        positive, positive, st.lists(positive, min_size=4, max_size=4),  # valid for Q (x 4)
        _NUMBER,
        st.lists(_NUMBER, min_size=0, max_size=6),
        st.lists(st.lists(_NUMBER, min_size=1, max_size=4), min_size=1, max_size=4),
        st.sampled_from([None, "1", "abc", [[1, 2], [3]], {"a": 1}, True, 1j, [1j, 1, 1, 1]]),
    )


def weight_texts() -> st.SearchStrategy[str]:
    """--Q / --R as typed: a number or a comma-separated diagonal, hostile numbers included."""
    numbers = st.one_of(st.sampled_from(HOSTILE_NUMBERS + ["", " ", "-1", "1e-320", "1,"]),
                        st.floats(allow_nan=True, allow_infinity=True).map(repr))
    return st.lists(numbers, min_size=1, max_size=6).map(",".join)


_UPRIGHT = {}


def upright():
    """The cart-pole's linear model about its upright, F the input (built once)."""
    if not _UPRIGHT:
        import math

        import lagrangian

        _UPRIGHT["model"] = lagrangian.load("cart_pendulum").linearize(
            {"x": 0, "theta": math.pi}, inputs=["F"])
    return _UPRIGHT["model"]


def design_lqr(weights_pair) -> None:
    import numpy as np

    import lagrangian

    Q, R = weights_pair
    design = lagrangian.lqr(upright(), Q, R)
    if not np.all(np.linalg.eigvals(design.closed_loop).real < 0):
        raise Broke("an LQR that does not stabilize was returned")


def design_lqr_from_text(texts) -> None:
    from lagrangian.cli.simulate import _numbers

    q_text, r_text = texts
    design_lqr((_numbers(q_text, "Q"), _numbers(r_text, "R")))


# -- class folders ------------------------------------------------------------------------

_KINDS = ["file", "file", "file", "link to key", "link to dir", "dangling link", "fifo",
          "folder", "empty", "hidden", "link loop"]


@st.composite
def class_folders(draw) -> list[tuple[str, str]]:
    """A class folder as (kind, file name) pairs: names with newlines, escapes, bidirectional
    overrides, separators and any Unicode, all ending .toml."""
    piece = st.one_of(st.sampled_from(["\n", "\r", "\x1b[2J", "\u202e", "\u2028", "\t", "\x00",
                                       "\x7f", "\x85", "ok", "student", "..", " ", "\\", "'",
                                       '"', ",", "é", "🙂"]),
                      st.text(min_size=1, max_size=5))
    name = st.lists(piece, min_size=1, max_size=4).map("".join)
    entries = draw(st.lists(st.tuples(st.sampled_from(_KINDS), name), min_size=1, max_size=5))
    return entries


def lay_out(folder: Path, entries) -> dict[str, str]:
    """Make the folder (names a file system refuses are left out); {path: kind}."""
    key = folder.parent / "KEY.toml"
    if not key.exists():
        key.write_text(f'[answer]\nT = "1/2*m*L^2*theta_dot^2"\n# {SECRET}\n', encoding="utf-8")
    made = {}
    for i, (kind, name) in enumerate(entries):
        stem = name.replace("/", "_").replace("\x00", "_")
        stem = ("." if kind == "hidden" else "") + f"{i}{stem}"
        path = folder / f"{stem}.toml"
        try:
            if kind in ("file", "hidden"):
                path.write_text('[answer]\nT = "1/2*m*L^2*theta_dot^2"\n', encoding="utf-8")
            elif kind == "empty":
                path.write_bytes(b"")
            elif kind == "link to key":
                path.symlink_to(key)
            elif kind == "link to dir":
                path.symlink_to(folder.parent)
            elif kind == "dangling link":
                path.symlink_to(folder / "absent.toml")
            elif kind == "link loop":
                path.symlink_to(path)
            elif kind == "fifo":
                os.mkfifo(path)
            elif kind == "folder":
                path.mkdir()
        except (OSError, ValueError):  # a name the file system refuses: not part of the class
            continue
        made[str(path)] = kind
    return made


def list_class(folder: Path, entries) -> None:
    """answer_files of the folder: links, FIFOs and folders never graded, every error one line
    without the key's text, every listed file a regular file inside the folder."""
    import lagrangian

    made = lay_out(folder, entries)
    listed = lagrangian.answer_files([folder])
    for path, error in listed:
        kind = made.get(path)
        if error is None and kind not in ("file", "empty", None):
            raise Broke(f"a {kind} would be graded: {path!r}")
        if error is not None and ("\n" in error or "\r" in error or SECRET in error):
            raise Broke(f"an error that forges a line or quotes the key: {error!r}")
        if error is None and Path(path).is_symlink():
            raise Broke(f"a link would be read: {path!r}")


# -- report options -----------------------------------------------------------------------

def report_options() -> st.SearchStrategy[tuple]:
    texts = st.one_of(st.sampled_from(["400x400", "0x0", "1x1", "99999x99999", "-1x4", "1e3x2",
                                       "x", "", "400X300", "400x", "nanxnan", "4x4x4",
                                       "400 x 300"]),
                      st.text(max_size=10))
    fps = st.one_of(st.integers(-10**20, 10**20), st.sampled_from([0, 1, 120, 121, -1]))
    ends = st.one_of(st.sampled_from(HOSTILE_NUMBERS + ["1 s", "2 min", "1kg", "-1", "1e-320",
                                                        "10 h", "0"]), st.text(max_size=8))
    outs = st.one_of(st.sampled_from(["page.html", "page.htm", "page.txt", "", ".", "..",
                                      "dir/", "a\nb.html", "x.HTML", "/dev/null",
                                      "/proc/self/mem", "nul.html"]),
                     st.text(max_size=12).map(lambda s: s + ".html"))
    # each option valid half the time, so the others reach their own checks too
    return st.tuples(st.one_of(texts, st.sampled_from(["400x400", "320x240", "64x64"])),
                     st.one_of(fps, st.integers(1, 120)),
                     st.one_of(ends, st.sampled_from(["1", "2.5 s", "0.5s", "1 min"])),
                     st.one_of(outs, st.sampled_from(["page.html", "out/page.html", "r.htm"])))


def check_report_options(options, folder: Path) -> None:
    from lagrangian import check_report_path, parse_quantity
    from lagrangian.output.media import check_fps, check_size

    size, fps, end, out = options
    check_size(size)
    check_fps(fps)
    parse_quantity(end, "s", "--t-end")
    target = Path(out) if os.path.isabs(out) else folder / out
    before = set(folder.iterdir())
    check_report_path(target)
    if set(folder.iterdir()) != before:
        raise Broke("checking a report path wrote a file")


# -- codegen names ------------------------------------------------------------------------

_PENDULUM = {}


def codegen_name(name: str) -> None:
    import re

    import lagrangian

    if not _PENDULUM:
        _PENDULUM["system"] = lagrangian.load("pendulum")
    code = _PENDULUM["system"].to_c(name)
    if not re.fullmatch(r"[a-z][a-z0-9_]{0,39}", code.prefix):
        raise Broke(f"prefix {code.prefix!r} is not a C identifier")
    if any(s in code.prefix for s in C_SEQUENCES if s.strip()):
        raise Broke(f"a C sequence in the prefix {code.prefix!r}")


def codegen_names() -> st.SearchStrategy[str]:
    valid = st.from_regex(r"[a-z][a-z0-9_]{0,45}", fullmatch=True)
    return st.one_of(special_names(), valid, st.sampled_from(["", " ", "a" * 40, "a" * 41,
                                                              "main", "int", "_x", "x-y"]))


# -- MJCF documents -----------------------------------------------------------------------

_LEG = """<mujoco model="NAME">
  <option gravity="GRAVITY"/>
  <worldbody>
    <body name="trunk" pos="POS">
      <freejoint name="root"/>
      <inertial pos="0.01 0.02 -0.01" mass="MASS" fullinertia="INERTIA"/>
      <body name="thigh" pos="0.2 0.1 0" euler="EULER">
        <joint name="hip" type="KIND" axis="AXIS" range="RANGE"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="SIZE"/>
        <body name="shin" pos="0 0 -0.3">
          <joint name="JOINT" axis="1 1 0"/>
          <geom type="GEOM" size="0.02 0.03 0.15" pos="0 0 -0.15"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
"""
_SLOTS = {"NAME": "leg", "GRAVITY": "0 0 -9.81", "POS": "0 0 1", "MASS": "5",
          "INERTIA": "0.1 0.2 0.25 0.01 -0.02 0.03", "EULER": "10 0 20", "KIND": "hinge",
          "AXIS": "0 1 0", "RANGE": "-1 1", "SIZE": "0.03", "JOINT": "knee", "GEOM": "box"}


@st.composite
def mjcf_documents(draw) -> str:
    """The floating leg of tests/mjcf_models.py with some of its values hostile: numbers
    (1e308, nan, -1, 1e-400), the wrong count, text, joint and geom kinds, names; sometimes a
    line dropped (an unclosed element, a body without mass)."""
    numbers = st.sampled_from(HOSTILE_NUMBERS)
    hostile = st.one_of(numbers, st.lists(numbers, min_size=0, max_size=7).map(" ".join),
                        st.sampled_from(["", " ", "ball", "slide", "free", "cylinder", "mesh",
                                         "root", "hip", "&amp;", "&lt;", "<", "\"", "]]>"]),
                        special_names().map(lambda s: s.replace("\x00", "")))
    values = {slot: draw(hostile) if draw(st.integers(0, 5)) == 5 else value
              for slot, value in _SLOTS.items()}
    text = _LEG
    for slot, value in values.items():
        text = text.replace(slot, value)
    lines = text.splitlines()
    if draw(st.booleans()) and draw(st.booleans()):
        del lines[draw(st.integers(0, len(lines) - 1))]
    return "\n".join(lines)


def read_mjcf_document(text: str) -> None:
    """parse_mjcf in both layouts (MuJoCo's own, a free joint its three world slides and a
    ball; and the floating base): a robot model, or one line; an accepted model's masses and
    inertias finite, its masses >= 0."""
    from lagrangian.model.mjcf import parse_mjcf

    for floating_base in (False, True):
        try:
            model = parse_mjcf(text, floating_base=floating_base)
        except LagrangianError:
            if floating_base:
                raise
            continue  # refused in MuJoCo's layout (its one line): the floating base's below
        _check_bodies(model)
        if not floating_base:
            _through_the_engine(model)


def _through_the_engine(model) -> None:
    """An accepted MJCF robot in MuJoCo's layout through the compiled engine at a random state
    (unit quaternions): M symmetric, and M, ID, FD and its derivatives finite, or the row NaN
    with the library's own DynamicsWarning (a massless branch: M not positive definite)."""
    import numpy as np

    from lagrangian import DynamicsWarning, System
    from lagrangian.dynamics.tree.spherical import quaternion_slices

    system = System(model)
    if not system.runs_on_tree:
        return
    d = system.dynamics()
    rng = np.random.default_rng(len(d.coordinates))
    q = rng.uniform(-1.0, 1.0, len(d.coordinates))
    for _, _, at, _ in quaternion_slices(d.tree):
        q[at:at + 4] /= np.linalg.norm(q[at:at + 4])
    v, tau = rng.uniform(-1.0, 1.0, (2, d.n))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynamicsWarning)  # the library's own: a NaN row
        M = d.mass_matrix(q)
        if not (np.isfinite(M).all() and np.array_equal(M, M.T)):
            raise Broke(f"M not finite and symmetric: {M}")
        if not np.isfinite(d.inverse_dynamics(q, v, tau)).all():
            raise Broke("inverse dynamics not finite")
        a = d.forward_dynamics(q, v, tau)
        derivatives = d.forward_dynamics_derivatives(q, v, tau)
    if np.isfinite(a).all() != all(np.isfinite(x).all() for x in derivatives):
        raise Broke("forward dynamics and its derivatives disagree on being defined")


def _check_bodies(model) -> None:
    import math

    import sympy as sp

    for body in model.rigid_bodies:
        for value in (body.mass, *(x for row in body.inertia for x in row)):
            number = sp.sympify(value)
            if number.is_number and not math.isfinite(float(number)):
                raise Broke(f"body {body.name!r} accepted with {value} in its inertia")
        if sp.sympify(body.mass).is_number and float(body.mass) < 0:
            raise Broke(f"body {body.name!r} accepted with mass {body.mass}")


# -- [[impacts]] tables -------------------------------------------------------------------

_BALL = {}


@st.composite
def impact_tables(draw) -> str:
    """The bouncing ball's [[impacts]] with hostile guards, points, normals, restitutions,
    tangential laws, releases and relabels (expressions, numbers, lists, tables, text)."""
    import json

    expressions_ = st.one_of(expressions(), st.sampled_from(HOSTILE_NUMBERS))
    anything = st.one_of(expressions_.map(json.dumps), st.sampled_from(HOSTILE_NUMBERS),
                         st.lists(expressions_, max_size=4).map(json.dumps),
                         st.sampled_from(["true", "{}", "[]", '{ y = "y" }', '{ q = "y" }',
                                          '"stick"', '"slip"', '"pivot"', '"ball"', '"floor"',
                                          '"nowhere"', "[0, 1]", "[0, 0]", "[1e308, 1e308]",
                                          '["nan", 1]', "[0, 1, 0]", '"e"', '"-e"', '"2"']))
    keys = {"name": '"floor"', "guard": '"y"', "point": '"ball"', "normal": "[0, 1]",
            "restitution": '"e"'}
    for key in ("name", "guard", "point", "normal", "restitution", "tangential", "release",
                "relabel", "bogus"):
        if draw(st.integers(0, 5)) == 5:  # hypothesis leans to 0: the valid table first
            keys[key] = draw(anything)
        elif key in keys and draw(st.integers(0, 9)) == 9:
            del keys[key]
    if not _BALL:
        from fuzz_inputs import EXAMPLE_TEXTS

        _BALL["text"] = EXAMPLE_TEXTS["bouncing_ball"].split("[[impacts]]")[0]
    table = "\n".join(f"{key} = {value}" for key, value in keys.items())
    return f"{_BALL['text']}[[impacts]]\n{table}\n"


def read_impacts(text: str) -> None:
    """parse_model: the model with its impacts (a numeric normal of unit length), or one
    line."""
    import math

    import sympy as sp

    import lagrangian

    model = lagrangian.parse_model(text)
    for impact in model.impacts:
        normal = [sp.sympify(c) for c in impact.normal]
        if all(c.is_number for c in normal) and not math.isclose(
                math.sqrt(sum(float(c) ** 2 for c in normal)), 1.0, rel_tol=1e-9):
            raise Broke(f"impact {impact.name!r} accepted with normal {impact.normal}")


_ENGINE_ROBOTS = {  # MJCF text, floating_base: a ball and MuJoCo's free joint, a free flyer
    "free joint, ball": ("FREE", False), "free flyer base": ("FREE", True),
    "ball, hinge, ball": ("CHAIN", False)}


@functools.cache
def _engine_robot(name: str):
    """The robot's compiled dynamics, built once a process (tests/mjcf_models.py's chain)."""
    import tempfile

    import lagrangian

    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from mjcf_models import BALL_HINGE_BALL, FREE_HINGE_BALL

    which, floating = _ENGINE_ROBOTS[name]
    text = BALL_HINGE_BALL if which == "CHAIN" else FREE_HINGE_BALL
    path = Path(tempfile.mkdtemp(prefix="fuzz-engine-")) / "robot.xml"
    path.write_text(text)
    return lagrangian.load(path, floating_base=floating).dynamics()


@st.composite
def engine_calls(draw):
    """(robot, function, inputs): one state's q, v, a of hostile numbers (NaN, inf, 1e308, a
    quaternion off unit norm or scaled by 1 + 1e-12), as float64 vectors, strided views,
    read-only arrays, float32, int or a list, now and then a number short or long."""
    import numpy as np

    robot = draw(st.sampled_from(sorted(_ENGINE_ROBOTS)))
    function = draw(st.sampled_from(["mass_matrix", "inverse_dynamics", "forward_dynamics",
                                     "bias_forces", "gravity", "kinetic_energy",
                                     "potential_energy"]))
    d = _engine_robot(robot)
    count = {"mass_matrix": 1, "gravity": 1, "potential_energy": 1, "bias_forces": 2,
             "kinetic_energy": 2}.get(function, 3)
    numbers = st.one_of(st.floats(-3.0, 3.0), st.sampled_from(
        [0.0, -0.0, 1e308, -1e308, 1e-308, float("nan"), float("inf"), float("-inf")]))
    inputs = []
    for k in range(count):
        width = d.nq if k == 0 else d.nv
        width += draw(st.sampled_from([0] * 12 + [-1, 1]))
        x = np.array(draw(st.lists(numbers, min_size=max(width, 0), max_size=max(width, 0))))
        if k == 0 and width == d.nq and draw(st.booleans()):  # its quaternions unit (or nearly)
            from lagrangian.dynamics.tree.spherical import quaternion_slices

            at = [s for *_, s, _ in quaternion_slices(d.tree)] + ([3] if d.tree.floating_base
                                                                  else [])
            with np.errstate(all="ignore"):
                for i in at:
                    x[i:i + 4] /= np.linalg.norm(x[i:i + 4]) / draw(st.sampled_from(
                        [1.0, 1.0 + 1e-12, 1.0 + 1e-6, 1.5]))
        layout = draw(st.sampled_from(["vector", "vector", "strided", "read-only", "float32",
                                       "int", "list"]))
        if layout == "strided":
            x = np.repeat(x, 2)[::2]
        elif layout == "read-only":
            x.flags.writeable = False
        elif layout == "float32":
            with np.errstate(over="ignore"):  # 1e308 is inf in float32
                x = x.astype(np.float32)
        elif layout == "int":
            with np.errstate(all="ignore"):
                x = np.nan_to_num(x, posinf=9, neginf=-9).astype(np.int64)
        elif layout == "list":
            x = x.tolist()
        inputs.append(x)
    return robot, function, tuple(inputs)


def call_engine(drawn) -> None:
    """One state through the compiled front (its own path, engine/tree_kernel_bindings.c's
    tk_single) and the same state as a batch of one (the batch path): the same refusal, or the
    same numbers bit for bit (NaN where either has them), the same DynamicsWarning count."""
    import numpy as np

    from lagrangian import DynamicsWarning

    robot, function, inputs = drawn
    call = getattr(_engine_robot(robot), function)
    outcomes = []
    for shaped in (inputs, tuple(np.asarray(x)[None] for x in inputs)):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", DynamicsWarning)
            try:
                out = np.asarray(call(*shaped))
            except LagrangianError as exc:
                outcomes.append(("refused", str(exc)))
                continue
        outcomes.append(("answer", out, sum(isinstance(w.message, DynamicsWarning)
                                             for w in caught)))
    (alone, batch) = outcomes
    if alone[0] != batch[0]:
        raise Broke(f"one state {alone[0]}, its batch of one {batch[0]}: {alone[1]!s:.200}")
    if alone[0] == "refused":
        raise LagrangianError(alone[1])  # the one line, counted as the surface's refusal
    if alone[2] != batch[2] or not np.array_equal(alone[1], batch[1][0], equal_nan=True):
        raise Broke(f"one state's {function} is not its batch of one's row")


# -- the surfaces ---------------------------------------------------------------------------

def surfaces(folder: Path) -> dict[str, tuple[st.SearchStrategy, object]]:
    """Surface name -> (strategy, action on one drawn input)."""
    counter = iter(range(10**9))

    def in_fresh_folder(entries):
        klass = folder / f"class-{next(counter)}"
        klass.mkdir()
        return list_class(klass, entries)

    return {
        "control laws (model file reader)": (control_models(), read_control),
        "LQR options (Python Q, R)": (st.tuples(weights(), weights()), design_lqr),
        "LQR options (--Q, --R text)": (st.tuples(weight_texts(), weight_texts()),
                                       design_lqr_from_text),
        "class folders (answer_files)": (class_folders(), in_fresh_folder),
        "report options (--size, --fps, --t-end, --out)": (
            report_options(), lambda options: check_report_options(options, folder)),
        "codegen names (--name)": (codegen_names(), codegen_name),
        "MJCF documents (parse_mjcf)": (mjcf_documents(), read_mjcf_document),
        "[[impacts]] tables (model file reader)": (impact_tables(), read_impacts),
        "engine calls (one state, a batch of one)": (engine_calls(), call_engine),
    }


def outcome_of(action, value, seconds: float = 20.0):
    """fuzz_inputs.Outcome of one input; a Broke promise or any other exception is a crash."""
    return run_input(quiet(lambda: action(value)), seconds)


def campaign(inputs: int, folder: Path, only: str | None = None, seed: int = 0) -> dict:
    """``inputs`` random inputs per surface: {surface: {status: count}} and the failures."""
    report: dict[str, dict] = {}
    for name, (strategy, action) in surfaces(folder).items():
        if only and only not in name:
            continue
        counts: dict[str, int] = {}
        failures: list[str] = []
        _run_surface(strategy, action, inputs, counts, failures)
        report[name] = {"counts": counts, "failures": failures}
    return report


def _run_surface(strategy, action, inputs: int, counts: dict, failures: list) -> None:
    """``inputs`` random draws of ``strategy`` through ``action``, counted."""
    from hypothesis import HealthCheck, given, settings

    @settings(max_examples=inputs, deadline=None, database=None, derandomize=False,
              suppress_health_check=list(HealthCheck))
    @given(value=strategy)
    def run(value):
        outcome = outcome_of(action, value)
        counts[outcome.status] = counts.get(outcome.status, 0) + 1
        if not outcome.ok and len(failures) < 20:
            failures.append(f"{outcome.kind}: {outcome.message[:300]} <- {value!r:.300}")

    run()


def main(argv: list[str] | None = None) -> int:
    """python tests/fuzz/fuzz_trust.py [--inputs N] [--surface TEXT] [--json PATH]"""
    import argparse
    import json
    import tempfile

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--inputs", type=int, default=100_000, help="inputs per surface")
    parser.add_argument("--surface", default=None, help="only surfaces whose name holds this")
    parser.add_argument("--json", default=None, help="write the counts here")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        report = campaign(args.inputs, Path(folder), args.surface)
    for name, result in report.items():
        print(f"{name}: {result['counts']}")
        for failure in result["failures"]:
            print(f"  FAILED {failure}")
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=2), encoding="utf-8")
    return 1 if any(r["failures"] for r in report.values()) else 0


__all__ = ["Broke", "LagrangianError", "campaign", "outcome_of", "surfaces"]

if __name__ == "__main__":
    raise SystemExit(main())
