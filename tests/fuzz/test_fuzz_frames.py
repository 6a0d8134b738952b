"""Fuzzing the compiled frame functions' seam (reach_bindings.c: frames and references named in
C, q and v read as arrays): hostile frame names (text of every kind, non-strings, unhashable
values), references, and q and v of any shape, type and number, on a fixed and a floating base.
Each call returns an array of the documented shape (NaN rows where a state is not finite, one
DynamicsWarning) or raises lagrangian.InputError with one line naming the argument; never
another exception, never a crash. Where the compiled call answers, the numpy walks give the
same numbers."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

import lagrangian

pytest.importorskip("yourdfpy")

from tests.dynamics.test_floating_base import FLOATING_URDF  # noqa: E402
from tests.dynamics.test_reach_batches import ARM  # noqa: E402

REFERENCES = ("world", "local", "local_world_aligned")


def fuzz(examples: int) -> settings:
    return settings(max_examples=examples, deadline=None, database=None, derandomize=True,
                    print_blob=True, suppress_health_check=list(HealthCheck))


@pytest.fixture(scope="module")
def robots(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fuzz-frames")
    out = {}
    for name, text in (("arm", ARM), ("hopper", FLOATING_URDF)):  # the hopper floats itself
        path = folder / f"{name}.urdf"
        path.write_text(text)
        fast = lagrangian.load(path).dynamics(backend="c")
        if not fast._reach_kernel():
            pytest.skip("no C compiler")
        slow = lagrangian.load(path).dynamics(backend="numpy")
        out[name] = (fast, slow)
    return out


NUMBERS = st.one_of(st.floats(-10, 10), st.sampled_from([np.nan, np.inf, -np.inf, 0.0, -0.0,
                                                        1e300, -1e-300, 1e6]))
NAMES = st.one_of(st.text(max_size=12), st.sampled_from(["tool", "b", "a", "trunk", "foot",
                                                         "tool ", "TOOL", "tool\x00", ""]),
                  st.integers(), st.none(), st.lists(st.text(max_size=3), max_size=2),
                  st.binary(max_size=4), st.floats())


def _array(draw, width: int):
    """q or v: usually (…, width) of numbers, sometimes the wrong width, type or depth."""
    kind = draw(st.sampled_from(["row"] * 5 + ["batch"] * 7 + ["wrong", "list", "text", "ints",
                                                             "empty", "scalar", "deep"]))
    if kind == "row":
        return np.array(draw(st.lists(NUMBERS, min_size=width, max_size=width)))
    if kind == "batch":
        count = draw(st.integers(0, 20))
        return np.array(draw(st.lists(st.lists(NUMBERS, min_size=width, max_size=width),
                                      min_size=count, max_size=count))).reshape(count, width)
    if kind == "wrong":
        return np.zeros(draw(st.integers(0, width + 3).filter(lambda k: k != width)))
    if kind == "list":
        return draw(st.lists(NUMBERS, min_size=width, max_size=width))
    if kind == "text":
        return ["x"] * width
    if kind == "ints":
        return np.arange(width, dtype=np.int64)
    if kind == "empty":
        return np.zeros((0, width))
    if kind == "scalar":
        return 0.5
    return np.zeros((2, 1, 3, width))


@st.composite
def calls(draw):
    robot = draw(st.sampled_from(["arm", "hopper"]))
    function = draw(st.sampled_from(["placement", "jacobian", "jacobian_dot_times_v",
                                     "center_of_mass", "center_of_mass_jacobian",
                                     "coriolis_matrix", "centroidal_momentum_matrix"]))
    frame = draw(NAMES)
    reference = draw(st.one_of(st.sampled_from(REFERENCES), NAMES))
    return robot, function, frame, reference, draw(st.data())


def _call(dynamics, function, frame, reference, q, v):
    method = getattr(dynamics, function)
    if function == "placement":
        return method(q, frame)
    if function == "jacobian":
        return method(q, frame, reference)
    if function == "jacobian_dot_times_v":
        return method(q, v, frame, reference)
    if function == "coriolis_matrix":
        return method(q, v)
    return method(q)


@fuzz(300)
@given(case=calls())
def test_frame_functions_answer_or_refuse_in_one_line(case, robots):
    robot, function, frame, reference, data = case
    fast, slow = robots[robot]
    if data.draw(st.booleans()):  # half the calls name one of the robot's own frames
        frame = data.draw(st.sampled_from(fast.frames))
        reference = data.draw(st.sampled_from(REFERENCES))
    q = _array(data.draw, len(fast.coordinates))
    v = _array(data.draw, fast.n)
    if robot == "hopper" and isinstance(q, np.ndarray) and q.ndim and q.shape[-1] == 7 + 3 \
            and data.draw(st.booleans()):  # mostly unit quaternions, so that numbers come back
        with np.errstate(all="ignore"):
            norm = np.linalg.norm(q[..., 3:7], axis=-1, keepdims=True)
            q = np.where(norm > 0, q, 1.0)
            q[..., 3:7] = q[..., 3:7] / np.where(norm > 0, norm, 2.0)
    answers = []
    for dynamics in (fast, slow):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", lagrangian.DynamicsWarning)
            try:
                answers.append(np.asarray(_call(dynamics, function, frame, reference, q, v)))
            except lagrangian.InputError as exc:
                text = str(exc)
                assert "\n" not in text and text, text
                answers.append(type(exc))
    # the compiled path and the numpy walks agree: both refuse, or both give the same numbers
    if isinstance(answers[1], type):
        assert answers[0] is answers[1], (answers[0], answers[1])
        event(f"{function}: refused")
        return
    event(f"{function}: answered")
    assert not isinstance(answers[0], type), answers
    assert answers[0].shape == answers[1].shape
    used = (q, v) if function in ("jacobian_dot_times_v", "coriolis_matrix") else (q,)
    sizes = [np.abs(np.asarray(x, dtype=float)) for x in used]
    if any((x[np.isfinite(x)] > 1e6).any() for x in sizes):
        return  # overflowing inputs (1e300 m): each path's inf and NaN are its own
    scale = 1.0 + np.nanmax(np.abs(answers[1]), initial=0.0, where=np.isfinite(answers[1]))
    np.testing.assert_array_equal(np.isnan(answers[0]), np.isnan(answers[1]))
    np.testing.assert_allclose(answers[0], answers[1], rtol=0, atol=1e-9 * scale)
