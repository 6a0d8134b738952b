"""A robot's kinematic tree (model/tree.py) as CasADi Functions: the recursive Newton-Euler
algorithm written over casadi SX, so a URDF or MJCF robot gets rhs, M and f without deriving
its equations. Spatial vectors (angular; linear at the body's origin) in body axes, SI units:

    tau = RNEA(q, q_dot, q_ddot),  M = d tau / d q_ddot (exact: tau is linear in q_ddot),
    b = RNEA(q, q_dot, 0) = C q_dot + g,  f = tau_model + B u - b.

A floating base (the free flyer at the root) has Pinocchio's layout, as our dynamics: q = [x, y,
z (m), qx, qy, qz, qw, joints], v = [v_b (m/s), w_b (rad/s) in the base's axes, joint rates];
its generalized force is the wrench on the base in its axes, force then moment. The base's R is
that of q / |q| (a rotation for any nonzero quaternion; ours at |q| = 1), and x_dot = [q_dot;
v_dot] with q_dot = [R v_b, 1/2 q (x) (w_b, 0), joint rates], as simulate integrates it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from ..errors import ModelError
from ..kinds import JointKind
from ..model.model import Model
from ..model.tree import KinematicTree, refuse_free_joints
from .casadi_functions import CasadiFunctions, _casadi


def _rotation(ca, axis, angle):
    """Rot(u, angle) by Rodrigues' formula, as SX."""
    u = ca.DM(axis)
    cross = ca.DM([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return ca.cos(angle) * ca.DM.eye(3) + ca.sin(angle) * cross + (1 - ca.cos(angle)) * (u @ u.T)


# the floating base's numbers, named as our dynamics names them (dynamics/tree/free_flyer.py)
BASE_CONFIGURATION = ("base_x", "base_y", "base_z", "base_qx", "base_qy", "base_qz", "base_qw")
BASE_VELOCITY = ("base_vx", "base_vy", "base_vz", "base_wx", "base_wy", "base_wz")


def quaternion_rotation(ca, quaternion):
    """R of the quaternion (x, y, z, w) / |.|, as SX."""
    x, y, z, w = (quaternion[i] for i in range(4))
    s = 2 / (x * x + y * y + z * z + w * w)
    return ca.vertcat(
        ca.horzcat(1 - s * (y * y + z * z), s * (x * y - z * w), s * (x * z + y * w)),
        ca.horzcat(s * (x * y + z * w), 1 - s * (x * x + z * z), s * (y * z - x * w)),
        ca.horzcat(s * (x * z - y * w), s * (y * z + x * w), 1 - s * (x * x + y * y)))


def configuration_rate(ca, tree: KinematicTree, q, v):
    """q_dot of a tree's state: the joints' rates, and a floating base's R v_b and quaternion
    rate 1/2 q (x) (w_b, 0) (module docstring)."""
    if not tree.floating_base:
        return v
    x, y, z, w = (q[3 + i] for i in range(4))
    wx, wy, wz = v[3], v[4], v[5]
    return ca.vertcat(quaternion_rotation(ca, q[3:7]) @ v[:3],
                      0.5 * (w * wx + y * wz - z * wy), 0.5 * (w * wy + z * wx - x * wz),
                      0.5 * (w * wz + x * wy - y * wx), -0.5 * (x * wx + y * wy + z * wz),
                      v[6:])


def cholesky_solve(ca, M, b):
    """M^-1 b for a symmetric positive definite M by Cholesky (M = L L^T), as SX: a tree's M is
    such, and the factor keeps the accuracy that CasADi's symbolic QR loses on a floating
    base's M (condition numbers of 1e4 and more)."""
    n = M.shape[0]
    L = [[None] * n for _ in range(n)]
    for j in range(n):
        d = M[j, j] - sum((L[j][k] * L[j][k] for k in range(j)), ca.SX(0))
        L[j][j] = ca.sqrt(d)
        for i in range(j + 1, n):
            L[i][j] = (M[i, j] - sum((L[i][k] * L[j][k] for k in range(j)), ca.SX(0))) / L[j][j]
    y = []
    for i in range(n):  # L y = b
        y.append((b[i] - sum((L[i][k] * y[k] for k in range(i)), ca.SX(0))) / L[i][i])
    x = [None] * n
    for i in reversed(range(n)):  # L^T x = y
        x[i] = (y[i] - sum((L[k][i] * x[k] for k in range(i + 1, n)), ca.SX(0))) / L[i][i]
    return ca.vertcat(*x)


def tree_inverse_dynamics(ca, tree: KinematicTree, q, v, a, gravity):
    """tau (nv SX) of a tree by recursive Newton-Euler; ``gravity`` the vector in world axes
    (m/s^2); a floating base's numbers first (module docstring)."""
    n = v.shape[0]
    bq, bv = tree.base_nq, tree.base_nv
    bodies = []  # per body: R (child -> parent), r (origin in parent), omega, vel, alpha, acc
    for joint in tree.joints:
        R0, t0, u = ca.DM(joint.rotation), ca.DM(joint.translation), ca.DM(joint.axis)
        if joint.kind == JointKind.FREE_FLYER:  # the root: its twist and its derivative
            R = R0 @ quaternion_rotation(ca, q[3:7])
            r = t0 + R0 @ q[:3]
            # the ground accelerates up at g (gravity's trick), seen in the base's axes
            bodies.append((R, r, v[3:6], v[:3], a[3:6], a[:3] - R.T @ ca.DM(gravity)))
            continue
        k, c = joint.multiplier, joint.coordinate
        theta, rate, accel = k * q[bq + c] + joint.offset, k * v[bv + c], k * a[bv + c]
        if joint.kind == JointKind.REVOLUTE:
            R, r = R0 @ _rotation(ca, joint.axis, theta), t0
            s_w, s_v = u, ca.DM.zeros(3)
        elif joint.kind == JointKind.PRISMATIC:
            R, r = R0, t0 + R0 @ u * theta
            s_w, s_v = ca.DM.zeros(3), u
        else:
            raise ModelError(f"joint '{joint.name}' is a {joint.kind.value} joint: the CasADi "
                             "functions of a tree take revolute and prismatic joints",
                             field="to_casadi")
        if joint.parent < 0:
            w_p, v_p = ca.DM.zeros(3), ca.DM.zeros(3)
            al_p, ac_p = ca.DM.zeros(3), -ca.DM(gravity)  # the base accelerates up at g
        else:
            _, _, w_p, v_p, al_p, ac_p = bodies[joint.parent]
        E = R.T
        w = E @ w_p + s_w * rate
        vel = E @ (v_p + ca.cross(w_p, r)) + s_v * rate
        # spatial acceleration: X a_parent + S q_ddot + v x_m (S q_dot)
        sw, sv = s_w * rate, s_v * rate
        alpha = E @ al_p + s_w * accel + ca.cross(w, sw)
        acc = E @ (ac_p + ca.cross(al_p, r)) + s_v * accel + ca.cross(w, sv) + ca.cross(vel, sw)
        bodies.append((R, r, w, vel, alpha, acc))
    forces = []
    for joint, (_, _, w, vel, alpha, acc) in zip(tree.joints, bodies, strict=True):
        m, h, J = joint.mass, ca.DM(joint.first_moment), ca.DM(joint.inertia)
        # I (omega, v) = (J omega + h x v, m v + omega x h); f = I a + v x_f (I v)
        n_mom, f_mom = J @ w + ca.cross(h, vel), m * vel + ca.cross(w, h)
        n_i = J @ alpha + ca.cross(h, acc) + ca.cross(w, n_mom) + ca.cross(vel, f_mom)
        f_i = m * acc + ca.cross(alpha, h) + ca.cross(w, f_mom)
        forces.append([n_i, f_i])
    tau = [ca.SX(0) for _ in range(n)]
    for index in reversed(range(len(tree.joints))):
        joint = tree.joints[index]
        R, r = bodies[index][0], bodies[index][1]
        n_i, f_i = forces[index]
        if joint.kind == JointKind.FREE_FLYER:  # the wrench on the base, in its axes
            for i in range(3):
                tau[i], tau[3 + i] = tau[i] + f_i[i], tau[3 + i] + n_i[i]
            continue
        u = ca.DM(joint.axis)
        along = ca.dot(u, n_i) if joint.kind == JointKind.REVOLUTE else ca.dot(u, f_i)
        tau[bv + joint.coordinate] = tau[bv + joint.coordinate] + joint.multiplier * along
        if joint.parent >= 0:
            f_parent = R @ f_i
            forces[joint.parent][0] = forces[joint.parent][0] + R @ n_i + ca.cross(r, f_parent)
            forces[joint.parent][1] = forces[joint.parent][1] + f_parent
    return ca.vertcat(*tau)


def tree_casadi_functions(model: Model, inputs: Sequence[str] = (),
                          parameters: Mapping[str, float] | None = None) -> CasadiFunctions:
    """rhs, mass_matrix and forcing of a robot's tree (no derivation); ``inputs`` name
    coordinates or their actuator parameters tau_<joint> (a generalized force each)."""
    ca = _casadi()
    tree = model.kinematic_tree
    if tree is None:
        raise ModelError("the model has no kinematic tree", field="to_casadi")
    refuse_free_joints(tree, "the CasADi functions of a tree")
    values = {p.name: p.value for p in model.parameters}
    for name, value in dict(parameters or {}).items():
        if name not in values:
            raise ModelError(f"'{name}' is not a parameter of this model", field="parameters")
        values[name] = float(value)
    unsupported = sorted(set(dict(parameters or {})) - {tree.gravity_parameter, *tree.actuators})
    if unsupported:
        raise ModelError(f"the tree's CasADi functions take g and the actuators' tau_<joint> "
                         f"as parameters, not {', '.join(unsupported)}", field="parameters")
    coordinates = list(tree.coordinates)
    n = len(coordinates)
    columns = []
    inputs = tuple(inputs)
    if len(set(inputs)) != len(inputs):
        raise ModelError(f"an input is named twice: {list(inputs)}", field="inputs")
    for name in inputs:
        if name in coordinates:
            columns.append(coordinates.index(name))
        elif name in tree.actuators:
            columns.append(list(tree.actuators).index(name))
        else:
            raise ModelError(f"'{name}' is not a coordinate or actuator of this robot (inputs "
                             f"may be any of: {', '.join(coordinates + list(tree.actuators))})",
                             field="inputs")
    gravity = [float(values[tree.gravity_parameter]) * x for x in tree.gravity_direction]
    nq, nv = tree.base_nq + n, tree.base_nv + n
    q, v, u = ca.SX.sym("q", nq), ca.SX.sym("q_dot", nv), ca.SX.sym("u", len(inputs))
    a = ca.SX.sym("q_ddot", nv)
    tau = tree_inverse_dynamics(ca, tree, q, v, a, gravity)
    mass = ca.jacobian(tau, a)
    bias = ca.substitute(tau, a, ca.SX.zeros(nv))
    applied = ca.SX(ca.DM([0.0] * tree.base_nv
                          + [float(values[name] or 0.0) for name in tree.actuators]))
    for k, row in enumerate(columns):
        applied[tree.base_nv + row] = applied[tree.base_nv + row] + u[k]
    forcing = applied - bias
    x = ca.vertcat(q, v)
    rate = configuration_rate(ca, tree, q, v)
    floating = tree.floating_base
    return CasadiFunctions(
        coordinates=tuple(coordinates), inputs=inputs, constraint_names=(),
        rhs=ca.Function("rhs", [x, u], [ca.vertcat(rate, cholesky_solve(ca, mass, forcing))],
                        ["x", "u"], ["x_dot"]),
        mass_matrix=ca.Function("mass_matrix", [q], [ca.substitute(mass, v, ca.SX.zeros(nv))],
                                ["q"], ["M"]),
        forcing=ca.Function("forcing", [q, v, u], [forcing], ["q", "q_dot", "u"], ["f"]),
        constraints=None, input_coordinates=tuple(columns),
        configuration=(BASE_CONFIGURATION + tuple(coordinates)) if floating else (),
        velocities=(BASE_VELOCITY + tuple(f"{c}_dot" for c in coordinates)) if floating
        else ())


__all__ = ["BASE_CONFIGURATION", "BASE_VELOCITY", "configuration_rate", "quaternion_rotation",
           "tree_casadi_functions", "tree_inverse_dynamics"]
