"""A robot's kinematic tree (model/tree.py) as CasADi Functions: the recursive Newton-Euler
algorithm written over casadi SX, so a URDF or MJCF robot gets rhs, M and f without deriving
its equations. Spatial vectors (angular; linear at the body's origin) in body axes, SI units:

    tau = RNEA(q, q_dot, q_ddot),  M = d tau / d q_ddot (exact: tau is linear in q_ddot),
    b = RNEA(q, q_dot, 0) = C q_dot + g,  f = tau_model + B u - b.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from ..errors import ModelError
from ..kinds import JointKind
from ..model.model import Model
from ..model.tree import KinematicTree
from .casadi_functions import CasadiFunctions, _casadi


def _rotation(ca, axis, angle):
    """Rot(u, angle) by Rodrigues' formula, as SX."""
    u = ca.DM(axis)
    cross = ca.DM([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return ca.cos(angle) * ca.DM.eye(3) + ca.sin(angle) * cross + (1 - ca.cos(angle)) * (u @ u.T)


def tree_inverse_dynamics(ca, tree: KinematicTree, q, v, a, gravity):
    """tau (n SX) of a fixed-base tree by recursive Newton-Euler; ``gravity`` the vector in
    world axes (m/s^2)."""
    n = q.shape[0]
    bodies = []  # per body: R (child -> parent), r (origin in parent), omega, vel, alpha, acc
    for joint in tree.joints:
        k, c = joint.multiplier, joint.coordinate
        theta, rate, accel = k * q[c] + joint.offset, k * v[c], k * a[c]
        R0, t0, u = ca.DM(joint.rotation), ca.DM(joint.translation), ca.DM(joint.axis)
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
        u = ca.DM(joint.axis)
        along = ca.dot(u, n_i) if joint.kind == JointKind.REVOLUTE else ca.dot(u, f_i)
        tau[joint.coordinate] = tau[joint.coordinate] + joint.multiplier * along
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
    if tree is None or tree.floating_base:
        raise ModelError("the CasADi functions of a tree take a fixed base (yet)",
                         field="to_casadi")
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
    q, v, u = ca.SX.sym("q", n), ca.SX.sym("q_dot", n), ca.SX.sym("u", len(inputs))
    a = ca.SX.sym("q_ddot", n)
    tau = tree_inverse_dynamics(ca, tree, q, v, a, gravity)
    mass = ca.jacobian(tau, a)
    bias = ca.substitute(tau, a, ca.SX.zeros(n))
    applied = ca.SX(ca.DM([float(values[name] or 0.0) for name in tree.actuators]))
    for k, row in enumerate(columns):
        applied[row] = applied[row] + u[k]
    forcing = applied - bias
    x = ca.vertcat(q, v)
    return CasadiFunctions(
        coordinates=tuple(coordinates), inputs=inputs, constraint_names=(),
        rhs=ca.Function("rhs", [x, u], [ca.vertcat(v, ca.solve(mass, forcing))], ["x", "u"],
                        ["x_dot"]),
        mass_matrix=ca.Function("mass_matrix", [q], [ca.substitute(mass, v, ca.SX.zeros(n))],
                                ["q"], ["M"]),
        forcing=ca.Function("forcing", [q, v, u], [forcing], ["q", "q_dot", "u"], ["f"]),
        constraints=None, input_coordinates=tuple(columns))


__all__ = ["tree_casadi_functions", "tree_inverse_dynamics"]
