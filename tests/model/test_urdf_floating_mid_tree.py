"""A URDF floating joint between two links: a free flyer inside the tree, as Pinocchio's
buildModelFromUrdf reads it (JointModelFreeFlyer: q = x y z in the parent's joint frame, then
qx qy qz qw; v = the child's linear then angular velocity relative to its parent, in its own
axes). The oracle is Pinocchio at random states, compared by joint name, and the numpy
reference; the compiled engine runs it (joint.h's kind 5), and so do kernel="unrolled" and
the C export (tests/dynamics/test_joint_kinds_export.py)."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

import lagrangian

pin = pytest.importorskip("pinocchio")
pytest.importorskip("yourdfpy")

INERTIA = 'ixx="{0}" ixy="0.0002" ixz="-0.0003" iyy="{1}" iyz="0.0001" izz="{2}"'


def _link(name, mass, xyz="0 0 0", rpy="0 0 0", moments=(0.004, 0.005, 0.006)):
    return (f'<link name="{name}"><inertial><origin xyz="{xyz}" rpy="{rpy}"/>'
            f'<mass value="{mass}"/><inertia {INERTIA.format(*moments)}/></inertial></link>')


def _joint(name, kind, parent, child, xyz="0 0 0", rpy="0 0 0", axis=None, extra=""):
    axis = f'<axis xyz="{axis}"/><limit lower="-3" upper="3" effort="9" velocity="9"/>' \
        if axis else ""
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}" rpy="{rpy}"/>{axis}{extra}</joint>')


# an arm carrying a free box (turned origin, off-centre inertial), a lid hinged on the box and a
# fixed tip on the lid: the free flyer has a moving parent and a moving child
ARM = ("<robot name='carrier'><link name='world'/>"
       + _link("upper", 2.0, "0.1 0.02 0.3", "0.1 0.2 0.3", (0.05, 0.04, 0.03))
       + _link("fore", 1.2, "0.2 0 0.05", moments=(0.02, 0.03, 0.01))
       + _link("box", 0.8, "0.03 -0.02 0.04", "0.3 -0.2 0.5")
       + _link("lid", 0.3, "0 0.05 0.01", moments=(0.001, 0.002, 0.0015)) + "<link name='tip'/>"
       + _joint("shoulder", "revolute", "world", "upper", "0 0 0.1", axis="0 0 1")
       + _joint("elbow", "revolute", "upper", "fore", "0.1 0 0.4", "0.2 0.1 -0.3", "0 1 0")
       + _joint("grip", "floating", "fore", "box", "0.35 0.05 0", "-0.4 0.3 0.2")
       + _joint("lid", "revolute", "box", "lid", "0.02 0.03 0.06", "0 0.5 0", "1 0 0")
       + _joint("tip_joint", "fixed", "lid", "tip", "0.1 0.2 0.3", "0.1 0.2 0.3")
       + "</robot>")
# two bodies linked by a floating joint, the pod's parent link welded to the hull: the free
# flyer's parent is the ground on a fixed hull, the base on a floating one
POD = ("<robot name='pod'>" + _link("hull", 5.0, "0.1 0 0", moments=(0.3, 0.4, 0.5))
       + "<link name='mount'/>" + _link("pod", 0.7, "0.02 0.01 -0.03", "0.2 0.1 0")
       + _link("fin", 0.4, "0.1 0 0", moments=(0.002, 0.003, 0.004))
       + _joint("mount_joint", "fixed", "hull", "mount", "0.3 -0.1 0.2", "0.5 0 0.4")
       + _joint("pod_joint", "floating", "mount", "pod", "0.05 0 0", "0 -0.3 0.1")
       + _joint("fin_joint", "revolute", "hull", "fin", "-0.2 0 0.1", axis="0 1 0")
       + "</robot>")


@pytest.fixture(scope="module")
def robots(tmp_path_factory):
    """(ours, Pinocchio's model, path) for the arm and the pod on a fixed and a floating hull."""
    folder = tmp_path_factory.mktemp("free")
    out = {}
    for key, text, floating in (("arm", ARM, False), ("pod", POD, False),
                                ("pod floating", POD, True)):
        path = folder / f"{key.split()[0]}.urdf"
        path.write_text(text)
        ours = lagrangian.load(path, floating_base=floating).dynamics()
        theirs = (pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer()) if floating
                  else pin.buildModelFromUrdf(str(path)))
        out[key] = ours, theirs, path
    return out


def _orders(ours, model):
    """Our q and v index of each of Pinocchio's numbers (matched by joint name)."""
    iq, iv = [], []
    names_q, names_v = list(ours.coordinates), list(ours.velocity_names)
    for k in range(1, model.njoints):
        joint, name = model.joints[k], model.names[k]
        stem = "base" if name == "root_joint" else name
        if joint.nq == 7:
            iq += [names_q.index(f"{stem}_{s}") for s in ("x", "y", "z", "qx", "qy", "qz", "qw")]
            iv += [names_v.index(f"{stem}_{s}") for s in ("vx", "vy", "vz", "wx", "wy", "wz")]
        else:
            iq.append(names_q.index(name))
            iv.append(names_v.index(name))
    return np.array(iq), np.array(iv)


def _states(model, count=3, seed=0):
    rng = np.random.default_rng(seed)
    q = rng.uniform(-1, 1, (count, model.nq))
    for k in range(1, model.njoints):
        if model.joints[k].nq == 7:
            start = model.joints[k].idx_q + 3
            q[:, start:start + 4] /= np.linalg.norm(q[:, start:start + 4], axis=-1, keepdims=True)
    return q, rng.uniform(-1, 1, (count, model.nv)), rng.uniform(-1, 1, (count, model.nv))


@pytest.mark.parametrize("key", ["arm", "pod", "pod floating"])
def test_dynamics_and_frames_match_pinocchio(robots, key):
    """M, the nonlinear effects, ABA, RNEA, g, T, V and every frame's placement and Jacobian."""
    ours, model, _ = robots[key]
    data = model.createData()
    iq, iv = _orders(ours, model)
    Q, V, A = _states(model)
    q, v, a = np.empty_like(Q), np.empty_like(V), np.empty_like(A)
    q[:, iq], v[:, iv], a[:, iv] = Q, V, A
    M, bias = ours.mass_matrix(q), ours.bias_forces(q, v)
    forward, inverse = ours.forward_dynamics(q, v, a), ours.inverse_dynamics(q, v, a)
    T, U = ours.kinetic_energy(q, v), ours.potential_energy(q)
    frames = [f.name for f in model.frames if f.name != "universe"]
    for k in range(len(Q)):
        theirs = pin.crba(model, data, Q[k])
        theirs = np.triu(theirs) + np.triu(theirs, 1).T
        np.testing.assert_allclose(M[k][np.ix_(iv, iv)], theirs, atol=1e-9)
        np.testing.assert_allclose(bias[k][iv], pin.nonLinearEffects(model, data, Q[k], V[k]),
                                   atol=1e-9)
        np.testing.assert_allclose(forward[k][iv], pin.aba(model, data, Q[k], V[k], A[k]),
                                   atol=1e-9)
        np.testing.assert_allclose(inverse[k][iv], pin.rnea(model, data, Q[k], V[k], A[k]),
                                   atol=1e-9)
        assert T[k] == pytest.approx(pin.computeKineticEnergy(model, data, Q[k], V[k]), abs=1e-9)
        assert U[k] == pytest.approx(pin.computePotentialEnergy(model, data, Q[k]), abs=1e-9)
        pin.computeJointJacobians(model, data, Q[k])
        pin.framesForwardKinematics(model, data, Q[k])
        for name in frames:
            fid = model.getFrameId(name, model.frames[[f.name for f in model.frames].index(name)]
                                   .type)
            np.testing.assert_allclose(ours.placement(q[k], name),
                                       data.oMf[fid].homogeneous, atol=1e-9)
            J = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
            np.testing.assert_allclose(ours.jacobian(q[k], name)[:, iv], J, atol=1e-9)


def test_velocity_terms_and_the_manifold_match_pinocchio(robots):
    """C(q, v), J_dot v, A_g, the centre of mass and a wrench at a frame; q (+) v dt and its
    inverse on the manifold."""
    ours, model, _ = robots["arm"]
    data = model.createData()
    iq, iv = _orders(ours, model)
    Q, V, _ = _states(model, 1, seed=3)
    q, v = np.empty_like(Q[0]), np.empty_like(V[0])
    q[iq], v[iv] = Q[0], V[0]
    C = pin.computeCoriolisMatrix(model, data, Q[0], V[0])
    np.testing.assert_allclose(ours.coriolis_matrix(q, v)[np.ix_(iv, iv)], C, atol=1e-9)
    np.testing.assert_allclose(ours.centroidal_momentum_matrix(q)[:, iv],
                               pin.ccrba(model, data, Q[0], V[0]), atol=1e-9)
    np.testing.assert_allclose(ours.center_of_mass(q), pin.centerOfMass(model, data, Q[0]),
                               atol=1e-9)
    pin.forwardKinematics(model, data, Q[0], V[0], np.zeros(model.nv))
    pin.updateFramePlacements(model, data)
    drift = pin.getFrameClassicalAcceleration(model, data, model.getFrameId("tip"),
                                              pin.LOCAL_WORLD_ALIGNED)
    np.testing.assert_allclose(ours.jacobian_dot_times_v(q, v, "tip"), drift.vector, atol=1e-9)
    # a wrench on the box (world axes, at its frame's origin: the joint's), Pinocchio's per joint
    wrench = np.array([0.3, -0.2, 0.5, 0.1, 0.4, -0.3])
    R = data.oMi[model.getJointId("grip")].rotation
    f_ext = [pin.Force.Zero() for _ in range(model.njoints)]
    f_ext[model.getJointId("grip")] = pin.Force(R.T @ wrench[:3], R.T @ wrench[3:])
    np.testing.assert_allclose(ours.inverse_dynamics(q, v, v, f_ext={"box": wrench})[iv],
                               pin.rnea(model, data, Q[0], V[0], V[0], f_ext), atol=1e-9)
    moved = pin.integrate(model, Q[0], 0.3 * V[0])
    np.testing.assert_allclose(ours.integrate(q, v, 0.3)[iq], moved, atol=1e-12)
    np.testing.assert_allclose(ours.difference(q, ours.integrate(q, v, 0.3)), 0.3 * v,
                               atol=1e-12)


@pytest.mark.parametrize("key", ["arm", "pod floating"])
def test_the_derivatives_match_pinocchio(robots, key):
    """d tau/dq, d tau/dv (computeRNEADerivatives) and d a/dq, d a/dv, M^-1
    (computeABADerivatives), the free flyer's d/dq along its own tangent, q (x) exp(dq): the
    engine's analytic ones over the flyer's six columns; and the regressor Y
    (computeJointTorqueRegressor)."""
    ours, model, _ = robots[key]
    assert ours._derivatives_kernel() is not None  # the engine's, not the complex step
    data = model.createData()
    iq, iv = _orders(ours, model)
    Q, V, A = _states(model, 2, seed=5)
    q, v, a = np.empty_like(Q), np.empty_like(V), np.empty_like(A)
    q[:, iq], v[:, iv], a[:, iv] = Q, V, A
    inverse, forward = ours.inverse_dynamics_derivatives(q, v, a), \
        ours.forward_dynamics_derivatives(q, v, a)
    for k in range(len(Q)):
        theirs = pin.computeRNEADerivatives(model, data, Q[k], V[k], A[k])
        for ours_, theirs_ in zip(inverse, theirs[:2], strict=True):
            np.testing.assert_allclose(ours_[k][np.ix_(iv, iv)], theirs_, atol=1e-9)
        theirs = pin.computeABADerivatives(model, data, Q[k], V[k], A[k])
        for ours_, theirs_ in zip(forward, theirs, strict=True):
            np.testing.assert_allclose(ours_[k][np.ix_(iv, iv)], theirs_, atol=1e-9)
        # the regressor: tau = Y pi, Pinocchio's parameters of each body in its own frame,
        # its bodies' blocks matched to ours by joint name
        bodies = [name.split("@")[1] for name in ours.parameter_names()[::10]]
        blocks = np.concatenate([np.arange(10) + 10 * bodies.index(name)
                                 for name in list(model.names)[1:]])
        Y = pin.computeJointTorqueRegressor(model, data, Q[k], V[k], A[k])
        np.testing.assert_allclose(ours.regressor(q[k], v[k], a[k])[np.ix_(iv, blocks)], Y,
                                   atol=1e-9)


def test_the_layout_names_and_the_symbolic_bodies(robots):
    """The free flyer's numbers are named after its joint; the model's own coordinates are its
    x, y, z and rpy (the symbolic bodies, in the URDF's R = Rz(yaw) Ry(pitch) Rx(roll)), and the
    box's symbolic placement is the tree's at the quaternion of those angles."""
    ours, _, path = robots["arm"]
    assert ours.coordinates[2:9] == ("grip_x", "grip_y", "grip_z", "grip_qx", "grip_qy",
                                     "grip_qz", "grip_qw")
    assert ours.velocity_names[2:8] == ("grip_vx", "grip_vy", "grip_vz", "grip_wx", "grip_wy",
                                        "grip_wz")
    assert (ours.nq, ours.nv, ours.backend) == (10, 9, "recursive")
    model = ours.model
    assert [c.name for c in model.coordinates][2:8] == ["grip_x", "grip_y", "grip_z",
                                                        "grip_roll", "grip_pitch", "grip_yaw"]
    box = next(b for b in model.rigid_bodies if b.name == "box")
    angles = dict(shoulder=0.4, elbow=-0.7, grip_x=0.1, grip_y=-0.2, grip_z=0.3,
                  grip_roll=0.5, grip_pitch=-0.6, grip_yaw=0.9, lid=0.2)
    values = {s: angles[s.name] for s in model.q}
    R = np.array([[float(x.xreplace(values)) for x in row] for row in box.rotation])
    origin = np.array([float(x.xreplace(values)) for x in box.origin])
    r, p, y = 0.5, -0.6, 0.9  # the quaternion (x y z w) of Rz(y) Ry(p) Rx(r)
    quaternion = [np.sin(r / 2) * np.cos(p / 2) * np.cos(y / 2)
                  - np.cos(r / 2) * np.sin(p / 2) * np.sin(y / 2),
                  np.cos(r / 2) * np.sin(p / 2) * np.cos(y / 2)
                  + np.sin(r / 2) * np.cos(p / 2) * np.sin(y / 2),
                  np.cos(r / 2) * np.cos(p / 2) * np.sin(y / 2)
                  - np.sin(r / 2) * np.sin(p / 2) * np.cos(y / 2),
                  np.cos(r / 2) * np.cos(p / 2) * np.cos(y / 2)
                  + np.sin(r / 2) * np.sin(p / 2) * np.sin(y / 2)]
    q = np.array([0.4, -0.7, 0.1, -0.2, 0.3, *quaternion, 0.2])
    placement = ours.placement(q, "box")
    np.testing.assert_allclose(R, placement[:3, :3], atol=1e-12)
    np.testing.assert_allclose(origin, placement[:3, 3], atol=1e-12)


@pytest.mark.parametrize("key", ["arm", "pod floating"])
def test_the_engine_agrees_with_the_numpy_reference(robots, key, capsys):
    """The compiled engine is chosen with no notice, and its M, ID, FD, T, V, frames,
    Jacobians and centre of mass equal the numpy reference's to 1e-9, batched and per state."""
    ours, model, path = robots[key]
    reference = lagrangian.load(path, floating_base=key != "arm").dynamics(backend="numpy")
    assert ours.backend == "recursive" and reference.backend == "recursive-numpy"
    assert "floating joint" not in capsys.readouterr().err
    iq, iv = _orders(ours, model)
    Q, V, A = _states(model, 6, seed=7)
    q, v, a = np.empty_like(Q), np.empty_like(V), np.empty_like(A)
    q[:, iq], v[:, iv], a[:, iv] = Q, V, A
    calls = {"M": lambda d, *x: d.mass_matrix(x[0]),
             "ID": lambda d, *x: d.inverse_dynamics(*x),
             "FD": lambda d, *x: d.forward_dynamics(*x),
             "T": lambda d, *x: d.kinetic_energy(x[0], x[1]),
             "V": lambda d, *x: d.potential_energy(x[0]),
             "com": lambda d, *x: d.center_of_mass(x[0]),
             "J_com": lambda d, *x: d.center_of_mass_jacobian(x[0])}
    for frame in ours.frames:
        calls[frame] = lambda d, *x, f=frame: d.placement(x[0], f)
        calls["J " + frame] = lambda d, *x, f=frame: d.jacobian(x[0], f)
        calls["J local " + frame] = lambda d, *x, f=frame: d.jacobian(x[0], f, "local")
    for name, call in calls.items():
        expected = call(reference, q, v, a)
        scale = max(1.0, float(np.abs(expected).max()))
        np.testing.assert_allclose(call(ours, q, v, a), expected, atol=1e-9 * scale,
                                   err_msg=name)
        np.testing.assert_allclose(call(ours, q[2], v[2], a[2]), expected[2],
                                   atol=1e-9 * scale, err_msg=name)


@pytest.mark.parametrize("key", ["arm", "pod floating"])
def test_the_casadi_functions_match_pinocchio(robots, key):
    """to_casadi's M and rhs (the numpy reference's recursions over casadi SX): M = crba,
    the accelerations = aba under an input torque and a moment on the box, q_dot = d/dt of
    Pinocchio's integrate(q, v t) at t = 0; and casadi's Jacobian of rhs = a central difference
    of our forward dynamics in every number of q (the quaternions' too) and v."""
    casadi = pytest.importorskip("casadi")
    ours, model, path = robots[key]
    data = model.createData()
    system = lagrangian.load(path, floating_base=key != "arm")
    moved, free = ("lid", "grip") if key == "arm" else ("fin_joint", "pod_joint")
    functions = system.to_casadi(inputs=[moved, f"tau_{moved}", f"{free}_wy"])
    iq, iv = _orders(ours, model)
    Q, V, _ = _states(model, 2, seed=11)
    q, v = np.empty_like(Q), np.empty_like(V)
    q[:, iq], v[:, iv] = Q, V
    nq, nv = model.nq, model.nv
    u = np.array([0.4, -0.3, 0.7])
    tau = np.zeros(nv)
    tau[list(ours.velocity_names).index(moved)] += u[0] + u[1]
    tau[list(ours.velocity_names).index(functions.inputs[2])] += u[2]
    h = 1e-6
    for k in range(len(Q)):
        M = np.asarray(functions.mass_matrix(q[k]))
        theirs = pin.crba(model, data, Q[k])
        np.testing.assert_allclose(M[np.ix_(iv, iv)], np.triu(theirs) + np.triu(theirs, 1).T,
                                   atol=1e-9)
        x_dot = np.asarray(functions.rhs(np.r_[q[k], v[k]], u)).ravel()
        np.testing.assert_allclose(x_dot[nq:][iv], pin.aba(model, data, Q[k], V[k], tau[iv]),
                                   atol=1e-9)
        rate = (pin.integrate(model, Q[k], h * V[k]) - pin.integrate(model, Q[k], -h * V[k]))
        np.testing.assert_allclose(x_dot[:nq][iq], rate / (2 * h), atol=1e-8)
    x = casadi.SX.sym("x", nq + nv)
    jacobian = casadi.Function("J", [x], [casadi.jacobian(functions.rhs(x, u), x)])
    J = np.asarray(jacobian(np.r_[q[0], v[0]]))[nq:]
    step = 1e-5
    starts = [model.joints[j].idx_q + 3 for j in range(1, model.njoints)
              if model.joints[j].nq == 7]

    def forward(y):  # off the unit sphere the rotation is that of q / |q| (ours near it)
        Q = y[:nq][iq]
        for k in starts:
            Q[k:k + 4] /= np.linalg.norm(Q[k:k + 4])
        y[:nq][iq] = Q
        return ours.forward_dynamics(y[:nq], y[nq:], tau)

    for i in range(nq + nv):
        plus, minus = np.r_[q[0], v[0]], np.r_[q[0], v[0]]
        plus[i] += step
        minus[i] -= step
        column = (forward(plus) - forward(minus)) / (2 * step)
        np.testing.assert_allclose(J[:, i], column, rtol=0,
                                   atol=1e-5 * max(1.0, np.abs(column).max()), err_msg=f"x[{i}]")


def test_bad_input_is_named_in_one_line(robots, tmp_path):
    ours, _, _ = robots["arm"]
    q = np.r_[np.zeros(8), 1.0, 0.0]
    bad = np.r_[q[:8], 0.5, 0.0]
    for call in (lambda: ours.mass_matrix(bad), lambda: ours.placement(bad, "tip"),
                 lambda: ours.integrate(bad, np.zeros(9), 0.1)):
        with pytest.raises(lagrangian.InputError, match=re.escape(
                "the floating joint 'grip' quaternion (q[5:9], x y z w) has norm 0.5")) as info:
            call()
        assert info.value.field == "q"
    ours.mass_matrix(np.r_[q[:8], 1 + 1e-7, 0.0])  # within the tolerance: used normalized
    limited = tmp_path / "limited.urdf"
    limited.write_text(ARM.replace('<origin xyz="0.35 0.05 0" rpy="-0.4 0.3 0.2"/>',
                                   '<origin xyz="0.35 0.05 0" rpy="-0.4 0.3 0.2"/><limit '
                                   'lower="-1" upper="1" effort="1" velocity="1"/>'))
    with pytest.raises(lagrangian.ModelError, match=r"joint 'grip'.limit: a floating joint has "
                       "no limits") as info:
        lagrangian.load(limited)
    assert "\n" not in str(info.value)
    mimic = tmp_path / "mimic.urdf"
    mimic.write_text(ARM.replace('<origin xyz="0.35 0.05 0" rpy="-0.4 0.3 0.2"/>',
                                 '<origin xyz="0.35 0.05 0" rpy="-0.4 0.3 0.2"/>'
                                 '<mimic joint="elbow"/>'))
    with pytest.raises(lagrangian.ModelError, match=r"joint 'grip'.mimic: a floating joint "
                       "cannot mimic"):
        lagrangian.load(mimic)


def test_the_command_prints_the_layout(robots, cli):
    """lagrangian dynamics: the free flyer's numbers named, its quaternion unturned by default,
    the bias there Pinocchio's; a quaternion off unit norm refused in one line."""
    ours, model, path = robots["arm"]
    result = cli("dynamics", str(path), "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert (document["nq"], document["nv"]) == (10, 9)
    assert document["coordinates"] == list(ours.coordinates)
    assert document["velocities"] == list(ours.velocity_names)
    assert document["q"] == [0, 0, 0, 0, 0, 0, 0, 0, 1, 0]
    iq, iv = _orders(ours, model)
    theirs = pin.nonLinearEffects(model, model.createData(), np.array(document["q"])[iq],
                                  np.zeros(9))
    np.testing.assert_allclose(np.array(document["bias_forces"])[iv], theirs, atol=1e-9)
    bad = cli("dynamics", str(path), "--q", "0,0,0,0,0,0,0,0.5,0,0")
    assert bad.code == 2 and bad.err.splitlines()[-1].startswith(
        "error: --q: the floating joint 'grip' quaternion (q[5:9], x y z w) has norm 0.5")
