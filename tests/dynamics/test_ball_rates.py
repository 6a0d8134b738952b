"""Velocity-level terms of trees with ball joints against MuJoCo, on the compiled engine's
front and the numpy reference: J_dot v of a frame (mj_jac at the frame's origin, by central
differences along mj_integratePos: mj_jacDot leaves out a slide joint's own motion), the
centroidal momentum matrix A_g (summed from each body's mass, inertia and mj_jacBodyCom), C(q, v)
with C v = bias - g (mj_rne) and M_dot - 2C skew (M_dot by mj_fullM along mj_integratePos),
and a wrench at a frame (mj_applyFT) in inverse and forward dynamics."""

from __future__ import annotations

import numpy as np
import pytest

import lagrangian

mujoco = pytest.importorskip("mujoco")
pytest.importorskip("yourdfpy")

from test_ball_joint import BODIES, CHAIN, PENDULUM, _states  # noqa: E402

TOLERANCE = 1e-9
ROBOTS = {"pendulum": (PENDULUM, "bob"), "chain": (CHAIN, "hand"), "bodies": (BODIES, "b")}


@pytest.fixture(scope="module")
def robots(tmp_path_factory):
    out = {}
    for name, (text, frame) in ROBOTS.items():
        path = tmp_path_factory.mktemp("ball") / f"{name}.xml"
        path.write_text(text)
        system = lagrangian.load(path)
        out[name] = ({"compiled": system.dynamics(), "numpy": system.dynamics(backend="numpy")},
                     mujoco.MjModel.from_xml_path(str(path)), frame)
    return out


def _agree(ours, theirs, what):
    error = float(np.abs(np.asarray(ours) - theirs).max())
    assert error <= TOLERANCE * (1.0 + float(np.abs(theirs).max())), f"{what}: off by {error:.2e}"


def _mass_matrix(model, data, qpos):
    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, M)
    return M


def _jacobian_rate(model, data, q, v, point, body, step=1e-6):
    """d/dt J v: MuJoCo's Jacobian at the point fixed to the body, along q (+) v t."""
    data.qpos[:] = q
    mujoco.mj_kinematics(model, data)
    R = data.xmat[body].reshape(3, 3)
    local = R.T @ (point - data.xpos[body])
    out = []
    for sign in (1.0, -1.0):
        moved = q.copy()
        mujoco.mj_integratePos(model, moved, v, sign * step)
        data.qpos[:] = moved
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        jp, jr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
        at = data.xpos[body] + data.xmat[body].reshape(3, 3) @ local
        mujoco.mj_jac(model, data, jp, jr, at, body)
        out.append(np.r_[jp, jr] @ v)
    return (out[0] - out[1]) / (2 * step)


def _centroidal(model, data):
    """A_g = sum_i [m_i Jp_i; I_i Jr_i + m_i (c_i - G) x Jp_i] at each body's centre of mass."""
    A = np.zeros((6, model.nv))
    centre = data.subtree_com[0]
    for i in range(1, model.nbody):
        jp, jr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
        mujoco.mj_jacBodyCom(model, data, jp, jr, i)
        R = data.ximat[i].reshape(3, 3)
        A[:3] += model.body_mass[i] * jp
        A[3:] += (R @ np.diag(model.body_inertia[i]) @ R.T @ jr
                  + model.body_mass[i] * np.cross(data.xipos[i] - centre, jp.T).T)
    return A


@pytest.mark.parametrize("robot", list(ROBOTS))
@pytest.mark.parametrize("backend", ["compiled", "numpy"])
def test_rates_and_wrenches_agree_with_mujoco(robots, robot, backend):
    dynamics, model, frame = robots[robot]
    d = dynamics[backend]
    data = mujoco.MjData(model)
    body = model.body(frame).id
    wrench = np.array([1.0, -2.0, 0.5, 0.3, 0.1, -0.4])  # N, N m at the frame's origin
    for q, v, a in zip(*_states(model, 3, seed=7), strict=True):
        where = f"{robot}, {backend}"
        point = d.placement(q, frame)[:3, 3]  # the frame's origin, fixed to the body
        rate = _jacobian_rate(model, data, q, v, point, body)
        error = np.abs(d.jacobian_dot_times_v(q, v, frame) - rate).max()
        assert error < 1e-7 * (1 + np.abs(rate).max()), f"{where}: J_dot v off by {error:.1e}"
        data.qpos[:], data.qvel[:] = q, v
        mujoco.mj_forward(model, data)
        _agree(d.centroidal_momentum_matrix(q), _centroidal(model, data), f"{where}: A_g")
        generalized = np.zeros(model.nv)
        mujoco.mj_applyFT(model, data, wrench[:3], wrench[3:], point, body, generalized)
        bias = data.qfrc_bias.copy()
        tau = d.inverse_dynamics(q, v, a)
        _agree(d.inverse_dynamics(q, v, a, f_ext={frame: wrench}), tau - generalized,
               f"{where}: ID with a wrench")
        _agree(d.forward_dynamics(q, v, tau - generalized, f_ext={frame: wrench}), a,
               f"{where}: FD with a wrench")
        data.qvel[:] = 0.0
        mujoco.mj_forward(model, data)
        C = d.coriolis_matrix(q, v)
        _agree(C @ v, bias - data.qfrc_bias, f"{where}: C v")
        step = 1e-6
        ahead, behind = q.copy(), q.copy()
        mujoco.mj_integratePos(model, ahead, v, step)
        mujoco.mj_integratePos(model, behind, v, -step)
        M_dot = (_mass_matrix(model, data, ahead) - _mass_matrix(model, data, behind)) / (2 * step)
        skew = M_dot - 2.0 * C
        assert np.abs(skew + skew.T).max() < 1e-7, f"{where}: M_dot - 2C not skew"


def test_a_batch_of_rates_is_its_single_calls(robots):
    """Batches on the numpy reference: each row its state's single call."""
    dynamics, model, frame = robots["chain"]
    d = dynamics["numpy"]
    Q, V, _ = _states(model, 4, seed=2)
    for function, args in [(d.coriolis_matrix, (Q, V)), (d.centroidal_momentum_matrix, (Q,)),
                           (lambda q, v: d.jacobian_dot_times_v(q, v, frame), (Q, V))]:
        batch = function(*args)
        for i in (0, 3):
            np.testing.assert_allclose(batch[i], function(*(x[i] for x in args)), atol=1e-13)
