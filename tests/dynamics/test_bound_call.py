"""The engine's recursions as TreeDynamics's own methods (engine/bound_call.c): one compiled call
with the tree's tables bound, the class's checked method behind it for inputs it does not take,
and the NaN rows' one warning at the user's line. Physics: the two-link point arm's closed-form
M = [[2 + 2c, 1 + c], [1 + c, 1]] kg m^2 (test_batch_reports.py's POINT_ARM)."""

from __future__ import annotations

import gc
import warnings
import weakref

import numpy as np
import pytest
from test_batch_reports import POINT_ARM

import lagrangian
from lagrangian.dynamics.recursive import TreeDynamics


@pytest.fixture(scope="module")
def arm(tmp_path_factory):
    pytest.importorskip("yourdfpy")
    path = tmp_path_factory.mktemp("bound") / "point_arm.urdf"
    path.write_text(POINT_ARM)
    robot = lagrangian.load(path).dynamics(kernel="compact")
    if robot.kernel != "compact":
        pytest.skip("no compiler: the numpy recursions")
    return path, robot


def _closed_form(elbow: float) -> np.ndarray:
    c = np.cos(elbow)
    return np.array([[2 + 2 * c, 1 + c], [1 + c, 1.0]])


def test_each_recursion_is_the_compiled_call_with_the_class_method_behind_it(arm):
    _, robot = arm
    assert "mass_matrix" in vars(robot)  # the instance's own: no Python frame in front
    assert robot.mass_matrix.__doc__ == TreeDynamics.mass_matrix.__doc__
    assert "TreeDynamics.mass_matrix" in repr(robot.mass_matrix)
    np.testing.assert_allclose(robot.mass_matrix(np.array([0.3, 1.1])), _closed_form(1.1),
                               atol=1e-14)
    # a list, a batch, a keyword: the checked path, the same numbers
    np.testing.assert_allclose(robot.mass_matrix([0.3, 1.1]), _closed_form(1.1), atol=1e-14)
    batch = robot.mass_matrix(np.array([[0.0, 0.5], [1.0, 2.0]]))
    np.testing.assert_allclose(batch, [_closed_form(0.5), _closed_form(2.0)], atol=1e-14)
    np.testing.assert_allclose(robot.mass_matrix(q=[0.0, 0.5]), _closed_form(0.5), atol=1e-14)
    tau = robot.inverse_dynamics([0.0, 0.5], [0.0, 0.0], [1.0, 0.0], f_ext=None)
    np.testing.assert_allclose(tau - robot.gravity([0.0, 0.5]), _closed_form(0.5)[:, 0],
                               atol=1e-12)


def test_bad_input_is_named_and_nan_rows_warn_at_the_users_line(arm):
    _, robot = arm
    with pytest.raises(lagrangian.InputError, match="q: expected 2 values"):
        robot.mass_matrix(np.zeros(3))
    with pytest.raises(TypeError):
        robot.forward_dynamics(np.zeros(2))
    q = np.array([[0.0, 0.5], [np.nan, 0.5]])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = robot.mass_matrix(q)
    assert len(caught) == 1 and caught[0].filename == __file__
    assert "1 of 2 states" in str(caught[0].message)
    assert np.isnan(out[1]).all()
    np.testing.assert_allclose(out[0], _closed_form(0.5), atol=1e-14)


def test_the_bound_methods_let_their_dynamics_go(arm):
    path, _ = arm
    robot = lagrangian.load(path).dynamics(kernel="compact")
    gone = weakref.ref(robot)
    del robot
    gc.collect()
    assert gone() is None
