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
    then nb records of STRIDE = 64 numbers, parent first (parent < own index):
      0 parent (-1 the ground)  1 kind code (JOINT_CODES)  2 coordinate index c
      3 multiplier k  4 offset (theta = k q[c] + offset)  5:14 R0 (joint -> parent axes,
      row-major)  14:17 t0 (m)  17:20 unit axis u (joint axes)  20 mass (kg)
      21:24 first moment h = m c about the body origin (kg m)  24:33 J_O (kg m^2, body axes)
      33:60 a revolute joint's turn tables P = R0 u u^T, C = R0 (1 - u u^T), S = R0 [u]x
      (row-major each: R0 Rot(u, theta) = P + cos theta C + sin theta S; every kind's)
      60 spare  61 the lead: the slide along u per unit theta (1 prismatic, the pitch in m/rad
      helical, 0 revolute)  62:64 spare.
      A free flyer (code 2, body 0 only) reads R0, t0 and the inertia alone; a helical joint
      (code 3) turns as a revolute one and slides by its lead.

A new joint kind is a new code in JOINT_CODES (tests/dynamics/test_joint_kinds.py walks each)
and its cases in tree_kernel.c (tk_place for the
placement, tk_subspace for S); the recursions themselves ask only for those. The module
(tree_kernel.c, tree_kernel_forward.c, then its Python bindings tree_kernel_bindings.c) is keyed
by its source alone, never the tree's numbers.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ...kinds import JointKind
from ...model.tree import KinematicTree, TreeJoint
from .free_flyer import QUATERNION_TOLERANCE
from .joint_models import JOINT_MODELS

HEADER, STRIDE = 8, 64
LEAD = 61  # a record's slide per unit theta (tree_kernel.c's TK_LEAD)


JOINT_CODES = {JointKind.REVOLUTE: 0, JointKind.PRISMATIC: 1, JointKind.FREE_FLYER: 2,
               JointKind.HELICAL: 3}


def describe(tree: KinematicTree, parameters: Mapping[str, float]) -> np.ndarray:
    """The tree as the kernel's array D (layout above), with the parameters' values (g and the
    actuators) in SI units."""
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
        model = JOINT_MODELS[JointKind(j.kind)]
        r[LEAD] = model.lead(j.pitch) if hasattr(model, "lead") else 0.0
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
        helical = kinds[int(r[1])] == JointKind.HELICAL
        out.append(TreeJoint(name="", parent=int(r[0]), kind=kinds[int(r[1])],
                             rotation=matrix(r[5:14]), translation=tuple(map(float, r[14:17])),
                             axis=tuple(map(float, r[17:20])),
                             coordinate=-1 if free else int(r[2]),
                             multiplier=float(r[3]), offset=float(r[4]), mass=float(r[20]),
                             first_moment=tuple(map(float, r[21:24])), inertia=matrix(r[24:33]),
                             pitch=float(r[LEAD]) if helical else 0.0))
    return tuple(out)


__all__ = ["HEADER", "JOINT_CODES", "LEAD", "STRIDE", "describe", "joints_of"]
