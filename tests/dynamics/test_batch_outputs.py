"""A large batch's outputs (batch_threads.c): blocks of 4 MB and more are kept when their arrays
are gone and given to the next batch of about their size, and outputs of 4 MB and more are
written past the caches. Neither may change a result: an array a caller still holds, or a view
of one, keeps its numbers when later batches run; every row of a batch that reused a block or
streamed its rows equals that state's call alone."""

from __future__ import annotations

import gc

import numpy as np
import pytest
from tests.dynamics.test_reach_reports import TWO_LEGS

import lagrangian

pytest.importorskip("yourdfpy")

# 9003 states of the floating biped (nv = 10): M and C(q, v) 7.2 MB each, the forward
# derivatives' three outputs 21.6 MB, all kept and streamed; 9003 is not a multiple of the
# lanes, so the last states run one by one, and the second output's rows do not start on a
# 64-byte boundary (written without streaming).
COUNT = 9003
ROWS = (0, 1, 7, 8, 4500, 8999, 9000, 9002)


@pytest.fixture(scope="module")
def robot(tmp_path_factory):
    path = tmp_path_factory.mktemp("biped") / "biped.urdf"
    path.write_text(TWO_LEGS)
    return lagrangian.load(path, floating_base=True).dynamics(backend="c")


def _states(robot, seed):
    rng = np.random.default_rng(seed)
    q = rng.uniform(-0.5, 0.5, (COUNT, len(robot.coordinates)))
    q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=-1, keepdims=True)
    v, a = rng.uniform(-1, 1, (2, COUNT, robot.n))
    return q, v, a


CALLS = {  # each an array that is (a view of) the batch's own block
    "mass_matrix": lambda r, q, v, a: r.mass_matrix(q),
    "coriolis_matrix": lambda r, q, v, a: r.coriolis_matrix(q, v),
    "d q_ddot/dq": lambda r, q, v, a: r.forward_dynamics_derivatives(q, v, a)[0],
    "d q_ddot/dq_dot": lambda r, q, v, a: r.forward_dynamics_derivatives(q, v, a)[1],
    "M^-1": lambda r, q, v, a: r.forward_dynamics_derivatives(q, v, a)[2],
}


@pytest.mark.parametrize("name", list(CALLS))
def test_outputs_held_keep_their_numbers_while_later_batches_reuse_blocks(robot, name):
    call = CALLS[name]
    first, second = _states(robot, 1), _states(robot, 2)
    held = call(robot, *first)
    view = call(robot, *first)[5:9]  # only the view holds its batch's block
    expected_held, expected_view = held.copy(), view.copy()
    for _ in range(3):  # blocks freed and given again, of the same size
        later = call(robot, *second)
        del later
        gc.collect()
    later = call(robot, *second)
    np.testing.assert_array_equal(held, expected_held)
    np.testing.assert_array_equal(view, expected_view)
    assert not np.shares_memory(held, later) and not np.shares_memory(view, later)
    for k in ROWS:  # each row of a batch on a reused block: that state's call alone
        alone = call(robot, *(x[k] for x in second))
        np.testing.assert_allclose(later[k], alone, rtol=1e-12, atol=1e-12)


def test_forward_derivatives_streamed_are_pinned_by_physics(robot):
    """The streamed rows, not only equal to single calls: d q_ddot/d tau is M^-1, so M times it
    is the identity, and d q_ddot/dq_dot at v = 0 is zero (q_ddot is quadratic in v)."""
    q, v, a = _states(robot, 3)
    v[::2] = 0.0
    by_q, by_v, inverse = robot.forward_dynamics_derivatives(q, v, a)
    mass = robot.mass_matrix(q)
    identity = np.einsum("kij,kjl->kil", mass, inverse)
    np.testing.assert_allclose(identity, np.broadcast_to(np.eye(robot.n), identity.shape),
                               atol=1e-10)
    assert np.abs(by_v[::2]).max() < 1e-9
    assert np.isfinite(by_q).all() and np.abs(by_v[1::2]).max() > 1e-3
