"""A robot's kinematic tree (model/tree.py) as CasADi Functions: the numpy reference's own
recursions (algorithms/recursions.py) run with casadi SX entries in numpy object arrays, so a
URDF or MJCF robot gets rhs, M and f with no Newton-Euler of its own, for every joint kind the
reference takes (revolute, prismatic, helical, ball, a free flyer at the root or below it, mimic
joints; locks, payloads and gravity are the tree's numbers). SI units:

    M(q) by the composite-rigid-body algorithm,  b = RNEA(q, v, 0) = C v + g - tau_p,
    f = B u - b,  x_dot = [q_dot(q, v); M^-1 f]  (M^-1 by Cholesky).

q and v are our dynamics' (dynamics().coordinates, velocity_names): a floating base's seven and
six numbers first (x y z, qx qy qz qw; its twist in its axes, linear first), a ball's quaternion
w x y z and its body's angular velocity in its own axes, a free flyer below the root as the
base's but in its parent's joint frame. q_dot from v as simulate integrates it: R v_lin for a
free flyer's position, 1/2 q (x) (0, w) for a quaternion; each rotation is that of q / |q|.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from ...compile.casadi_functions import CasadiFunctions, casadi_module
from ...errors import ModelError
from ...model.model import Model
from ...model.tree import KinematicTree
from ..algorithms.recursions import TreeRecursions, _Joint
from ..tree.free_flyer import BASE_CONFIGURATION, BASE_VELOCITY
from ..tree.spherical import ball_slices, joint_layout


class _SymbolicTree(TreeRecursions):
    """The reference recursions' host (recursive_numpy.NumpyBackend's attributes) over the
    tree's own joints: gravity g (m/s^2) and the actuator parameters tau_p as numbers."""

    def __init__(self, tree: KinematicTree, g: float, actuators: Sequence[float]):
        self.tree, self.n = tree, tree.nv
        self._g = g
        self._actuators = np.array([0.0] * tree.base_nv + list(actuators), dtype=float)
        self._up = -g * np.array(tree.gravity_direction, dtype=float)  # the ground's rise
        self._joints = [_Joint(j, tree) for j in tree.joints]


def _row(x) -> np.ndarray:
    """A batch of one state (1, n), object dtype, of the SX column x's entries."""
    out = np.empty((1, x.shape[0]), dtype=object)
    for i in range(x.shape[0]):
        out[0, i] = x[i]
    return out


def _sx(ca, entry):
    """An entry of the recursions' output (SX, or a number where it stayed constant) as SX."""
    return entry if isinstance(entry, ca.SX) else ca.SX(float(entry))


def _rotate(q, v) -> list:
    """R(q / |q|) v for the quaternion q = (x, y, z, w): a free flyer's position rate."""
    x, y, z, w = q
    s = 2 / (x * x + y * y + z * z + w * w)
    return [(1 - s * (y * y + z * z)) * v[0] + s * (x * y - z * w) * v[1] + s * (x * z + y * w) * v[2],
            s * (x * y + z * w) * v[0] + (1 - s * (x * x + z * z)) * v[1] + s * (y * z - x * w) * v[2],
            s * (x * z - y * w) * v[0] + s * (y * z + x * w) * v[1] + (1 - s * (x * x + y * y)) * v[2]]


def _turn_rate(w, x, y, z, omega) -> tuple:
    """(w, x, y, z)_dot = 1/2 q (x) (0, omega), omega in the body's axes (rad/s)."""
    wx, wy, wz = omega
    return (-0.5 * (x * wx + y * wy + z * wz), 0.5 * (w * wx + y * wz - z * wy),
            0.5 * (w * wy + z * wx - x * wz), 0.5 * (w * wz + x * wy - y * wx))


def configuration_rate(ca, tree: KinematicTree, q, v):
    """q_dot (nq SX) of the state (q, v): each free flyer's R v_lin and quaternion rate (x y z
    w), each ball's quaternion rate (w x y z), the other joints' rates (module docstring)."""
    q, v = [q[i] for i in range(tree.nq)], [v[i] for i in range(tree.nv)]
    rate = [None] * tree.nq
    flyers = [(0, 0)] if tree.floating_base else []
    flyers += [(tree.base_nq + j.coordinate, tree.base_nv + tree.velocity_index(j.coordinate))
               for j in tree.free_joints]
    for iq, iv in flyers:
        x, y, z, w = q[iq + 3:iq + 7]
        rate[iq:iq + 3] = _rotate((x, y, z, w), v[iv:iv + 3])
        dw, dx, dy, dz = _turn_rate(w, x, y, z, v[iv + 3:iv + 6])
        rate[iq + 3:iq + 7] = [dx, dy, dz, dw]
    for _, iq, iv in ball_slices(tree):
        rate[iq:iq + 4] = _turn_rate(*q[iq:iq + 4], v[iv:iv + 3])
    qs, vs = joint_layout(tree)
    for i, k in zip(qs, vs, strict=True):
        rate[tree.base_nq + i] = v[tree.base_nv + k]
    return ca.vertcat(*rate)


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


def _input_columns(tree: KinematicTree, inputs: tuple[str, ...]) -> list[int]:
    """Per input, the joints' velocity number it forces: a velocity's own name (a coordinate,
    a ball's shoulder_wx) or its actuator's parameter tau_<joint>."""
    names = list(tree.velocity_coordinates)
    actuators = list(tree.actuators)
    if len(set(inputs)) != len(inputs):
        raise ModelError(f"an input is named twice: {list(inputs)}", field="inputs")
    columns = []
    for name in inputs:
        if name in names:
            columns.append(names.index(name))
        elif name in actuators:
            columns.append(actuators.index(name))
        else:
            every = names + [a for a in actuators if a is not None]
            raise ModelError(f"'{name}' is not a coordinate or actuator of this robot (inputs "
                             f"may be any of: {', '.join(every)})", field="inputs")
    return columns


def _values(model: Model, tree: KinematicTree, parameters) -> dict:
    """The model's parameter values with ``parameters`` applied (gravity, actuators only)."""
    values = {p.name: p.value for p in model.parameters}
    for name, value in dict(parameters or {}).items():
        if name not in values:
            raise ModelError(f"'{name}' is not a parameter of this model", field="parameters")
        values[name] = float(value)
    unsupported = sorted(set(dict(parameters or {})) - {tree.gravity_parameter, *tree.actuators})
    if unsupported:
        raise ModelError(f"the tree's CasADi functions take g and the actuators' tau_<joint> "
                         f"as parameters, not {', '.join(unsupported)}", field="parameters")
    return values


def tree_casadi_functions(model: Model, inputs: Sequence[str] = (),
                          parameters: Mapping[str, float] | None = None) -> CasadiFunctions:
    """rhs, mass_matrix and forcing of a robot's tree (no derivation); ``inputs`` name the
    joints' velocity numbers or their actuator parameters tau_<joint> (a generalized force each)."""
    ca = casadi_module()
    tree = model.kinematic_tree
    if tree is None:
        raise ModelError("the model has no kinematic tree", field="to_casadi")
    values = _values(model, tree, parameters)
    inputs = tuple(inputs)
    columns = _input_columns(tree, inputs)
    nq, nv, bv = tree.nq, tree.nv, tree.base_nv
    recursions = _SymbolicTree(tree, float(values.get(tree.gravity_parameter) or 0.0),
                               [float(values[a] or 0.0) if a else 0.0 for a in tree.actuators])
    q, v, u = ca.SX.sym("q", nq), ca.SX.sym("q_dot", nv), ca.SX.sym("u", len(inputs))
    Q, V = _row(q), _row(v)
    crba = recursions._composite_rigid_body(Q)[0]
    mass = ca.vertcat(*(ca.horzcat(*(_sx(ca, e) for e in row)) for row in crba))
    bias = ca.vertcat(*(_sx(ca, e) for e in recursions._newton_euler(Q, V, None)[0]))
    applied = [ca.SX(0.0)] * nv
    for k, row in enumerate(columns):
        applied[bv + row] = applied[bv + row] + u[k]
    forcing = ca.vertcat(*applied) - bias
    rate = configuration_rate(ca, tree, q, v)
    # x's names where q and v differ (a quaternion): the configuration, then each velocity
    # number (a coordinate's rate named <coordinate>_dot, a twist's base_vx, shoulder_wx, ...)
    named = tree.floating_base or bool(tree.quaternion_joints)
    coordinates = tuple(tree.coordinates)
    base_q, base_v = (BASE_CONFIGURATION, BASE_VELOCITY) if tree.floating_base else ((), ())
    rates = tuple(f"{c}_dot" if c in coordinates else c for c in tree.velocity_coordinates)
    return CasadiFunctions(
        coordinates=coordinates, inputs=inputs, constraint_names=(),
        rhs=ca.Function("rhs", [ca.vertcat(q, v), u],
                        [ca.vertcat(rate, cholesky_solve(ca, mass, forcing))],
                        ["x", "u"], ["x_dot"]),
        mass_matrix=ca.Function("mass_matrix", [q], [mass], ["q"], ["M"]),
        forcing=ca.Function("forcing", [q, v, u], [forcing], ["q", "q_dot", "u"], ["f"]),
        constraints=None, input_coordinates=tuple(columns),
        configuration=(base_q + coordinates) if named else (),
        velocities=(base_v + rates) if named else (), floating=tree.floating_base)


__all__ = ["configuration_rate", "tree_casadi_functions"]
