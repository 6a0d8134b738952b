"""Against Pinocchio (skipped where it is not installed): M, bias, gravity, inverse and forward
dynamics and energies of URDF arms at random states."""

from __future__ import annotations

import numpy as np
import pytest

import lagrangian
from robot_data import robots as _robots

pin = pytest.importorskip("pinocchio")
pytest.importorskip("yourdfpy")

# Revolute and prismatic joints (continuous joints are (cos, sin) pairs in Pinocchio), offsets
# in every axis, rpy origins, a tilted axis, full inertia tensors, an inertial rpy, a fixed
# joint with its own link mass (merged into the parent by both).
ARM = """<?xml version="1.0"?>
<robot name="spatial">
  <link name="base"/>
  <link name="a"><inertial><origin xyz="0.05 0.02 0.3" rpy="0.1 -0.2 0.3"/><mass value="1.2"/>
    <inertia ixx="0.02" ixy="0.001" ixz="-0.002" iyy="0.03" iyz="0.0015" izz="0.025"/></inertial></link>
  <link name="b"><inertial><origin xyz="0.25 -0.01 0.02" rpy="0 0.4 0"/><mass value="0.8"/>
    <inertia ixx="0.004" ixy="0.0005" ixz="0" iyy="0.02" iyz="-0.0007" izz="0.021"/></inertial></link>
  <link name="c"><inertial><origin xyz="0.1 0 0.03"/><mass value="0.5"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.0025"/></inertial></link>
  <link name="tool"><inertial><origin xyz="0 0 0.05"/><mass value="0.2"/>
    <inertia ixx="0.0002" ixy="0" ixz="0" iyy="0.0002" iyz="0" izz="0.0001"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/>
    <origin xyz="0 0 0.2" rpy="0 0 0.5"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/>
    <origin xyz="0.03 0.04 0.5" rpy="1.5707963267948966 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j3" type="prismatic"><parent link="b"/><child link="c"/>
    <origin xyz="0.4 0 -0.05" rpy="0.2 0.1 -0.3"/><axis xyz="0.6 0 0.8"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="flange" type="fixed"><parent link="c"/><child link="tool"/>
    <origin xyz="0.1 0.02 0" rpy="0 0.3 0"/></joint>
</robot>
"""


def _dynamics(system, backend):
    if backend == "symbolic":  # the derived equations, lambdified
        from lagrangian.compile.functions import numeric
        from lagrangian.dynamics.joint_space import Dynamics

        return Dynamics(numeric(system.equations_of_motion(), backend="numpy"))
    if backend in ("unrolled", "compact"):  # the C kernel: the tree's own, or for every tree
        return system.dynamics(kernel=backend)
    return system.dynamics(backend=backend)


@pytest.mark.slow
# derived equations; recursive numpy; recursive C (numpy without a compiler)
@pytest.mark.parametrize("backend", ["symbolic", "numpy", "unrolled", "compact"])
def test_spatial_arm_matches_pinocchio(tmp_path, backend):
    path = tmp_path / "spatial.urdf"
    path.write_text(ARM)
    f = _dynamics(lagrangian.load(path), backend)
    model = pin.buildModelFromXML(ARM)
    data = model.createData()
    assert model.nq == f.n == 3
    rng = np.random.default_rng(7)
    q, v, a, tau = (rng.uniform(-1, 1, (8, 3)) for _ in range(4))
    mass, bias, gravity = f.mass_matrix(q), f.bias_forces(q, v), f.gravity(q)
    inverse, forward = f.inverse_dynamics(q, v, a), f.forward_dynamics(q, v, tau)
    kinetic, potential = f.kinetic_energy(q, v), f.potential_energy(q)
    for k in range(len(q)):
        m = pin.crba(model, data, q[k]).copy()
        m = np.triu(m) + np.triu(m, 1).T
        np.testing.assert_allclose(mass[k], m, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(bias[k], pin.rnea(model, data, q[k], v[k], np.zeros(3)),
                                   rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(gravity[k], pin.computeGeneralizedGravity(model, data, q[k]),
                                   rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(inverse[k], pin.rnea(model, data, q[k], v[k], a[k]),
                                   rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(forward[k], pin.aba(model, data, q[k], v[k], tau[k]),
                                   rtol=1e-9, atol=1e-12)
        assert kinetic[k] == pytest.approx(pin.computeKineticEnergy(model, data, q[k], v[k]),
                                           rel=1e-9)
        assert potential[k] == pytest.approx(pin.computePotentialEnergy(model, data, q[k]),
                                             rel=1e-9, abs=1e-12)




@pytest.mark.slow
def test_panda_numpy_fallback_matches_pinocchio(monkeypatch, tmp_path):
    """The Panda (fingers locked, 7-DOF) where no compiler works: the recursions in numpy (the
    expanded equations are too deep for lambdify), against Pinocchio's reduced model."""
    from lagrangian.compile import compiled

    monkeypatch.setenv("CC", "/nonexistent/cc")
    monkeypatch.setenv("LAGRANGIAN_CACHE", str(tmp_path))
    monkeypatch.setattr(compiled, "_LOADED", {})
    path = _robots() / "panda_description/urdf/panda.urdf"
    lock = {"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0}
    f = lagrangian.load(path, lock=lock).dynamics()
    assert f.kernel == "numpy"
    model = pin.buildModelFromUrdf(str(path))
    model = pin.buildReducedModel(model, [model.getJointId(j) for j in lock], pin.neutral(model))
    data = model.createData()
    assert model.nq == f.n == 7
    rng = np.random.default_rng(0)
    q = rng.uniform(np.maximum(model.lowerPositionLimit, -3),
                    np.minimum(model.upperPositionLimit, 3), (8, 7))
    v, a, tau = (rng.uniform(-2, 2, (8, 7)) for _ in range(3))
    mass, bias, gravity = f.mass_matrix(q), f.bias_forces(q, v), f.gravity(q)
    inverse, forward = f.inverse_dynamics(q, v, a), f.forward_dynamics(q, v, tau)
    kinetic, potential = f.kinetic_energy(q, v), f.potential_energy(q)

    def close(ours, theirs):
        np.testing.assert_allclose(ours, theirs, rtol=1e-9, atol=1e-9 * np.abs(theirs).max())

    for k in range(len(q)):
        m = pin.crba(model, data, q[k]).copy()
        close(mass[k], np.triu(m) + np.triu(m, 1).T)
        close(bias[k], pin.rnea(model, data, q[k], v[k], np.zeros(7)))
        close(gravity[k], pin.computeGeneralizedGravity(model, data, q[k]))
        close(inverse[k], pin.rnea(model, data, q[k], v[k], a[k]))
        close(forward[k], pin.aba(model, data, q[k], v[k], tau[k]))
        assert kinetic[k] == pytest.approx(pin.computeKineticEnergy(model, data, q[k], v[k]),
                                           rel=1e-9)
        assert potential[k] == pytest.approx(pin.computePotentialEnergy(model, data, q[k]),
                                             rel=1e-9, abs=1e-9)


@pytest.mark.parametrize("backend", ["symbolic", "numpy", "unrolled", "compact"])
def test_tilted_gravity_matches_pinocchios_model_gravity(tmp_path, backend):
    """A wall-mounted or sloped arm: load(path, gravity=...) against Pinocchio's model.gravity."""
    path = tmp_path / "spatial.urdf"
    path.write_text(ARM)
    g = np.array([2.5, -4.0, -8.2])
    f = _dynamics(lagrangian.load(path, gravity=tuple(g)), backend)
    model = pin.buildModelFromXML(ARM)
    model.gravity.linear = g
    data = model.createData()
    rng = np.random.default_rng(11)
    q, v, tau = (rng.uniform(-1, 1, (6, 3)) for _ in range(3))
    gravity, bias, forward = f.gravity(q), f.bias_forces(q, v), f.forward_dynamics(q, v, tau)
    potential = f.potential_energy(q)
    for k in range(len(q)):
        np.testing.assert_allclose(gravity[k], pin.computeGeneralizedGravity(model, data, q[k]),
                                   rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(bias[k], pin.rnea(model, data, q[k], v[k], np.zeros(3)),
                                   rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(forward[k], pin.aba(model, data, q[k], v[k], tau[k]),
                                   rtol=1e-9, atol=1e-12)
        assert potential[k] == pytest.approx(pin.computePotentialEnergy(model, data, q[k]),
                                             rel=1e-9, abs=1e-12)
