"""The compact tree kernel: one compiled module (tree_kernel.c) for every tree, the tree given
at run time as one array of doubles, so a 200-joint chain needs no code of its own and a link's
mass, centre of mass or inertia changes without a rebuild.

The description ``D`` (float64, contiguous), built by ``describe``:

    D[0] nb bodies, D[1] n the joints' velocity numbers (their coordinates, but 3 for a ball
    joint's 4 configuration numbers), D[2:5] the gravity vector g * direction (world
    axes, m/s^2), D[5] 1 where a coordinate drives more than one body (mimic joints): forward
    dynamics by Cholesky of M instead of the articulated-body algorithm, D[6] 1 for a
    floating base (body 0 on a free flyer: q of n + 7 numbers, v of n + 6, free_flyer.py's
    layout), D[7] the quaternion-norm tolerance (free_flyer.QUATERNION_TOLERANCE);
    D[8:8+n] the actuator parameters tau_<joint> (N m or N), acting as loads, one per velocity
    number;
    then nb records of STRIDE = 64 numbers, parent first (parent < own index), each in its
    joint's canonical axes (below):
      0 parent (-1 the ground)  1 kind code (JOINT_CODES)  2 the index c of its (first)
      velocity number among the joints'; 40 that of its (first) configuration number
      3 multiplier k  4 offset (theta = k q[c] + offset)  5:14 R0 (joint -> parent axes,
      row-major)  14:17 t0 (m)  17:20 unit axis u, always (0, 0, 1)  20 mass (kg)
      21:24 first moment h = m c about the body origin (kg m)  24:33 J_O (kg m^2, body axes)
      33:36 where R0 is a signed permutation, the column of each row's one nonzero, 36:39 its
      sign, 39 1 then (else 0: R0 is read as its nine numbers), 41:44 then for each column
      k the row whose nonzero is there, 44:47 its sign  47:56 A (canonical -> the joint's
      own body axes, row-major: what a result per the link's own inertial turns by)  56 1 where R0
      is exactly the identity (a free flyer's or a ball's turn then needs no product)  57:61 spare
      61 the lead: the slide along u per unit theta (1 prismatic, the pitch in m/rad
      helical, 0 revolute)  62 the engine's own: a module's copy marks the kind there
      (joint.h's TK_FLAGS)  63 spare.
      A free flyer (code 2, body 0 only) reads R0, t0 and the inertia alone; one below the
      root (code 5, FLYER: a URDF floating joint between two links) reads R0, t0, the inertia
      and its q (x y z qx qy qz qw) and v (linear, angular) offsets; a helical joint
      (code 3) turns as a revolute one and slides by its lead; a ball joint (code 4,
      spherical.py) reads R0, t0, the inertia and its q (w x y z) and v offsets, in its own
      axes (no canonical turn: its velocity is in the child's axes).

Canonical axes: each body's axes are turned by a fixed A (A e_z = u, a signed permutation
for an axis along a joint axis' own x, y or z) so that every joint turns and slides about z:
R = R0 Rot(z, theta) is 12 products, or none where R0 is a signed permutation (a URDF's
quarter turns), and S has one nonzero. M, the energies and every generalized force are the
same in any body axes; R0 becomes A_parent^T R0 A, t0 A_parent^T t0, h A^T h, J A^T J A. A
rotation within 1e-14 of a signed permutation is taken as that permutation.

A new joint kind is a new code in JOINT_CODES (tests/dynamics/test_joint_kinds.py walks each)
and its branch in engine/joint.h (jt_place for the placement, tk_subspace for S), which every
compiled module reads D with (the tree kernel, the reach module); the recursions themselves ask
only for those. Each module is keyed by its source and the headers alone, never the tree's
numbers.
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
QCOORD = 40  # a record's configuration index (tree_kernel.c's TK_QCOORD)
AXES = 47  # a record's A, canonical -> own body axes (joint.h's TK_AXES)
IDENTITY = 56  # a record's flag: R0 exactly 1 (joint.h's TK_IDENTITY)
FLYER = 5  # a free flyer below the root's code (joint.h's TK_FLYER): JointKind.FREE_FLYER's own
# code 2 is the floating base's, whose numbers are the base's, not the joints'


JOINT_CODES = {JointKind.REVOLUTE: 0, JointKind.PRISMATIC: 1, JointKind.FREE_FLYER: 2,
               JointKind.HELICAL: 3, JointKind.SPHERICAL: 4}
# the kinds whose body keeps its own axes (no canonical turn about a joint axis)
_OWN_AXES = (JointKind.FREE_FLYER, JointKind.SPHERICAL)


def canonical_frame(joint: TreeJoint) -> np.ndarray:
    """A (3x3, joint axes -> canonical axes) with A e_z = u: exact where u is a signed basis
    vector; the identity for a free flyer and a ball joint."""
    if JointKind(joint.kind) in _OWN_AXES:
        return np.eye(3)
    u = np.array(joint.axis, dtype=float)
    u = u / np.linalg.norm(u)
    a = np.zeros(3)
    a[int(np.argmin(np.abs(u)))] = 1.0  # the basis vector least along u
    x = a - (a @ u) * u
    x = x / np.linalg.norm(x)
    return np.column_stack([x, np.cross(u, x), u])


def _signed_permutation(R: np.ndarray) -> np.ndarray | None:
    """R snapped to a signed permutation where it is one within 1e-14, else None."""
    snapped = np.where(np.abs(R) < 1e-14, 0.0, np.where(np.abs(np.abs(R) - 1.0) < 1e-14,
                                                        np.sign(R), np.nan))
    if np.isnan(snapped).any() or not (np.count_nonzero(snapped, axis=1) == 1).all() \
            or not (np.count_nonzero(snapped, axis=0) == 1).all():
        return None
    return snapped


def describe(tree: KinematicTree, parameters: Mapping[str, float]) -> np.ndarray:
    """The tree as the kernel's array D (layout above, canonical axes), with the parameters'
    values (g and the actuators) in SI units."""
    n, nb = len(tree.velocity_coordinates), len(tree.joints)
    D = np.zeros(HEADER + n + nb * STRIDE)
    D[0], D[1] = nb, n
    D[2:5] = float(parameters.get(tree.gravity_parameter, 0.0)) * np.array(tree.gravity_direction)
    coordinates = [j.coordinate for j in tree.joints if j.coordinate >= 0]
    D[5] = float(len(set(coordinates)) < len(coordinates))  # a mimic joint's shared coordinate
    D[6], D[7] = float(tree.floating_base), QUATERNION_TOLERANCE
    D[HEADER:HEADER + n] = [float(parameters.get(a, 0.0)) for a in tree.actuators]  # None: 0
    frames = [canonical_frame(j) for j in tree.joints]
    for i, j in enumerate(tree.joints):
        r = D[HEADER + n + i * STRIDE:HEADER + n + (i + 1) * STRIDE]
        A, Ap = frames[i], (frames[j.parent] if j.parent >= 0 else np.eye(3))
        inner = JointKind(j.kind) == JointKind.FREE_FLYER and j.coordinate >= 0
        r[0], r[1] = j.parent, FLYER if inner else JOINT_CODES[JointKind(j.kind)]
        r[2] = tree.velocity_index(j.coordinate) if j.coordinate >= 0 else 0
        r[QCOORD] = max(j.coordinate, 0)
        r[3], r[4] = j.multiplier, j.offset
        R0 = Ap.T @ np.array(j.rotation, dtype=float) @ A
        permutation = _signed_permutation(R0)
        if permutation is not None and JointKind(j.kind) != JointKind.SPHERICAL and not inner:
            R0 = permutation
            columns = np.argmax(np.abs(permutation), axis=1)
            r[33:36], r[36:39], r[39] = columns, permutation[np.arange(3), columns], 1.0
            rows = np.argmax(np.abs(permutation), axis=0)  # column k's nonzero row
            r[41:44], r[44:47] = rows, permutation[rows, np.arange(3)]
        r[5:14] = np.ravel(R0)
        r[IDENTITY] = float(np.array_equal(R0, np.eye(3)))
        r[14:17] = Ap.T @ np.array(j.translation, dtype=float)
        r[17:20] = (0.0, 0.0, 1.0) if JointKind(j.kind) not in _OWN_AXES else j.axis
        r[20], r[21:24] = j.mass, A.T @ np.array(j.first_moment, dtype=float)
        r[AXES:AXES + 9] = np.ravel(A)
        r[24:33] = np.ravel(A.T @ np.array(j.inertia, dtype=float) @ A)
        model = JOINT_MODELS[JointKind(j.kind)]
        r[LEAD] = model.lead(j.pitch) if hasattr(model, "lead") else 0.0
    D.flags.writeable = False
    return D


def joints_of(D: np.ndarray) -> tuple[TreeJoint, ...]:
    """The bodies of a description as TreeJoints (names left empty, canonical axes): what the
    numpy twin (recursive_numpy.py) reads, so that both compute from the same array."""
    kinds = {code: kind for kind, code in JOINT_CODES.items()} | {FLYER: JointKind.FREE_FLYER}
    nb, n = int(D[0]), int(D[1])
    out = []
    for i in range(nb):
        r = D[HEADER + n + i * STRIDE:HEADER + n + (i + 1) * STRIDE]

        def matrix(a):
            return tuple(tuple(float(x) for x in row) for row in np.reshape(a, (3, 3)))

        free = int(r[1]) == JOINT_CODES[JointKind.FREE_FLYER]  # the base's (FLYER: its own q)
        helical = kinds[int(r[1])] == JointKind.HELICAL
        out.append(TreeJoint(name="", parent=int(r[0]), kind=kinds[int(r[1])],
                             rotation=matrix(r[5:14]), translation=tuple(map(float, r[14:17])),
                             axis=tuple(map(float, r[17:20])),
                             coordinate=-1 if free else int(r[QCOORD]),
                             multiplier=float(r[3]), offset=float(r[4]), mass=float(r[20]),
                             first_moment=tuple(map(float, r[21:24])), inertia=matrix(r[24:33]),
                             pitch=float(r[LEAD]) if helical else 0.0))
    return tuple(out)


__all__ = ["AXES", "FLYER", "HEADER", "IDENTITY", "JOINT_CODES", "LEAD", "QCOORD", "STRIDE",
           "canonical_frame", "describe", "joints_of"]
