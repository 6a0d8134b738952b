"""The joint-torque regressor: tau = Y(q, q_dot, q_ddot) pi, linear in the inertial parameters.

For a URDF tree (model/tree.py), 10 parameters per moving body in Pinocchio's order
(``Inertia.toDynamicParameters``, ``computeJointTorqueRegressor``):

    pi = [m, m c_x, m c_y, m c_z, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz]

with c the centre of mass and I the inertia tensor about the body's (joint's) frame origin, in
its axes (kg, kg m, kg m^2). Newton-Euler is linear in them: a body's wrench about its origin is
f = m a + dw x h + w x (w x h), n = I dw + w x I w + h x a (a includes gravity), and each wrench
reaches every joint above it. For a model file the parameters are named ones in which T and V
(hence M and f) are linear: Y_k = dM/dp_k q_ddot - df/dp_k, from the derived equations.
Units SI; the actuator parameters tau_<joint> are not in Y pi (they are the torques' other side).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import sympy as sp

from ..compile.lambdified import StateFunction
from ..errors import InputError
from ..model.expressions import as_expression

PARAMETERS_PER_BODY = ("m", "mc_x", "mc_y", "mc_z", "I_xx", "I_xy", "I_yy", "I_xz", "I_yz", "I_zz")
# (row, column) of I for I_xx, I_xy, I_yy, I_xz, I_yz, I_zz: Pinocchio's order
_INERTIA_ENTRIES = ((0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2))


def cross_matrix(x) -> np.ndarray:
    """[x]x for x (N, 3): (N, 3, 3) with [x]x y = x cross y."""
    out = np.zeros(x.shape[:-1] + (3, 3), dtype=np.result_type(x, float))
    out[..., 0, 1], out[..., 0, 2], out[..., 1, 2] = -x[..., 2], x[..., 1], -x[..., 0]
    out[..., 1, 0], out[..., 2, 0], out[..., 2, 1] = x[..., 2], -x[..., 1], x[..., 0]
    return out


def tree_parameters(tree) -> np.ndarray:
    """pi of the tree's bodies, (10 * bodies,), in Pinocchio's order."""
    out = []
    for joint in tree.joints:
        inertia = np.array(joint.inertia, dtype=float)
        out += [joint.mass, *joint.first_moment, *(inertia[r, c] for r, c in _INERTIA_ENTRIES)]
    return np.array(out, dtype=float)


def tree_parameter_names(tree) -> tuple[str, ...]:
    """'<parameter>@<joint>' for each entry of pi."""
    return tuple(f"{p}@{joint.name}" for joint in tree.joints for p in PARAMETERS_PER_BODY)


def tree_regressor(recursions, Q: np.ndarray, V: np.ndarray, A: np.ndarray) -> np.ndarray:
    """Y (N, nv, 10 * bodies) over flat batches Q (N, nq), V, A (N, nv): tau = Y pi, from the
    numpy reference's forward pass (recursive_numpy.NumpyBackend in the bodies' own frames):
    each body's wrench per unit of its parameters carried to every joint from its own to the
    root. A floating base's six rows are the wrench on the base in its axes (force, then
    moment), as Pinocchio's rnea; a ball joint's three the moment on its body, a free flyer's
    below the root six its wrench, in its body's axes."""
    count, nv = V.shape
    joints = recursions._joints
    placements, w, dw, acc = recursions._motion(Q, V, A)
    Y = np.zeros((count, nv, 10 * len(joints)))
    if count <= 256:  # few states: every body's basis wrenches in one call (Python's overhead
        # is per call); many: body by body (arrays that stay in cache)
        forces, moments = (x.reshape(len(joints), count, 3, 10) for x in _basis_wrenches(
            *(np.concatenate([np.broadcast_to(y, (count, 3)) for y in x])
              for x in (w, dw, acc))))
    for i in range(len(joints)):
        if count <= 256:
            force, moment = forces[i], moments[i]
        else:
            force, moment = _basis_wrenches(*(np.broadcast_to(x[i], (count, 3))
                                              for x in (w, dw, acc)))
        columns = slice(10 * i, 10 * i + 10)
        k = i
        while k >= 0:  # the body's wrench reaches every joint from its own to the root
            joint = joints[k]
            if joint.free:  # the floating base: S = 1, the whole wrench (the root)
                Y[:, 0:3, columns] += force
                Y[:, 3:6, columns] += moment
                break
            if joint.ball:
                Y[:, joint.iv:joint.iv + 3, columns] += moment
            elif joint.inner:
                Y[:, joint.iv:joint.iv + 3, columns] += force
                Y[:, joint.iv + 3:joint.iv + 6, columns] += moment
            else:
                column = 0.0
                if joint.s_w is not None:
                    column = column + np.einsum("nij,i->nj", moment, joint.s_w)
                if joint.s_v is not None:
                    column = column + np.einsum("nij,i->nj", force, joint.s_v)
                Y[:, joint.iv, columns] += joint.multiplier * column
            if joint.parent < 0:
                break
            R, _, P = placements[k]
            force = R @ force
            moment = R @ moment + P @ force
            k = joint.parent
    return Y


def _basis_wrenches(w, dw, a):
    """The wrench (f, n) about the body's origin per unit of each of its 10 parameters,
    (N, 3, 10) each."""
    count = len(w)
    force = np.zeros((count, 3, 10))
    moment = np.zeros((count, 3, 10))
    W, DW, Acc = cross_matrix(w), cross_matrix(dw), cross_matrix(a)
    force[:, :, 0] = a  # m
    force[:, :, 1:4] = DW + W @ W  # f = dw x h + w x (w x h)
    moment[:, :, 1:4] = -Acc  # n = h x a
    for k, (r, c) in enumerate(_INERTIA_ENTRIES):
        E = np.zeros((3, 3))
        E[r, c] = E[c, r] = 1.0
        moment[:, :, 4 + k] = dw @ E + np.einsum("nij,nj->ni", W, w @ E)  # E dw + w x E w
    return force, moment


class ModelRegressor:
    """Y for named parameters of a model file: Y_k = dM/dp_k q_ddot - df/dp_k (compiled once),
    refused where T and V are not linear in them."""

    def __init__(self, eom, names: Sequence[str], values: dict):
        model = eom.model
        known = {p.name: p.symbol for p in model.parameters}
        unknown = [name for name in names if name not in known]
        if unknown or not names:
            from ..errors import did_you_mean

            name = unknown[0] if unknown else ""
            raise InputError(f"'{name}' is not a parameter of this model"
                             f"{did_you_mean(name, known)}" if unknown else
                             "name the parameters the regressor is linear in",
                             field="parameters")
        symbols = [known[name] for name in names]
        for name in names:
            if values.get(name) is None:
                raise InputError(f"parameter '{name}' has no value", field="parameters")
        n = len(model.q)
        mass = [as_expression(e) for e in eom.mass_matrix]
        forcing = [as_expression(e) for e in eom.forcing]
        for expression in [eom.kinetic_energy, eom.potential_energy, *mass, *forcing]:
            expression = as_expression(expression)
            derivatives = [expression.diff(s) for s in symbols]
            if any(sp.expand(d.diff(s)) != 0 for d in derivatives for s in symbols):
                raise InputError("T, V and the forces must be linear in the parameters "
                                 f"{', '.join(names)} for a regressor", field="parameters")
        if any(sp.expand(e.xreplace({s: 0 for s in symbols})) != 0
               for e in [*mass, *forcing]):
            raise InputError(f"the equations have terms without any of {', '.join(names)}: "
                             "tau = Y pi needs every term to carry one", field="parameters")
        others = {p.symbol: sp.Float(float(v)) for p in model.parameters
                  if p.name not in names and (v := values.get(p.name)) is not None}
        self.names = tuple(names)
        self.n = n
        self._mass = StateFunction(model, [e.diff(s) for s in symbols for e in mass], others)
        self._forcing = StateFunction(model, [e.diff(s) for s in symbols for e in forcing],
                                      others)
        self.values = np.array([float(values[name]) for name in names])

    def __call__(self, Q, V, A) -> np.ndarray:
        """Y (N, n, k) for flat batches."""
        k, n = len(self.names), self.n
        mass = self._mass(Q, np.zeros_like(Q), 0.0).reshape(len(Q), k, n, n)
        forcing = self._forcing(Q, V, 0.0).reshape(len(Q), k, n)
        return np.swapaxes(np.einsum("nkij,nj->nki", mass, A) - forcing, -1, -2)


# Relative size |R_kk| / |R_00| below which a pivoted column counts as dependent.
BASE_TOLERANCE = 1e-8


class BaseParameters:
    """A minimal identifiable set: beta = combination @ pi, with tau = Y[..., independent] beta
    for every state. Found by QR with column pivoting of Y stacked over random states: the
    columns whose |R_kk| exceed ``tolerance`` |R_00| are kept, the others are combinations of
    them (beta = pi_1 + R_11^-1 R_12 pi_2)."""

    def __init__(self, names: Sequence[str], stacked: np.ndarray, tolerance: float):
        import scipy.linalg

        if not (0 < tolerance < 1):
            raise InputError(f"the tolerance must lie between 0 and 1, got {tolerance}",
                             field="tolerance")
        _, R, pivots = scipy.linalg.qr(stacked, mode="economic", pivoting=True)
        diagonal = np.abs(np.diag(R))
        rank = int(np.sum(diagonal > tolerance * max(diagonal[0], 1e-300))) if diagonal.size else 0
        kept, dropped = pivots[:rank], pivots[rank:]
        self.names = tuple(names)
        self.tolerance = float(tolerance)
        self.independent = tuple(int(i) for i in kept)
        combination = np.zeros((rank, len(names)))
        combination[np.arange(rank), kept] = 1.0
        if rank and len(dropped):
            combination[:, dropped] = scipy.linalg.solve_triangular(R[:rank, :rank],
                                                                    R[:rank, rank:])
        combination[np.abs(combination) < 1e-12] = 0.0  # round-off, not a dependency
        self.combination = combination

    @property
    def base_names(self) -> tuple[str, ...]:
        return tuple(self.names[i] for i in self.independent)

    def __len__(self) -> int:
        return len(self.independent)

    def values(self, pi) -> np.ndarray:
        """beta of a standard parameter vector pi."""
        return self.combination @ np.asarray(pi, dtype=float)

    def regressor(self, Y) -> np.ndarray:
        """The base regressor Y_b = Y[..., independent], tau = Y_b beta."""
        return np.asarray(Y)[..., list(self.independent)]

    def describe(self) -> list[str]:
        """Each base parameter as its combination of standard ones, one line each."""
        lines = []
        for row, name in zip(self.combination, self.base_names, strict=True):
            terms = [f"{c:+.6g} {self.names[j]}" for j, c in enumerate(row)
                     if c != 0 and self.names[j] != name]
            lines.append(f"{name}" + (f" {' '.join(terms)}" if terms else ""))
        return lines

    def __repr__(self) -> str:
        return (f"BaseParameters({len(self)} of {len(self.names)}, tolerance "
                f"{self.tolerance:g})")
