"""A user's arrays read as numbers or refused in one line naming the argument (numbers.py), and
through the dynamics functions: text, a mapping, ragged rows and batches that do not broadcast
are InputError, never numpy's ValueError or TypeError."""

from __future__ import annotations

import numpy as np
import pytest

import lagrangian
from lagrangian.dynamics.tree.numbers import batch_shape, float_array
from lagrangian.errors import InputError


def test_numbers_are_read_and_anything_else_named():
    q = np.arange(3.0)
    assert float_array(q, "q") is q  # no copy of what already is float64
    np.testing.assert_array_equal(float_array([1, 2], "v"), [1.0, 2.0])
    for bad, words in ((["x", 1.0], "could not convert"), ({"a": 1}, "dict"),
                       ([[1.0, 2.0], [3.0]], "rows of different lengths")):
        with pytest.raises(InputError, match=words) as caught:
            float_array(bad, "tau")
        assert caught.value.field == "tau" and "\n" not in str(caught.value)


def test_batches_broadcast_or_are_named():
    assert batch_shape((np.zeros((4, 1, 3)), np.zeros((5, 3))), ("q", "v")) == (4, 5)
    with pytest.raises(InputError, match=r"do not broadcast together \(q \(2,\), v \(3,\)\)"):
        batch_shape((np.zeros((2, 3)), np.zeros((3, 3))), ("q", "v"))


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_dynamics_functions_name_bad_arrays(backend):
    arm = lagrangian.load("two_link_arm").dynamics(backend=backend)
    calls = {
        "q": [lambda: arm.mass_matrix(["x", "y"]), lambda: arm.placement({"a": 1}, "fore"),
              lambda: arm.center_of_mass([[0.1, 0.2], [0.3]])],
        "v": [lambda: arm.bias_forces([0.1, 0.2], ["a", 0.0]),
              lambda: arm.jacobian_dot_times_v([0.0, 0.0], ["a", "b"], "fore")],
        "tau": [lambda: arm.forward_dynamics([0.0, 0.0], [0.0, 0.0], {"x": 1})],
        "dt": [lambda: arm.integrate([0.0, 0.0], [1.0, 0.0], dt="soon")],
    }
    for field, functions in calls.items():
        for call in functions:
            with pytest.raises(InputError) as caught:
                call()
            assert caught.value.field == field, (field, str(caught.value))
    with pytest.raises(InputError, match="do not broadcast"):
        arm.jacobian_dot_times_v(np.zeros((2, 2)), np.zeros((3, 2)), "fore")


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_a_bad_quaternion_is_named_by_its_state_and_a_state_not_finite_is_nan(backend):
    robot = lagrangian.load("two_link_arm", floating_base=True).dynamics(backend=backend)
    q = np.tile([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.3, 0.5], (3, 1))
    q[0, 7] = np.nan  # state 0 not finite: its rows NaN, its quaternion not judged
    q[0, 3:7] = 0.0
    for function in (robot.mass_matrix, robot.center_of_mass,
                     lambda x: robot.placement(x, "fore")):
        with pytest.warns(lagrangian.DynamicsWarning):
            out = function(q)
        assert np.isnan(out[0]).all() and np.isfinite(out[1:]).all()
        bad = q.copy()
        bad[2, 6] = 0.5  # |quaternion| 0.5 in state 2
        with pytest.raises(InputError, match="norm 0.5 in state 2"):
            function(bad)
