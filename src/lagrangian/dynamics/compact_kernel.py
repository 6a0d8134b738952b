"""The compact tree kernel: one compiled module (tree_kernel.c) for every tree, the tree given
at run time as one array of doubles, so a 200-joint chain needs no code of its own and a link's
mass, centre of mass or inertia changes without a rebuild.

The description ``D`` (float64, contiguous), built by ``describe``:

    D[0] nb bodies, D[1] n joint coordinates, D[2:5] the gravity vector g * direction (world
    axes, m/s^2), D[5] 1 where a coordinate drives more or fewer than one body (mimic joints:
    forward dynamics by Cholesky of M instead of the articulated-body algorithm), D[6] 1 for a
    floating base (body 0 on a free flyer: q of n + 7 numbers, v of n + 6, free_flyer.py's
    layout), D[7] the quaternion-norm tolerance (free_flyer.QUATERNION_TOLERANCE);
    D[8:8+n] the actuator parameters tau_<joint> (N m or N), acting as loads;
    then nb records of STRIDE = 40 numbers, parent first (parent < own index):
      0 parent (-1 the ground)  1 kind code (JOINT_CODES)  2 coordinate index c
      3 multiplier k  4 offset (theta = k q[c] + offset)  5:14 R0 (joint -> parent axes,
      row-major)  14:17 t0 (m)  17:20 unit axis u (joint axes)  20 mass (kg)
      21:24 first moment h = m c about the body origin (kg m)  24:33 J_O (kg m^2, body axes)
      33:60 a revolute joint's turn tables P = R0 u u^T, C = R0 (1 - u u^T), S = R0 [u]x
      (row-major each: R0 Rot(u, theta) = P + cos theta C + sin theta S)  60:64 spare.
      A free flyer (code 2, body 0 only) reads R0, t0 and the inertia alone.

A new joint kind is a new code in JOINT_CODES and its cases in tree_kernel.c (tk_place for the
placement, tk_subspace for S); the recursions themselves ask only for those. The module
(tree_kernel.c, tree_kernel_forward.c, then its Python bindings tree_kernel_bindings.c) is keyed
by its source alone, never the tree's numbers.
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..kinds import JointKind
from ..model.model import Model
from ..model.tree import KinematicTree, TreeJoint
from .recursive import RecursiveDynamics

HEADER, STRIDE = 8, 64
JOINT_CODES = {JointKind.REVOLUTE: 0, JointKind.PRISMATIC: 1, JointKind.FREE_FLYER: 2}

# the recursions (forward dynamics in a file of its own), the thread count shared with the other
# modules, then the batched Python bindings (one translation unit)
_SOURCES = tuple(Path(__file__).with_name(name)
                 for name in ("tree_kernel.c", "tree_kernel_forward.c", "batch_threads.c",
                              "tree_kernel_bindings.c"))


def _source() -> str:
    from .tree_c import _SINCOS

    head, rest = _SOURCES[0].read_text(encoding="utf-8").split("/* TK_SINCOS */")
    return "\n".join([head, _SINCOS, rest,
                      *(path.read_text(encoding="utf-8") for path in _SOURCES[1:])])

# Trees of more moving bodies than this get the compact kernel; smaller ones the unrolled
# module of tree_c.py: about 2x faster per call and, up to tree_emitter.VECTOR_LIMIT, several
# states per vector operation in a batch, while its cold compile stays under ~20 s (measured:
# docs/benchmarks.md, benchmarks/bench_tree_kernel.py --threshold).
COMPACT_ABOVE = 16


def describe(tree: KinematicTree, parameters: Mapping[str, float]) -> np.ndarray:
    """The tree as the kernel's array D (layout above), with the parameters' values (g and the
    actuators) in SI units."""
    from .free_flyer import QUATERNION_TOLERANCE

    n, nb = len(tree.coordinates), len(tree.joints)
    D = np.zeros(HEADER + n + nb * STRIDE)
    D[0], D[1] = nb, n
    D[2:5] = float(parameters.get(tree.gravity_parameter, 0.0)) * np.array(tree.gravity_direction)
    drives = np.bincount([j.coordinate for j in tree.joints if j.coordinate >= 0], minlength=n)
    D[5] = float(not np.all(drives == 1))
    D[6], D[7] = float(tree.floating_base), QUATERNION_TOLERANCE
    D[HEADER:HEADER + n] = [float(parameters.get(a, 0.0)) for a in tree.actuators]  # None: 0
    for i, j in enumerate(tree.joints):
        r = D[HEADER + n + i * STRIDE:HEADER + n + (i + 1) * STRIDE]
        r[0], r[1], r[2] = j.parent, JOINT_CODES[JointKind(j.kind)], max(j.coordinate, 0)
        r[3], r[4] = j.multiplier, j.offset
        r[5:14] = np.ravel(j.rotation)
        r[14:17], r[17:20] = j.translation, j.axis
        r[20], r[21:24], r[24:33] = j.mass, j.first_moment, np.ravel(j.inertia)
        R0, u = np.array(j.rotation, dtype=float), np.array(j.axis, dtype=float)
        uu = np.outer(u, u)
        skew = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
        r[33:42], r[42:51], r[51:60] = np.ravel(R0 @ uu), np.ravel(R0 @ (np.eye(3) - uu)), \
            np.ravel(R0 @ skew)
    D.flags.writeable = False
    return D


def joints_of(D: np.ndarray) -> tuple[TreeJoint, ...]:
    """The bodies of a description as TreeJoints (names left empty): what the numpy twin
    (recursive_numpy.py) reads, so that both compute from the same array."""
    kinds = {code: kind for kind, code in JOINT_CODES.items()}
    nb, n = int(D[0]), int(D[1])
    out = []
    for i in range(nb):
        r = D[HEADER + n + i * STRIDE:HEADER + n + (i + 1) * STRIDE]

        def matrix(a):
            return tuple(tuple(float(x) for x in row) for row in np.reshape(a, (3, 3)))

        free = kinds[int(r[1])] == JointKind.FREE_FLYER
        out.append(TreeJoint(name="", parent=int(r[0]), kind=kinds[int(r[1])],
                             rotation=matrix(r[5:14]), translation=tuple(map(float, r[14:17])),
                             axis=tuple(map(float, r[17:20])),
                             coordinate=-1 if free else int(r[2]),
                             multiplier=float(r[3]), offset=float(r[4]), mass=float(r[20]),
                             first_moment=tuple(map(float, r[21:24])), inertia=matrix(r[24:33])))
    return tuple(out)


@lru_cache(maxsize=1)
def kernel_key() -> str:
    """The module's key: its C source (and this file), never a tree."""
    here = Path(__file__)
    return "compact-tree-kernel\n" + hashlib.sha256(
        b"".join(path.read_bytes() for path in (*_SOURCES, here, here.with_name("tree_c.py"))
                 )).hexdigest()


def kernel_module():
    """The compiled compact kernel (built once, then from the verified cache)."""
    from ..compile import compiled
    from ..compile.codegen import GeneratedSource

    return compiled.load_keyed(kernel_key(), lambda: GeneratedSource(
        source=_source(), parameters=(), n=0, m=0), native=True)


class CompactDynamics(RecursiveDynamics):
    """A tree's recursive dynamics on the compact kernel, batched over leading axes (SI units);
    the functions of recursive.RecursiveDynamics, the tree ``description`` their last argument."""

    kernel = "compact"

    def __init__(self, model: Model, tree: KinematicTree,
                 parameters: Mapping[str, float] | None = None):
        self._take_tree(model, tree, parameters)
        self.module = kernel_module()
        self.description = describe(tree, self.parameters)
        m, D = self.module, self.description
        self._mass, self._bias, self._gravity = m.mass_matrix, m.bias_forces, m.gravity
        self._inverse, self._forward = m.inverse_dynamics, m.forward_dynamics
        self._kinetic, self._potential = m.kinetic_energy, m.potential_energy
        self._P = D

    def __repr__(self) -> str:
        return f"CompactDynamics(coordinates={list(self.coordinates)})"

    def numeric_system(self):
        """The NumericSystem over this kernel (M, f = -b, energy, accelerations, rhs)."""
        from ..compile.functions import NumericSystem

        if self.tree.floating_base:  # q and v differ in length: simulate_floating steps it
            from .recursive_numpy import floating_refusal

            raise floating_refusal()
        return NumericSystem(coordinates=self.coordinates, constraint_names=(),
                             constraint_kinds=(), parameters=dict(self.parameters),
                             _kernel=_CompactKernel(self))


class _CompactKernel:
    """NumericSystem's kernel over the compact module (no constraints: m = 0)."""

    backend = "compact"  # not "c": the module has no DOP853 loop of its own (scipy steps)

    def __init__(self, dynamics: CompactDynamics):
        self.m, self.D, self.n = dynamics.module, dynamics.description, dynamics.n

    def _plain(self, out):
        return out[0] if out.__class__ is tuple else out

    def parts(self, Q, V, T):
        count = len(Q)
        return (self._plain(self.m.mass_matrix(Q, self.D)),
                -self._plain(self.m.bias_forces(Q, V, self.D)),
                np.zeros((count, 0, self.n)), np.zeros((count, 0)))

    def residual(self, Q, V, T):
        return np.zeros((len(Q), 0))

    def energy(self, Q, V, T):
        return (self._plain(self.m.kinetic_energy(Q, V, self.D))
                + self._plain(self.m.potential_energy(Q, self.D)))

    def accelerations(self, Q, V, T):
        qdd = self._plain(self.m.forward_dynamics(Q, V, np.zeros_like(Q), self.D))
        return qdd, np.zeros((len(Q), 0))

    def rhs(self, t, y):
        y = np.asarray(y, dtype=float)
        n = self.n
        if y.shape != (2 * n,):
            raise ValueError(f"y must hold {2 * n} numbers [q, q_dot]")
        qdd = self._plain(self.m.forward_dynamics(y[:n], y[n:], np.zeros(n), self.D))
        return np.concatenate([y[n:], qdd])


__all__ = ["COMPACT_ABOVE", "CompactDynamics", "JOINT_CODES", "describe", "joints_of",
           "kernel_module"]
