"""URDF arms: closed forms, the same arm as a 3D rigid-body model file, mimic, lock, bad input."""

from __future__ import annotations

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import LagrangianError, ModelError

pytest.importorskip("yourdfpy")

INERTIAL = ('<inertial><origin xyz="{x} {y} {z}" rpy="{rpy}"/><mass value="{m}"/>'
            '<inertia ixx="{ixx}" ixy="{ixy}" ixz="{ixz}" iyy="{iyy}" iyz="{iyz}" izz="{izz}"/>'
            '</inertial>')


def link(name, m=None, xyz=(0, 0, 0), rpy="0 0 0", inertia=(0.1, 0, 0, 0.1, 0, 0.1)):
    if m is None:
        return f'<link name="{name}"/>'
    ixx, ixy, ixz, iyy, iyz, izz = inertia
    body = INERTIAL.format(x=xyz[0], y=xyz[1], z=xyz[2], rpy=rpy, m=m, ixx=ixx, ixy=ixy,
                           ixz=ixz, iyy=iyy, iyz=iyz, izz=izz)
    return f'<link name="{name}">{body}<visual><geometry><mesh filename="package://none/x.stl"/>' \
           '</geometry></visual></link>'


def joint(name, parent, child, kind="revolute", xyz="0 0 0", rpy="0 0 0", axis="0 0 1",
          extra=""):
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/>'
            f'<limit lower="-3" upper="3" effort="10" velocity="5"/>{extra}</joint>')


def robot(*parts):
    return '<?xml version="1.0"?>\n<robot name="arm">' + "".join(parts) + "</robot>"


def write(tmp_path, text, name="arm.urdf"):
    path = tmp_path / name
    path.write_text(text)
    return path


# Two links in the vertical x-z plane, joints about -y (positive angle lifts the arm).
M1, M2, L1, C1, C2, I1, I2 = 2.0, 1.5, 1.0, 0.5, 0.4, 0.2, 0.1
TWO_LINK = robot(
    link("base"),
    link("upper", M1, (C1, 0, 0), inertia=(0.01, 0, 0, I1, 0, I1)),
    link("fore", M2, (C2, 0, 0), inertia=(0.01, 0, 0, I2, 0, I2)),
    joint("shoulder", "base", "upper", axis="0 -1 0"),
    joint("elbow", "upper", "fore", kind="continuous", xyz=f"{L1} 0 0", axis="0 -1 0"),
)


def two_link_closed_form(q, v):
    """Textbook planar two-link arm (Spong): M, C q_dot and g with angles from the horizontal."""
    q1, q2 = q
    c2 = np.cos(q2)
    m11 = M1 * C1**2 + I1 + M2 * (L1**2 + C2**2 + 2 * L1 * C2 * c2) + I2
    m12 = M2 * (C2**2 + L1 * C2 * c2) + I2
    m22 = M2 * C2**2 + I2
    h = -M2 * L1 * C2 * np.sin(q2)
    coriolis = np.array([h * (2 * v[0] * v[1] + v[1] ** 2), -h * v[0] ** 2])
    g = 9.81
    gravity = np.array([(M1 * C1 + M2 * L1) * g * np.cos(q1) + M2 * C2 * g * np.cos(q1 + q2),
                        M2 * C2 * g * np.cos(q1 + q2)])
    return np.array([[m11, m12], [m12, m22]]), coriolis + gravity, gravity


def test_two_link_arm_has_the_textbook_mass_matrix_bias_and_gravity(tmp_path):
    arm = lagrangian.load(write(tmp_path, TWO_LINK))
    assert [c.name for c in arm.model.coordinates] == ["shoulder", "elbow"]
    assert {"tau_shoulder", "tau_elbow", "g"} <= set(arm.parameters)
    f = arm.dynamics()
    rng = np.random.default_rng(1)
    q, v = rng.uniform(-2, 2, (20, 2)), rng.uniform(-3, 3, (20, 2))
    mass, bias, gravity = f.mass_matrix(q), f.bias_forces(q, v), f.gravity(q)
    assert mass.shape == (20, 2, 2) and bias.shape == (20, 2)
    for k in range(20):
        m, b, g = two_link_closed_form(q[k], v[k])
        np.testing.assert_allclose(mass[k], m, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(bias[k], b, rtol=1e-11, atol=1e-11)
        np.testing.assert_allclose(gravity[k], g, rtol=1e-11, atol=1e-11)
    # one state (n,) gives unbatched shapes
    assert f.mass_matrix(q[0]).shape == (2, 2)
    assert f.inverse_dynamics(q[0], v[0], v[1]).shape == (2,)


def test_inverse_and_forward_dynamics_undo_each_other_and_energy_is_kept(tmp_path):
    arm = lagrangian.load(write(tmp_path, TWO_LINK))
    f = arm.dynamics()
    rng = np.random.default_rng(2)
    q, v, a = (rng.uniform(-2, 2, (50, 2)) for _ in range(3))
    tau = f.inverse_dynamics(q, v, a)
    np.testing.assert_allclose(f.forward_dynamics(q, v, tau), a, rtol=1e-9, atol=1e-9)
    m = f.mass_matrix(q)
    np.testing.assert_allclose(f.kinetic_energy(q, v),
                               0.5 * np.einsum("ni,nij,nj->n", v, m, v), rtol=1e-10)
    height = C1 * np.sin(q[:, 0]) * M1 + M2 * (L1 * np.sin(q[:, 0]) + C2 * np.sin(q.sum(1)))
    np.testing.assert_allclose(f.potential_energy(q), 9.81 * height, rtol=1e-10, atol=1e-10)
    # zero torque: T + V is kept along a simulated motion
    run = arm.simulate(2.0, initial={"shoulder": 0.3, "elbow": -0.5, "elbow_dot": 1.0})
    energy = run.energy if hasattr(run, "energy") else None
    qs = np.column_stack([run.q[name] for name in ("shoulder", "elbow")]) \
        if isinstance(getattr(run, "q", None), dict) else None
    if energy is None or qs is None:
        frame = run.to_pandas()
        qs = frame[["shoulder", "elbow"]].to_numpy()
        vs = frame[["shoulder_dot", "elbow_dot"]].to_numpy()
        energy = f.kinetic_energy(qs, vs) + f.potential_energy(qs)
    assert np.ptp(energy) < 1e-6 * max(1.0, np.abs(energy).max())


# A 3-DOF spatial arm: offsets in all three axes, rpy origins, a tilted axis, full tensors,
# an inertial origin with its own rpy.
SPATIAL = robot(
    link("base", 3.0, (0.0, 0.0, 0.1)),
    link("a", 1.2, (0.05, 0.02, 0.3), rpy="0.1 -0.2 0.3",
         inertia=(0.02, 0.001, -0.002, 0.03, 0.0015, 0.025)),
    link("b", 0.8, (0.25, -0.01, 0.02), rpy="0 0.4 0",
         inertia=(0.004, 0.0005, 0.0, 0.02, -0.0007, 0.021)),
    link("c", 0.5, (0.1, 0.0, 0.03), inertia=(0.001, 0, 0, 0.002, 0, 0.0025)),
    joint("j1", "base", "a", xyz="0 0 0.2", rpy="0 0 0.5", axis="0 0 1"),
    joint("j2", "a", "b", xyz="0.03 0.04 0.5", rpy="1.5707963267948966 0 0", axis="0 0 1"),
    joint("j3", "b", "c", xyz="0.4 0.0 -0.05", rpy="0.2 0.1 -0.3", axis="0.6 0 0.8"),
)


def _rpy(r, p, y):
    cr, sr, cp, sp_, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    ry = np.array([[cp, 0, sp_], [0, 1, 0], [-sp_, 0, cp]])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    return rz @ ry @ rx


def _axis_angle(u, a):
    u = np.asarray(u, float) / np.linalg.norm(u)
    k = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    return np.eye(3) + np.sin(a) * k + (1 - np.cos(a)) * k @ k


def _newton_euler_free_energy(q, v):
    """T and V of SPATIAL by finite-difference body velocities of numpy frames (independent of
    the symbolic path): omega from R^T dR/dt, v_G from d r_G/dt, central differences."""
    def frames(q):
        out = []
        r, p = np.eye(3), np.zeros(3)
        specs = [((0, 0, 0.2), (0, 0, 0.5), (0, 0, 1)),
                 ((0.03, 0.04, 0.5), (np.pi / 2, 0, 0), (0, 0, 1)),
                 ((0.4, 0.0, -0.05), (0.2, 0.1, -0.3), (0.6, 0, 0.8))]
        for (xyz, rpy, axis), angle in zip(specs, q, strict=True):
            p = p + r @ np.array(xyz)
            r = r @ _rpy(*rpy) @ _axis_angle(axis, angle)
            out.append((r, p))
        return out

    bodies = [(1.2, (0.05, 0.02, 0.3), (0.1, -0.2, 0.3), (0.02, 0.001, -0.002, 0.03, 0.0015, 0.025)),
              (0.8, (0.25, -0.01, 0.02), (0, 0.4, 0), (0.004, 0.0005, 0.0, 0.02, -0.0007, 0.021)),
              (0.5, (0.1, 0.0, 0.03), (0, 0, 0), (0.001, 0, 0, 0.002, 0, 0.0025))]
    h = 1e-6
    now, ahead, behind = frames(q), frames(q + h * v), frames(q - h * v)
    kinetic = potential = 0.0
    for (m, c, rpy, i), (r, p), (ra, pa), (rb, pb) in zip(bodies, now, ahead, behind, strict=True):
        ixx, ixy, ixz, iyy, iyz, izz = i
        tensor = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        turn = _rpy(*rpy)
        tensor = turn @ tensor @ turn.T
        rdot = (ra - rb) / (2 * h)
        w = r.T @ rdot
        omega = np.array([w[2, 1], w[0, 2], w[1, 0]])
        vg = ((pa + ra @ c) - (pb + rb @ c)) / (2 * h)
        kinetic += 0.5 * m * vg @ vg + 0.5 * omega @ tensor @ omega
        potential += m * 9.81 * (p + r @ c)[2]
    return kinetic, potential


@pytest.fixture(scope="module")
def spatial(tmp_path_factory):
    # the derived equations, lambdified (numpy: the C build of these unsimplified, float-laden
    # expressions takes ~1 min; System.dynamics(backend="numpy") would run the recursions)
    from lagrangian.compile.functions import numeric
    from lagrangian.dynamics.joint_space import Dynamics

    path = write(tmp_path_factory.mktemp("spatial"), SPATIAL)
    return Dynamics(numeric(lagrangian.load(path).equations_of_motion(), backend="numpy"))


@pytest.mark.slow
def test_spatial_arm_energies_match_numpy_frames_and_mass_matrix_is_the_energy_hessian(spatial):
    f = spatial
    rng = np.random.default_rng(3)
    for _ in range(5):
        q, v = rng.uniform(-2, 2, 3), rng.uniform(-2, 2, 3)
        kinetic, potential = _newton_euler_free_energy(q, v)
        assert f.kinetic_energy(q, v) == pytest.approx(kinetic, rel=1e-8)
        # the base link is fixed to the ground: its constant weight term is left out
        assert f.potential_energy(q) == pytest.approx(potential, rel=1e-10, abs=1e-10)
        # M is the Hessian of T in v: M_ij = T(e_i + e_j) - T(e_i) - T(e_j), from the frames
        m = f.mass_matrix(q)
        unit = [_newton_euler_free_energy(q, e)[0] for e in np.eye(3)]
        for i in range(3):
            for j in range(3):
                both = _newton_euler_free_energy(q, np.eye(3)[i] + np.eye(3)[j])[0]
                expected = 2 * unit[i] if i == j else both - unit[i] - unit[j]
                assert m[i, j] == pytest.approx(expected, rel=1e-6, abs=1e-8)


@pytest.mark.slow
def test_spatial_arm_gravity_is_the_potential_gradient_and_dynamics_invert(spatial):
    f = spatial
    q = np.array([0.3, -0.7, 1.1])
    h = 1e-6
    gradient = [(f.potential_energy(q + h * e) - f.potential_energy(q - h * e)) / (2 * h)
                for e in np.eye(3)]
    np.testing.assert_allclose(f.gravity(q), gradient, rtol=1e-7, atol=1e-8)
    rng = np.random.default_rng(4)
    q, v, a = (rng.uniform(-2, 2, (10, 3)) for _ in range(3))
    np.testing.assert_allclose(f.forward_dynamics(q, v, f.inverse_dynamics(q, v, a)), a,
                               rtol=1e-8, atol=1e-8)


def test_mimic_and_lock(tmp_path):
    text = robot(
        link("base"), link("a", 1.0, (0.3, 0, 0)), link("b", 0.5, (0.2, 0, 0)),
        joint("j1", "base", "a", axis="0 -1 0"),
        joint("j2", "a", "b", xyz="0.6 0 0", axis="0 -1 0",
              extra='<mimic joint="j1" multiplier="2" offset="0.1"/>'),
    )
    arm = lagrangian.load(write(tmp_path, text))
    assert [c.name for c in arm.model.coordinates] == ["j1"]
    f = arm.dynamics()
    q = 0.4
    height = 1.0 * 0.3 * np.sin(q) + 0.5 * (0.6 * np.sin(q) + 0.2 * np.sin(q + 2 * q + 0.1))
    assert f.potential_energy([q]) == pytest.approx(9.81 * height, rel=1e-12)
    # locking the mimic joint (the Panda's second finger) freezes it at its own value
    frozen = lagrangian.load(write(tmp_path, text), lock={"j2": 0.25}).dynamics()
    height = 1.0 * 0.3 * np.sin(q) + 0.5 * (0.6 * np.sin(q) + 0.2 * np.sin(q + 0.25))
    assert frozen.potential_energy([q]) == pytest.approx(9.81 * height, rel=1e-12)
    locked = lagrangian.load(write(tmp_path, TWO_LINK), lock={"elbow": np.pi / 2})
    assert [c.name for c in locked.model.coordinates] == ["shoulder"]
    m = locked.dynamics().mass_matrix([0.2])
    assert m[0, 0] == pytest.approx(M1 * C1**2 + I1 + M2 * (L1**2 + C2**2) + I2, rel=1e-12)


@pytest.mark.parametrize(("text", "words"), [
    ("<robot name='x'><link name='a'", "not well-formed XML"),
    (robot(link("a"), link("b", 1.0), joint("j", "a", "b", kind="floating")),
     "no joint left to move: a model needs at least one revolute, continuous or prismatic "
     "joint that is not locked (a lone floating body: not yet)"),
    (robot(link("a"), link("b", 1.0), joint("j", "a", "b", kind="spherical")),
     "joint 'j': unknown joint type 'spherical' (use revolute, continuous, prismatic, planar, "
     "floating or fixed)"),
    (robot(link("a"), link("b", 1.0), link("c", 1.0), joint("j1", "a", "b"),
           joint("j2", "b", "c"), joint("j3", "a", "c")), "closed loop"),
    (robot(link("a"), link("b", 1.0), joint("j", "a", "zz")), "joint 'j': no link 'zz'"),
    (robot(link("a"), link("b", 1.0), joint("j", "a", "b", kind="fixed")), "no joint left"),
])
def test_bad_urdf_is_named(tmp_path, text, words):
    path = write(tmp_path, text)
    with pytest.raises(ModelError) as info:
        lagrangian.load(path)
    assert words in str(info.value)
    assert str(path) in str(info.value)


def test_unknown_lock_and_massless_tree(tmp_path):
    path = write(tmp_path, TWO_LINK)
    with pytest.raises(ModelError, match="no joint 'elbw'.*did you mean 'elbow'"):
        lagrangian.load(path, lock={"elbw": 0.0})
    massless = write(tmp_path, robot(link("base"), link("a"), link("b", 1.0, (0.5, 0, 0)),
                                     joint("j1", "base", "a", axis="0 -1 0"),
                                     joint("j2", "a", "b", axis="0 -1 0")), "massless.urdf")
    with pytest.raises(LagrangianError, match="singular.*j1, j2"):
        lagrangian.load(massless).dynamics().mass_matrix([0.1, 0.2])


def test_wrong_state_length_is_named(tmp_path):
    f = lagrangian.load(write(tmp_path, TWO_LINK)).dynamics()
    with pytest.raises(ModelError, match="expected 2 values"):
        f.mass_matrix([0.1, 0.2, 0.3])


def test_two_link_arm_agrees_with_the_newton_euler_crosscheck():
    # an independent, force-based derivation of the same URDF bodies
    report = lagrangian.load("two_link_arm").crosscheck()
    assert report.passed


def test_what_example_robot_data_taught_is_refused_or_warned_in_words(tmp_path, cli):
    """Issue 23: an unphysical inertia on a link fixed to the root (TIAGo's antennas) is a
    warning, the dynamics those of the robot without it; joints that move no mass (Romeo's
    hands) name --lock; an empty <robot> (ur3.urdf) says so, with no Python exception's name."""
    bad = ('<link name="antenna"><inertial><mass value="0.1"/><inertia ixx="1" ixy="0" ixz="0" '
           'iyy="-1" iyz="0" izz="1"/></inertial></link>')
    plain = [link("base"), link("a", 1.0, (0.3, 0, 0)), joint("j1", "base", "a", axis="0 -1 0")]
    antenna = write(tmp_path, robot(*plain, bad, joint("fix", "base", "antenna", kind="fixed")),
                    "antenna.urdf")
    with pytest.warns(lagrangian.ModelWarning, match="link 'antenna'.inertial: the inertia "
                                                     "tensor is not positive semidefinite; "
                                                     "ignored.*fixed to the root"):
        warned = lagrangian.load(antenna).dynamics(backend="numpy")
    reference = lagrangian.load(write(tmp_path, robot(*plain), "plain.urdf")).dynamics(
        backend="numpy")
    assert warned.mass_matrix([0.4]) == pytest.approx(reference.mass_matrix([0.4]), rel=1e-15)
    result = cli("dynamics", str(antenna), "--q", "0.4")
    assert result.code == 0
    assert result.err.startswith("warning: ") and "fixed to the root" in result.err
    moving = write(tmp_path, robot(*plain, bad, joint("j2", "a", "antenna")), "moving.urdf")
    with pytest.raises(ModelError, match="link 'antenna'.inertial: the inertia tensor is not "
                                         "positive semidefinite"):
        lagrangian.load(moving)
    hand = write(tmp_path, robot(*plain, link("hand"), joint("grip", "a", "hand")), "hand.urdf")
    with pytest.raises(LagrangianError, match="URDF joint 'grip' moves no mass.*--lock grip=0 "
                                              r"\(Python: load\(path, lock=\{'grip': 0.0\}\)\)"):
        lagrangian.load(hand).dynamics()
    locked = lagrangian.load(hand, lock={"grip": 0.0}).dynamics()
    assert locked.mass_matrix([0.4]) == pytest.approx(reference.mass_matrix([0.4]), rel=1e-15)
    empty = tmp_path / "empty.urdf"
    empty.write_text('<?xml version="1.0"?>\n<robot xmlns:xacro="http://wiki.ros.org/xacro">'
                     "</robot>")
    with pytest.raises(ModelError, match="the <robot> holds no <link>: an empty robot") as info:
        lagrangian.load(empty)
    assert "KeyError" not in str(info.value)
    nameless = tmp_path / "nameless.urdf"
    nameless.write_text('<robot><link name="a"/></robot>')
    with pytest.raises(ModelError, match="the <robot> element has no name"):
        lagrangian.load(nameless)
