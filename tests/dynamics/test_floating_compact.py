"""A floating base on the compact kernel (compact_kernel.py: one compiled module for every tree,
the free flyer as body 0): M, bias, g, inverse and forward dynamics and the energies agree with
Pinocchio's buildModelFromUrdf(path, JointModelFreeFlyer()) to 1e-12, a batch equals its states
one by one, a quaternion of the wrong norm is one line, and kernel="auto" picks it for a large
floating tree (Talos) and for a floating tree with link inertials set at run time."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

import lagrangian

pytest.importorskip("yourdfpy")
pytestmark = pytest.mark.skipif(not (shutil.which("cc") or shutil.which("gcc")),
                                reason="no C compiler")

from tests.dynamics.test_floating_base import (  # noqa: E402
    FLOATING_URDF,
    _compare_dynamics,
    _robots,
)


@pytest.mark.parametrize("robot", [
    "solo_description/robots/solo12.urdf",
    "anymal_b_simple_description/robots/anymal.urdf",
    "talos_data/robots/talos_reduced.urdf",
])
def test_compact_floating_robots_match_pinocchio(robot):
    """A quadruped whose trunk is the root link, one welded below it, a humanoid: to 1e-12."""
    import pinocchio as pin

    path = _robots() / robot
    if not path.is_file():
        pytest.skip(f"{robot} is not in this example-robot-data")
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    ours = lagrangian.load(path, floating_base=True).dynamics(kernel="compact")
    assert ours.kernel == "compact"
    _compare_dynamics(model, ours, states=5)


def test_auto_picks_the_compact_kernel_for_a_large_floating_tree():
    """The full Talos (more than COMPACT_ABOVE bodies, its grippers' mimic joints as one
    coordinate each, where Pinocchio keeps them apart) on a floating base runs the compact
    kernel without kernel="compact", and agrees with the numpy recursions (the tree's joints
    read directly) to 1e-12, forward dynamics by Cholesky of M for the mimic joints."""
    path = _robots() / "talos_data/robots/talos_full_v2.urdf"
    if not path.is_file():
        pytest.skip("talos_full_v2.urdf is not in this example-robot-data")
    system = lagrangian.load(path, floating_base=True)
    ours, twin = system.dynamics(), system.dynamics(backend="numpy")
    assert ours.kernel == "compact" and len(ours.tree.joints) > 16
    rng = np.random.default_rng(2)
    q = rng.uniform(-1, 1, (3, ours.nq))
    q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=-1, keepdims=True)
    v, a = rng.uniform(-1, 1, (2, 3, ours.nv))
    for name, arguments in (("mass_matrix", (q,)), ("bias_forces", (q, v)), ("gravity", (q,)),
                            ("inverse_dynamics", (q, v, a)), ("kinetic_energy", (q, v)),
                            ("potential_energy", (q,))):
        expected = getattr(twin, name)(*arguments)
        np.testing.assert_allclose(getattr(ours, name)(*arguments), expected, rtol=0,
                                   atol=1e-12 * max(1.0, np.abs(expected).max()))
    mass, bias = twin.mass_matrix(q), twin.bias_forces(q, v)
    # M q_ddot + b = tau to 1e-12 of |M| |q_ddot| (a solve's backward error)
    forward = ours.forward_dynamics(q, v, a)
    residual = np.einsum("kij,kj->ki", mass, forward) + bias - a
    scale = np.einsum("kij,kj->ki", np.abs(mass), np.abs(forward)).max()
    assert np.abs(residual).max() <= 1e-12 * max(1.0, scale, np.abs(bias).max())


def test_the_hopper_on_the_compact_kernel(tmp_path):
    """A URDF floating joint with an origin of its own, a prismatic joint: as Pinocchio; a
    batch equals its states one by one; inertials set at run time pick the compact kernel."""
    pin = pytest.importorskip("pinocchio")
    path = tmp_path / "hopper.urdf"
    path.write_text(FLOATING_URDF)
    model = pin.buildModelFromXML(FLOATING_URDF)
    system = lagrangian.load(path)
    ours = system.dynamics(kernel="compact")
    _compare_dynamics(model, ours, states=6)
    rng = np.random.default_rng(4)
    q = rng.uniform(-1, 1, (5, ours.nq))
    q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=-1, keepdims=True)
    v, a = rng.uniform(-1, 1, (2, 5, ours.nv))
    for function, arguments in ((ours.mass_matrix, (q,)), (ours.bias_forces, (q, v)),
                                (ours.inverse_dynamics, (q, v, a)),
                                (ours.forward_dynamics, (q, v, a)),
                                (ours.kinetic_energy, (q, v)), (ours.potential_energy, (q,))):
        batch = function(*arguments)
        for k in range(5):
            np.testing.assert_array_equal(batch[k], function(*(x[k] for x in arguments)))
    # a heavier thigh at run time: the compact kernel, and Pinocchio with the same mass
    heavier = system.dynamics(parameters={"thigh.mass": 1.6})
    assert heavier.kernel == "compact"
    body = model.getJointId("hip")
    inertia = model.inertias[body]
    model.inertias[body] = pin.Inertia(inertia.mass + 0.8, inertia.lever, inertia.inertia)
    _compare_dynamics(model, heavier, states=3)


def test_a_quaternion_of_the_wrong_norm_is_one_line(tmp_path):
    """|quaternion| = 2 in the second state: refused naming q, the norm and the state; a norm
    within rounding of 1 is used normalized."""
    path = tmp_path / "hopper.urdf"
    path.write_text(FLOATING_URDF)
    ours = lagrangian.load(path).dynamics(kernel="compact")
    q = np.zeros((2, ours.nq))
    q[:, 6] = 1.0
    q[1, 3:7] = [0.0, 0.0, 0.0, 2.0]
    with pytest.raises(lagrangian.InputError, match="norm 2 in state 1") as info:
        ours.forward_dynamics(q, np.zeros((2, ours.nv)), np.zeros((2, ours.nv)))
    assert info.value.field == "q" and "\n" not in str(info.value)
    near = q[0].copy()
    near[6] = 1.0 + 1e-9
    np.testing.assert_allclose(ours.gravity(near), ours.gravity(q[0]), rtol=0, atol=1e-12)
    with pytest.raises(lagrangian.InputError, match="norm 2"):  # one q against five v
        ours.bias_forces(q[1], np.zeros((5, ours.nv)))
    with pytest.warns(lagrangian.DynamicsWarning):  # a state not finite: a NaN row, not judged
        out = ours.forward_dynamics(np.stack([q[0], np.r_[q[0, :6], np.nan, q[0, 7:]]]),
                                    np.zeros(ours.nv), np.zeros(ours.nv))
    assert np.isfinite(out[0]).all() and np.isnan(out[1]).all()
    with pytest.raises(lagrangian.InputError, match="10 values") as info:
        ours.gravity(np.zeros(9))
    assert info.value.field == "q"
