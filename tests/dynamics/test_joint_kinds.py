"""Every joint kind a kinematic tree moves (dynamics/tree/joint_models.py's JOINT_MODELS) and
every kind expanded into them (a universal joint, lagrangian.RobotBuilder; a URDF planar joint)
walked through every backend method (M, bias, g, ID, FD, T, V, a frame's placement and
Jacobian, the ID and FD derivatives) on the compiled engine (dynamics(), the default) and the
numpy reference (backend="numpy"), against Pinocchio's own model of the same robot built from
its JointModel classes (JointModelHelicalUnaligned, JointModelUniversal, ...) to 1e-10. A kind
with no tree here, or with no branch in a kernel, fails under its own name.

The ball (spherical) joint is read from MJCF (MuJoCo's ball joint: its quaternion w x y z, its
angular velocity in the child's axes) and compared with Pinocchio's JointModelSpherical (the
quaternion x y z w, the same velocity): q is reordered between the two. Its derivatives (along
the turn, q (x) exp(dq), as Pinocchio's: the engine's analytic ones over the ball's three
columns, the numpy reference's complex step), C(q, v), A_g and J_dot v and the regressor agree
with Pinocchio's, and so does the per-tree generated code (kernel="unrolled" and the standalone
C export; the free joints and the other kinds' export: test_joint_kinds_export.py).

Pinocchio 4.1's computeRNEADerivatives and computeABADerivatives are wrong for
JointModelUniversal (its d tau/dq disagrees with its own rnea's finite differences by O(1)), so
a universal joint's derivatives are checked against the same robot in Pinocchio with the joint
as two RevoluteUnaligned joints (its rnea and aba shown equal to JointModelUniversal's first)."""

from __future__ import annotations

import re

import numpy as np
import pytest

import lagrangian
from lagrangian.dynamics.tree.description import JOINT_CODES
from lagrangian.dynamics.tree.joint_models import JOINT_MODELS
from lagrangian.kinds import JointKind
from lagrangian.model.urdf import parse_urdf

pin = pytest.importorskip("pinocchio")
pytest.importorskip("yourdfpy")

TOLERANCE = 1e-10
BACKENDS = ("compiled", "numpy")


def _unit(x):
    x = np.array(x, dtype=float)
    return x / np.linalg.norm(x)


# (name, mass kg, centre of mass m, principal moments about it kg m^2), link axes
LINKS = [("base", 2.0, (0.05, -0.02, 0.04), (0.05, 0.04, 0.06)),
         ("a", 1.2, (0.1, 0.02, -0.05), (0.02, 0.03, 0.015)),
         ("b", 0.8, (0.0, 0.1, 0.03), (0.01, 0.012, 0.02)),
         ("c", 0.5, (0.03, -0.02, 0.1), (0.004, 0.005, 0.006)),
         ("tool", 0.3, (0.0, 0.0, 0.02), (0.001, 0.002, 0.0015))]
ORIGINS = [((0.1, 0.2, 0.3), (0.1, -0.2, 0.3)), ((0.2, 0.0, 0.1), (0.4, 0.1, -0.3)),
           ((0.0, 0.15, 0.05), (-0.2, 0.3, 0.1))]
AXES = [_unit((0.3, -0.5, 0.8)), _unit((1.0, 0.2, -0.1)), _unit((0.0, 1.0, 1.0))]
# a second axis for each universal joint, perpendicular to the first
SECOND = [_unit(np.cross(AXES[0], (1.0, 0.0, 0.0))), None, _unit(np.cross(AXES[2], (0.0, 0.0, 1.0)))]
PITCHES = [0.07, 0.0, -0.12]
TOOL = ((0.05, 0.0, 0.1), (0.2, 0.0, 0.5))  # a fixed joint from c: folded into c's body

# each tree: the kinds of its joints base -> a -> b -> c (a revolute joint between, so that the
# kind sits at the root and below a turning body), floating: a free flyer carries the base
TREES = {
    JointKind.REVOLUTE: (("revolute", "revolute", "revolute"), False),
    JointKind.PRISMATIC: (("prismatic", "revolute", "prismatic"), False),
    JointKind.HELICAL: (("helical", "revolute", "helical"), False),
    JointKind.FREE_FLYER: (("helical", "revolute", "prismatic"), True),
    "universal": (("universal", "revolute", "universal"), False),
    JointKind.SPHERICAL: (("spherical", "revolute", "spherical"), False),  # from MJCF: _ball
}
EXPANDED = ("universal", "planar")


def _builder(kinds):
    b = lagrangian.RobotBuilder("kinds")
    for name, mass, com, moments in LINKS:
        b.link(name, mass=mass, com=com, inertia=moments)
    chain = ("base", "a", "b", "c")
    for k, kind in enumerate(kinds):
        (xyz, rpy), axis = ORIGINS[k], AXES[k]
        b.joint(f"j{k + 1}", kind, chain[k], chain[k + 1], xyz=xyz, rpy=rpy, axis=axis,
                pitch=PITCHES[k] if kind == "helical" else 0.0,
                axis2=SECOND[k] if kind == "universal" else None)
    b.joint("tool_joint", "fixed", "c", "tool", xyz=TOOL[0], rpy=TOOL[1])
    return b


def _inertia(name):
    _, mass, com, moments = next(link for link in LINKS if link[0] == name)
    return pin.Inertia(mass, np.array(com), np.diag(moments))


def _placement(xyz, rpy):
    return pin.SE3(pin.rpy.rpyToMatrix(*rpy), np.array(xyz, dtype=float))


def _joint_model(kind, k):
    """Pinocchio's model of joint k + 1 of a tree of TREES."""
    if kind == "revolute":
        return pin.JointModelRevoluteUnaligned(AXES[k])
    if kind == "prismatic":
        return pin.JointModelPrismaticUnaligned(AXES[k])
    if kind == "helical":
        return pin.JointModelHelicalUnaligned(AXES[k], PITCHES[k])
    return pin.JointModelUniversal(AXES[k], SECOND[k])


def _pinocchio(kinds, floating, chain=False):
    """The same robot in Pinocchio from its own joint models, and the joint of link c's body;
    ``chain``: a universal joint as two revolute ones (for the derivatives)."""
    model = pin.Model()
    parent = 0
    if floating:
        parent = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root_joint")
        model.appendBodyToJoint(parent, _inertia("base"), pin.SE3.Identity())
    for k, kind in enumerate(kinds):
        (xyz, rpy), axis = ORIGINS[k], AXES[k]
        joint = _joint_model(kind, k)
        if kind == "universal" and chain:
            parent = model.addJoint(parent, pin.JointModelRevoluteUnaligned(axis),
                                    _placement(xyz, rpy), f"j{k + 1}_1")
            joint = pin.JointModelRevoluteUnaligned(SECOND[k])
            parent = model.addJoint(parent, joint, pin.SE3.Identity(), f"j{k + 1}_2")
        else:
            parent = model.addJoint(parent, joint, _placement(xyz, rpy), f"j{k + 1}")
        model.appendBodyToJoint(parent, _inertia("abc"[k]), pin.SE3.Identity())
    model.appendBodyToJoint(parent, _inertia("tool"), _placement(*TOOL))
    return model, parent


PLANAR_URDF = """<robot name="planar_arm">
  <link name="world"/>
  <link name="base"><inertial><origin xyz="0.05 -0.02 0.04"/><mass value="2"/>
    <inertia ixx="0.05" ixy="0" ixz="0" iyy="0.04" iyz="0" izz="0.06"/></inertial></link>
  <link name="c"><inertial><origin xyz="0.03 -0.02 0.1"/><mass value="0.5"/>
    <inertia ixx="0.004" ixy="0" ixz="0" iyy="0.005" iyz="0" izz="0.006"/></inertial></link>
  <joint name="mobile" type="planar"><parent link="world"/><child link="base"/>
    <origin xyz="0.1 0.2 0.3" rpy="0.1 -0.2 0.3"/><axis xyz="0 0 1"/></joint>
  <joint name="arm" type="revolute"><parent link="base"/><child link="c"/>
    <origin xyz="0.2 0 0.1" rpy="0.4 0.1 -0.3"/><axis xyz="1 0 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>"""


def _numbers(values):
    return " ".join(repr(float(c)) for c in values)


def _quat_wxyz(rpy):
    x, y, z, w = pin.Quaternion(pin.rpy.rpyToMatrix(*rpy)).coeffs()
    return _numbers((w, x, y, z))


def _ball_mjcf():
    """base -> a (ball) -> b (hinge) -> c (ball), as MJCF: each body at ORIGINS[k], its joint
    at its origin, its link's inertial about the centre of mass in its own axes."""
    def body(k, name, joint, inner=""):
        (xyz, rpy), (_, mass, com, moments) = ORIGINS[k], next(x for x in LINKS if x[0] == name)
        kind = 'type="ball"' if joint == "ball" else f'type="hinge" axis="{_numbers(AXES[k])}"'
        return (f'<body name="{name}" pos="{_numbers(xyz)}" quat="{_quat_wxyz(rpy)}">'
                f'<joint name="j{k + 1}" {kind}/><inertial pos="{_numbers(com)}" '
                f'mass="{mass!r}" diaginertia="{_numbers(moments)}"/>{inner}</body>')
    chain = body(0, "a", "ball", body(1, "b", "hinge", body(2, "c", "ball")))
    return (f'<mujoco model="balls"><compiler angle="radian"/><worldbody>{chain}</worldbody>'
            "</mujoco>")


def _ball():
    """The ball-joint tree from MJCF, and in Pinocchio from JointModelSpherical."""
    from lagrangian.model.mjcf import parse_mjcf

    system = lagrangian.System(parse_mjcf(_ball_mjcf()))
    model = pin.Model()
    parent = 0
    for k, name in enumerate("abc"):
        joint = pin.JointModelRevoluteUnaligned(AXES[k]) if k == 1 else pin.JointModelSpherical()
        parent = model.addJoint(parent, joint, _placement(*ORIGINS[k]), f"j{k + 1}")
        model.appendBodyToJoint(parent, _inertia(name), pin.SE3.Identity())
    return system, model, parent


def _ours(kind, q):
    """Our q of Pinocchio's: a ball's quaternion x y z w reordered w x y z (MuJoCo's)."""
    q = np.array(q, dtype=float)
    if kind != JointKind.SPHERICAL:
        return q
    out = q.copy()
    for start in (0, 5):  # j1's four numbers, j2's one, j3's four
        out[..., start] = q[..., start + 3]
        out[..., start + 1:start + 4] = q[..., start:start + 3]
    return out


def _planar():
    """A mobile arm on a URDF planar joint, and in Pinocchio x, y sliding and theta turning in
    the joint's frame (the planar joint's own coordinates: rates their time derivatives)."""
    system = lagrangian.System(parse_urdf(PLANAR_URDF))
    model = pin.Model()
    x = model.addJoint(0, pin.JointModelPX(), _placement(*ORIGINS[0]), "mobile_x")
    y = model.addJoint(x, pin.JointModelPY(), pin.SE3.Identity(), "mobile_y")
    theta = model.addJoint(y, pin.JointModelRZ(), pin.SE3.Identity(), "mobile_theta")
    model.appendBodyToJoint(theta, _inertia("base"), pin.SE3.Identity())
    arm = model.addJoint(theta, pin.JointModelRX(), _placement(*ORIGINS[1]), "arm")
    model.appendBodyToJoint(arm, _inertia("c"), pin.SE3.Identity())
    return system, model, arm


@pytest.fixture(scope="module", params=[*sorted(JOINT_MODELS), *EXPANDED], ids=str)
def case(request):
    """(kind, the System, Pinocchio's model and data, the joint whose body frame "c" is,
    states q, v, a, tau, and the Pinocchio model and data of the derivatives); every kind of
    JOINT_MODELS is a param: one without a tree here fails by its name."""
    kind = request.param
    if kind == "planar":
        system, model, body = _planar()
        derivatives = model
    elif kind == JointKind.SPHERICAL:
        system, model, body = _ball()
        derivatives = model
    else:
        if kind not in TREES:
            pytest.fail(f"no tree walks the {kind} joint: add one to TREES")
        kinds, floating = TREES[kind]
        system = _builder(kinds).build(floating_base=floating)
        model, body = _pinocchio(kinds, floating)
        derivatives = _pinocchio(kinds, floating, chain=True)[0]
    data = model.createData()
    rng = np.random.default_rng(7)
    q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq)) \
        if kind in (JointKind.FREE_FLYER, JointKind.SPHERICAL) \
        else rng.uniform(-1.0, 1.0, model.nq)
    v, a = rng.uniform(-1.0, 1.0, (2, model.nv))
    assert len(system.dynamics().coordinates) == model.nq, kind
    tau = pin.rnea(model, data, q, v, a)
    chain = derivatives.createData()  # the same robot: the same ID and FD
    _agree(pin.rnea(derivatives, chain, q, v, a), tau, f"{kind}: Pinocchio's two models")
    _agree(pin.aba(derivatives, chain, q, v, tau), a, f"{kind}: Pinocchio's two models")
    return kind, system, model, data, body, (q, v, a, tau), (derivatives, chain)


@pytest.fixture(scope="module")
def backends(case):
    system = case[1]
    return {"compiled": system.dynamics(), "numpy": system.dynamics(backend="numpy")}


def _agree(ours, theirs, what):
    ours, theirs = np.asarray(ours, dtype=float), np.asarray(theirs, dtype=float)
    assert ours.shape == theirs.shape, what
    error = float(np.abs(ours - theirs).max())
    assert error <= TOLERANCE * (1.0 + float(np.abs(theirs).max())), f"{what}: off by {error:.2e}"


@pytest.mark.parametrize("backend", BACKENDS)
def test_dynamics_agree_with_pinocchio(case, backends, backend):
    kind, _, model, data, _, (q, v, a, tau), _ = case
    d = backends[backend]
    where = f"{kind} joint, {backend}"
    assert ("numpy" in d.backend) == (backend == "numpy"), where  # the engine by default
    M = pin.crba(model, data, q)
    pq, q = q, _ours(kind, q)
    _agree(d.mass_matrix(q), np.triu(M) + np.triu(M, 1).T, f"{where}: M")
    _agree(d.bias_forces(q, v), pin.nle(model, data, pq, v), f"{where}: bias")
    _agree(d.gravity(q), pin.computeGeneralizedGravity(model, data, pq), f"{where}: g")
    _agree(d.inverse_dynamics(q, v, a), tau, f"{where}: ID")
    _agree(d.forward_dynamics(q, v, tau), pin.aba(model, data, pq, v, tau), f"{where}: FD")
    _agree(d.kinetic_energy(q, v), pin.computeKineticEnergy(model, data, pq, v), f"{where}: T")
    _agree(d.potential_energy(q), pin.computePotentialEnergy(model, data, pq), f"{where}: V")


@pytest.mark.parametrize("backend", BACKENDS)
def test_frames_agree_with_pinocchio(case, backends, backend):
    kind, _, model, data, body, (q, *_), _ = case
    d = backends[backend]
    where = f"{kind} joint, {backend}"
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    q = _ours(kind, q)
    _agree(d.placement(q, "c"), data.oMi[body].homogeneous, f"{where}: placement")
    for reference, pinocchio in (("local_world_aligned", pin.LOCAL_WORLD_ALIGNED),
                                 ("local", pin.LOCAL), ("world", pin.WORLD)):
        _agree(d.jacobian(q, "c", reference),
               pin.getJointJacobian(model, data, body, pinocchio), f"{where}: J {reference}")


@pytest.mark.parametrize("backend", BACKENDS)
def test_derivatives_agree_with_pinocchio(case, backends, backend):
    kind, system, _, _, _, (q, v, a, tau), (model, data) = case
    d = backends[backend]
    where = f"{kind} joint, {backend}"
    # the engine's analytic derivatives on every kind (a ball's as its three columns), never
    # the complex step the numpy backend takes
    assert (d._derivatives_kernel() is not None) == (backend == "compiled"), where
    # a ball joint's d/dq along its turn in its body's axes (q (x) exp(dq)), as Pinocchio's
    mine = _ours(kind, q) if kind == JointKind.SPHERICAL else q
    dq, dv, _ = pin.computeRNEADerivatives(model, data, q, v, a)
    ours = d.inverse_dynamics_derivatives(mine, v, a)
    _agree(ours[0], dq, f"{where}: d tau/dq")
    _agree(ours[1], dv, f"{where}: d tau/dv")
    fq, fv, inverse = pin.computeABADerivatives(model, data, q, v, tau)
    ours = d.forward_dynamics_derivatives(mine, v, tau)
    _agree(ours[0], fq, f"{where}: d a/dq")
    _agree(ours[1], fv, f"{where}: d a/dv")
    _agree(ours[2], inverse, f"{where}: d a/d tau")


@pytest.mark.parametrize("backend", BACKENDS)
def test_momentum_coriolis_and_regressor_agree_with_pinocchio(case, backends, backend):
    """The centre of mass, A_g, J_dot v, C(q, v) and the regressor Y (Pinocchio's C and Y
    of a universal joint from its two revolute joints, as its derivatives; a ball joint's
    against Pinocchio's JointModelSpherical)."""
    kind, _, model, data, body, (q, v, a, tau), (chain, chain_data) = case
    d = backends[backend]
    where = f"{kind} joint, {backend}"
    ball = kind == JointKind.SPHERICAL
    ours = _ours(kind, q) if ball else q  # Pinocchio's quaternion (x y z w), ours (w x y z)
    _agree(d.center_of_mass(ours), pin.centerOfMass(model, data, q), f"{where}: com")
    _agree(d.centroidal_momentum_matrix(ours), pin.ccrba(model, data, q, v), f"{where}: A_g")
    pin.forwardKinematics(model, data, q, v, np.zeros(model.nv))
    _agree(d.jacobian_dot_times_v(ours, v, "c", "local_world_aligned"),
           pin.getClassicalAcceleration(model, data, body, pin.LOCAL_WORLD_ALIGNED).vector,
           f"{where}: J_dot v")
    _agree(d.coriolis_matrix(ours, v), pin.computeCoriolisMatrix(chain, chain_data, q, v),
           f"{where}: C")
    Y = d.regressor(ours, v, a)
    _agree(Y, pin.computeJointTorqueRegressor(chain, chain_data, q, v, a), f"{where}: Y")
    _agree(Y @ d.inertial_parameters(), tau, f"{where}: Y pi")


def test_the_casadi_functions_agree_with_pinocchio(case):
    """to_casadi (the numpy reference's recursions over casadi SX) on each kind: M = crba,
    -f = nle with no input, and rhs's accelerations = aba under the joints' torques (the
    inputs: every joint's velocity number; a floating base unforced)."""
    casadi = pytest.importorskip("casadi")
    kind, system, model, data, _, (q, v, _, tau), _ = case
    where = f"{kind} joint, casadi"
    names = list(system.model.kinematic_tree.velocity_coordinates)
    functions = system.to_casadi(inputs=names)
    assert isinstance(functions.rhs, casadi.Function)
    base = model.nv - len(names)  # the floating base's six, unforced
    forced = np.r_[np.zeros(base), tau[base:]]
    M = pin.crba(model, data, q)
    ours = _ours(kind, q)
    _agree(np.asarray(functions.mass_matrix(ours)), np.triu(M) + np.triu(M, 1).T, f"{where}: M")
    _agree(-np.asarray(functions.forcing(ours, v, np.zeros(len(names)))).ravel(),
           pin.nle(model, data, q, v), f"{where}: bias")
    x_dot = np.asarray(functions.rhs(np.r_[ours, v], tau[base:])).ravel()
    _agree(x_dot[model.nq:], pin.aba(model, data, q, v, forced), f"{where}: FD")


def test_a_batch_is_its_single_calls(case, backends):
    """The compiled engine's batches (vector lanes) on each kind: rows equal the single calls
    (M, ID, FD bit for bit; a frame's Jacobian and the derivatives to 1e-13), a NaN state's
    row NaN."""
    kind, _, model, _, _, (q, v, a, tau), _ = case
    d = backends["compiled"]
    rng = np.random.default_rng(11)
    Q = _ours(kind, [pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
                     for _ in range(9)])
    V, A = rng.uniform(-1.0, 1.0, (2, 9, model.nv))
    Q[4, -1] = np.nan
    with pytest.warns(lagrangian.DynamicsWarning):
        batches = [d.mass_matrix(Q), d.inverse_dynamics(Q, V, A), d.forward_dynamics(Q, V, A),
                   d.jacobian(Q, "c"), d.forward_dynamics_derivatives(Q, V, A)[0]]
    for k, batch in enumerate(batches):
        assert np.isnan(batch[4]).all(), (kind, k)
        for i in (0, 3, 8):
            single = [d.mass_matrix(Q[i]), d.inverse_dynamics(Q[i], V[i], A[i]),
                      d.forward_dynamics(Q[i], V[i], A[i]), d.jacobian(Q[i], "c"),
                      d.forward_dynamics_derivatives(Q[i], V[i], A[i])[0]][k]
            if k < 3:
                assert np.array_equal(batch[i], single), (kind, k, i)
            else:
                _agree(batch[i], single, f"{kind}: batch {k}, row {i}")


@pytest.mark.parametrize("case", [JointKind.SPHERICAL], indirect=True, ids=str)
def test_the_generated_code_takes_the_ball_joint(case, tmp_path):
    """The per-tree generated code on the ball joint: kernel="unrolled" (a batch on vector
    lanes, and a single call) and the standalone C export (-std=c99 -pedantic -Werror) give
    Pinocchio's M, bias, g, ID, FD, T and V, the export the frame's placement and Jacobians
    too, to 1e-10 (test_joint_kinds_export.py: an MJCF free joint, a URDF floating joint
    between links, every export function against the numpy reference)."""
    import ctypes

    from tests.dynamics.test_joint_kinds_export import _export

    kind, system, model, data, body, (pq, v, a, tau), _ = case
    q = _ours(kind, pq)
    M = pin.crba(model, data, pq)
    expected = {"M": np.triu(M) + np.triu(M, 1).T, "b": pin.nle(model, data, pq, v),
                "g": pin.computeGeneralizedGravity(model, data, pq), "ID": tau, "FD": a,
                "T": pin.computeKineticEnergy(model, data, pq, v),
                "V": pin.computePotentialEnergy(model, data, pq)}

    def seven(d, x, y, z, t):
        return {"M": d.mass_matrix(x), "b": d.bias_forces(x, y), "g": d.gravity(x),
                "ID": d.inverse_dynamics(x, y, z), "FD": d.forward_dynamics(x, y, t),
                "T": d.kinetic_energy(x, y), "V": d.potential_energy(x)}

    d = system.dynamics(kernel="unrolled")
    assert d.kernel == "unrolled"
    batch = seven(d, *(np.repeat(np.asarray(x)[None], 5, axis=0) for x in (q, v, a, tau)))
    for what, single in seven(d, q, v, a, tau).items():
        _agree(single, expected[what], f"ball joint, unrolled: {what}")
        for row in batch[what]:
            _agree(row, expected[what], f"ball joint, unrolled batch: {what}")
    c, P, code = _export(system, tmp_path, "-O0")

    def at(x):
        return np.ascontiguousarray(x, dtype=float).ctypes.data_as(ctypes.c_void_p)

    count = int(re.search(rf"#define {P.upper()}_NP (\d+)", code.header).group(1))
    p = at(np.ctypeslib.as_array((ctypes.c_double * count).in_dll(c, f"{P}_parameters")))
    n = model.nv
    M, out, T = np.zeros((n, n)), np.zeros(n), np.zeros((4, 4))
    getattr(c, f"{P}_mass_matrix")(at(q), p, at(M))
    _agree(M, expected["M"], "ball joint, export: M")
    for name, args, what in (("bias_forces", (q, v), "b"), ("gravity", (q,), "g"),
                             ("inverse_dynamics", (q, v, a), "ID"),
                             ("forward_dynamics", (q, v, tau), "FD")):
        getattr(c, f"{P}_{name}")(*map(at, args), p, at(out))
        _agree(out, expected[what], f"ball joint, export: {what}")
    for name, args, what in (("kinetic_energy", (q, v), "T"), ("potential_energy", (q,), "V")):
        function = getattr(c, f"{P}_{name}")
        function.restype = ctypes.c_double
        _agree(function(*map(at, args), p), expected[what], f"ball joint, export: {what}")
    names = [x.decode() for x in (ctypes.c_char_p * len(d.frames)).in_dll(c, f"{P}_frame_names")]
    pin.computeJointJacobians(model, data, pq)
    getattr(c, f"{P}_frame_placement")(at(q), names.index("c"), at(T))
    _agree(T, data.oMi[body].homogeneous, "ball joint, export: placement")
    for r, reference in enumerate((pin.WORLD, pin.LOCAL, pin.LOCAL_WORLD_ALIGNED)):
        J = np.zeros((6, n))
        getattr(c, f"{P}_frame_jacobian")(at(q), names.index("c"), r, at(J))
        _agree(J, pin.getJointJacobian(model, data, body, reference), f"ball joint, export: J {r}")


def test_every_kind_has_a_code_and_a_tree():
    """A kind in JOINT_MODELS has its record code (description.py) and a tree here."""
    assert set(JOINT_CODES) == set(JOINT_MODELS), set(JOINT_MODELS) ^ set(JOINT_CODES)
    missing = sorted(set(JOINT_MODELS) - set(TREES))
    assert not missing, f"no tree walks the {', '.join(missing)} joint"


def test_a_kind_without_its_branch_is_refused_by_the_engine():
    """A record code joint.h has no branch for is refused by its tk_open in each module that
    reads the description (the tree kernel, the reach and the derivatives modules): no silent
    motion."""
    from lagrangian.dynamics.engine import derivatives_c, reach_c
    from lagrangian.dynamics.engine.compact_kernel import kernel_module
    from lagrangian.dynamics.tree.description import HEADER, describe

    system = _builder(TREES[JointKind.HELICAL][0]).build()
    tree = system.model.kinematic_tree
    D = np.array(describe(tree, {"g": 9.81}))
    D[HEADER + len(tree.coordinates) + 1] = 9.0  # body 0's kind: a code no branch takes
    with pytest.raises((TypeError, ValueError), match="not a tree description"):
        kernel_module().prepare(D)
    with pytest.raises(TypeError, match="not a prepared tree"):  # the tables, never the array
        kernel_module().mass_matrix(np.zeros(len(tree.coordinates)), D)
    reach, derivatives = reach_c.engine(), derivatives_c.engine()
    if reach is None or derivatives is None:
        pytest.skip("no C compiler")
    with pytest.raises(ValueError, match="not a tree description"):
        reach.tree(D, *reach_c.tables(tree), {})
    with pytest.raises(ValueError, match="not a description"):
        derivatives.tree(D, derivatives_c.tables(tree))
    reach.tree(describe(tree, {}), *reach_c.tables(tree), {})  # the same tree's own D: taken
    derivatives.tree(describe(tree, {}), derivatives_c.tables(tree))
