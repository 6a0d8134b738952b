"""The derivatives of a tree's dynamics in compiled C: d tau/dq, d tau/dq_dot of Newton-Euler
and d q_ddot/dq, d q_ddot/dq_dot, M^-1 of forward dynamics (derivatives_kernel.c: analytic,
O(n^2) per state; a floating base's q derivatives along its own axes, q (+) dq, as Pinocchio's),
and the joint-torque regressor Y; a batch in one call on vector lanes and threads
(derivatives_bindings.c). One compiled module for every tree (keyed by its C and this file,
never a tree's numbers): the tree is given at run time as two tables, made once per dynamics
object, and gravity, the actuator parameters tau_<joint> and the bodies' inertials as P
(runtime_values). Revolute, prismatic, helical and ball joints and free flyers (at the root, or
below it: a ball or a flyer below the root as one record per column, ``description``); the
complex step of derivatives.py is the fallback (no compiler) and the check. Units SI.

The tree reaches it as its description D (tree/description.py, the tree kernel's: each joint
in canonical axes, placed by joint.h) and one table of its pattern (``tables``), nb bodies
numbered parents first, nj joint coordinates, a floating base's six velocity coordinates first
(nv = nj + 6 ff, nq = nj + 7 ff, and one more per ball joint or free flyer below the root):

    I (int32): nb, nj, ff (1: body 0 a free flyer), np pairs, nnz pattern entries, ltdl (1:
    M factored along the tree), once (1: each coordinate one body's), sparse (1: the lanes'
    products over the pattern); then pairs[np][2] (k, j: j on k's path to the ground, k itself
    first), row0[nv + 1] and rows[nnz] (column j's rows that d tau/d(q, q_dot) can have
    nonzero: rows[row0[j] .. row0[j + 1]], ascending), lambda[nv] (each coordinate's parent
    coordinate, -1 at a root).
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping
from functools import partial
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ...kinds import JointKind
from ...model.tree import KinematicTree
from ..emit.tree_c import _SINCOS, _VECTOR
from ..tree.description import FLYER, HEADER, IDENTITY, JOINT_CODES, STRIDE, describe
from ..tree.free_flyer import QUATERNION_TOLERANCE
from .headers import header_bytes, spliced

_KERNEL = Path(__file__).with_name("derivatives_kernel.c")
_REGRESSOR = Path(__file__).with_name("derivatives_regressor.c")  # the core's last part
_FACTOR = Path(__file__).with_name("derivatives_factor.c")  # at the core's DK_FACTOR line
_BINDINGS = Path(__file__).with_name("derivatives_bindings.c")
_THREADS = Path(__file__).with_name("batch_threads.c")  # the thread count, before the bindings

# the kernel's core on one state, then on LG_LANES states at once (derivatives_kernel.c)
_SCALAR = """#define DK_T double
#define DK_ON_LANES 0
#define DK_FN(name) dk_##name
#define DK_C(x) (x)
#define DK_SINCOS lg_sincos
#define DK_SQRT sqrt
#define DK_MASK int
#define DK_FAILED(d) (!((d) > 0.0))
#define DK_BITS(mask) (mask)"""
_LANES = """#undef DK_T
#undef DK_ON_LANES
#define DK_ON_LANES 1
#undef DK_FN
#undef DK_C
#undef DK_SINCOS
#undef DK_SQRT
#undef DK_FAILED
#undef DK_MASK
#undef DK_BITS
#define DK_T lg_v4
#define DK_FN(name) dk4_##name
#define DK_C(x) LG_V4(x)
#define DK_SINCOS lg_vsincos
#define DK_SQRT lg_vsqrt
/* the lanes where !(d > 0) as a vector of 0 / -1, made bits once at the end */
typedef long long dk4_mask __attribute__((vector_size(sizeof(lg_v4))));
#define DK_MASK dk4_mask
#define DK_FAILED(d) (~(dk4_mask)((d) > LG_V4(0.0)))
#define DK_BITS(mask) dk4_bits(mask)
static inline int dk4_bits(dk4_mask mask)
{
    int bits = 0;
    for (int l = 0; l < LG_LANES; l++) bits |= (mask[l] != 0) << l;
    return bits;
}"""


# a record of a joint of several columns made one per column (joint.h's TK_COLUMN): 1, 2, 3 a
# ball's x, y, z; 1 to 6 a free flyer below the root's (its twist in its own axes: linear x, y,
# z, then angular)
COLUMN = 57


def _columns_of(records: np.ndarray) -> np.ndarray:
    """Each record's joint's velocity numbers: a ball's 3, a free flyer's below the root 6,
    else 1."""
    kinds = records[:, 1]
    return np.where(kinds == JOINT_CODES[JointKind.SPHERICAL], 3, np.where(kinds == FLYER, 6, 1))


def description(tree: KinematicTree, parameters: Mapping[str, float]) -> np.ndarray:
    """The tree's description D (describe) as this module reads it: each ball joint's and each
    free flyer below the root's one record made one per column of its body's twist in its own
    axes (a chain of one-column records, the first placed as the joint, the others at its pose;
    the body's inertial on the last, which its children hang from), so that every record drives
    one velocity number, as the kernel's pairs take them (derivatives_kernel.c: each column
    moves the subtree rigidly, from the joint's parent's motion)."""
    D = describe(tree, parameters)
    n, nb = int(D[1]), int(D[0])
    records = D[HEADER + n:].reshape(nb, STRIDE)
    columns = _columns_of(records)
    if (columns == 1).all():
        return D
    out, index = [], {}  # index: each old body's new one (a split joint's: its last column's)
    for i, record in enumerate(records):
        parent = int(record[0])
        record = record.copy()
        record[0] = index[parent] if parent >= 0 else -1
        if columns[i] == 1:
            index[i] = len(out)
            out.append(record)
            continue
        last = int(columns[i])
        for column in range(1, last + 1):
            r = record.copy()
            r[COLUMN], r[2] = column, record[2] + column - 1
            if column > 1:  # at the joint's pose: no turn, no offset of its own
                r[0] = len(out) - 1
                r[5:14], r[14:17], r[IDENTITY] = np.eye(3).ravel(), 0.0, 1.0
            if column < last:  # massless: the body's inertial is the last column's
                r[20:33] = 0.0
            out.append(r)
        index[i] = len(out) - 1
    D = np.concatenate([D[:HEADER + n], np.ravel(out)])
    D[0] = len(out)
    D.flags.writeable = False
    return D


def _bodies(D: np.ndarray) -> tuple[list[int], list[int], bool]:
    """Each record's parent and velocity number (a floating base's body 0: -1), and whether
    body 0 is a floating base."""
    n, nb = int(D[1]), int(D[0])
    records = D[HEADER + n:].reshape(nb, STRIDE)
    floating = bool(D[6])
    parents = [int(r[0]) for r in records]
    coordinates = [-1 if floating and b == 0 else int(r[2]) for b, r in enumerate(records)]
    return parents, coordinates, floating


def _pairs(parents: list[int]) -> list[tuple[int, int]]:
    """(k, j) for every body k and each j on its path to the ground, k itself first."""
    out = []
    for k in range(len(parents)):
        j = k
        while j >= 0:
            out.append((k, j))
            j = parents[j]
    return out


def _column_rows(coordinates: list[int], floating: bool, n: int,
                 pairs: list[tuple[int, int]]) -> list[list[int]]:
    """For each coordinate j, the coordinates k whose d tau_k/dq_j, d tau_k/dq_dot_j can be
    nonzero: the entries the kernel's pairs write (a path to the ground through both joints; a
    floating base's six with every coordinate), ascending."""
    base = range(6) if floating else range(0)

    def of(body: int):
        if floating and body == 0:
            return base
        return [6 * floating + coordinates[body]]

    rows: list[set[int]] = [set() for _ in range(n + 6 * floating)]
    for k, j in pairs:
        for a in of(k):
            for b in of(j):
                rows[b].add(a)
                rows[a].add(b)
    return [sorted(r) for r in rows]


def _coordinate_parents(parents: list[int], coordinates: list[int], floating: bool,
                        n: int) -> list[int] | None:
    """Each velocity coordinate's parent coordinate (-1 at a root; a floating base's six a chain
    under which its children hang), or None where the coordinates are not a tree numbered
    parents first, one body each (a mimic joint's coordinate moves two bodies)."""
    out = [c - 1 for c in range(6)] if floating else []
    out += [None] * n
    for b, (p, coordinate) in enumerate(zip(parents, coordinates, strict=True)):
        if floating and b == 0:
            continue
        c = 6 * floating + coordinate
        parent = -1 if p < 0 else 5 if floating and p == 0 else 6 * floating + coordinates[p]
        if out[c] is not None or parent >= c:
            return None
        out[c] = parent
    return None if None in out else out


def factored_along_the_tree(tree: KinematicTree,
                            parents: list[int] | None = None) -> list[int] | None:
    """The coordinates' parents where forward dynamics' M is factored along the tree (M =
    L^T D L, no fill-in: derivatives_factor.c's ltdl_factor) rather than by a dense Cholesky: a
    tree that branches (two legs, or more), its coordinates one body's each, numbered parents
    first; else None. On a chain both do the same work and the dense loops are the simpler.
    ``parents``: the coordinates' parents (_coordinate_parents), where the caller has them."""
    if parents is None:
        D = description(tree, {})
        parents = _coordinate_parents(*_bodies(D), int(D[1]))
    if parents is None:
        return None
    children = [parents.count(c) for c in range(-1, len(parents))]
    return parents if max(children) > 1 else None


def tables(tree: KinematicTree) -> np.ndarray:
    """The tree's I (int32), laid out as this module's docstring says, over the records of
    its description (``description``: a ball joint's three)."""
    D = description(tree, {})
    nb, nj = int(D[0]), int(D[1])
    body_parents, coordinates, floating = _bodies(D)
    nv = nj + 6 * floating
    pairs = _pairs(body_parents)
    rows = _column_rows(coordinates, floating, nj, pairs)
    starts = np.cumsum([0] + [len(r) for r in rows])
    # on the lanes, the products -M^-1 d tau/dq, -M^-1 d tau/dq_dot skip the zero entries where
    # a quarter or more are zero (a floating base's legs: 36% fewer multiply-adds on Solo12); a
    # denser pattern (a serial arm: none) keeps the row by row loops
    sparse = starts[-1] <= 0.75 * nv ** 2
    # None where a coordinate moves two bodies (mimic)
    one_body = _coordinate_parents(body_parents, coordinates, floating, nj)
    parents = factored_along_the_tree(tree, one_body)
    header = [nb, nj, int(floating), len(pairs), int(starts[-1]), int(parents is not None),
              int(one_body is not None), int(sparse)]
    I = np.concatenate([
        header, np.ravel(np.array(pairs, dtype=int)), starts, [k for r in rows for k in r],
        parents if parents is not None else [-1] * nv]).astype(np.int32)
    I.flags.writeable = False
    return I


def kernel_source():
    """The module's C: derivatives_kernel.c's core on one state and on the lanes, the thread
    count and the bindings; the same for every tree."""
    from ...compile.codegen import GeneratedSource

    text = _KERNEL.read_text(encoding="utf-8")
    head, rest = text.split("/* DK_CORE_BEGIN */")
    core = rest.split("/* DK_CORE_END */")[0] + _REGRESSOR.read_text(encoding="utf-8")
    marker = "/* DK_FACTOR: derivatives_factor.c, here"
    at = core.index(marker)
    core = core[:at] + _FACTOR.read_text(encoding="utf-8") + core[core.index("\n", at):]
    bindings = _THREADS.read_text(encoding="utf-8") + _BINDINGS.read_text(encoding="utf-8")
    source = "\n".join([
        "/* lagrangian: the derivatives of a tree's inverse and forward dynamics */",
        "#define PY_SSIZE_T_CLEAN",
        "#include <Python.h>",
        "#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION",
        "#include <numpy/arrayobject.h>",
        "#include <math.h>",
        "#include <stdlib.h>",
        "#include <string.h>",
        f"#define DK_QTOL {QUATERNION_TOLERANCE!r}",
        _SINCOS, _VECTOR,
        head, _SCALAR, core, _LANES, core, bindings,
    ])
    source = spliced(source)
    return GeneratedSource(source=source, parameters=(), n=0, m=0)


def applies(tree: KinematicTree | None) -> bool:
    """Whether the kernel takes this tree: revolute, prismatic, helical and ball joints and free
    flyers (at the root: a floating base; or below it), of any size."""
    if tree is None or not tree.joints:
        return False
    kinds = [j.kind for j in tree.joints]
    if tree.floating_base and kinds[0] != JointKind.FREE_FLYER:
        return False
    return all(k in (JointKind.REVOLUTE, JointKind.PRISMATIC, JointKind.HELICAL,
                      JointKind.SPHERICAL, JointKind.FREE_FLYER) for k in kinds)


def engine():
    """The one compiled module for every tree (built once per installation, then from the
    verified cache), or None where no compiler works."""
    from ...compile import compiled

    generated = kernel_source()
    key = "\n".join(["derivatives", hashlib.sha256(
        generated.source.encode() + Path(__file__).read_bytes() + header_bytes()).hexdigest()])
    try:
        return compiled.load_keyed(key, lambda: generated, native=True)
    except compiled.BackendUnavailable:
        return None


class TreeDerivatives(NamedTuple):
    """The engine's functions bound to one tree: each takes (Q, V, X, P)."""

    inverse_derivatives: partial
    forward_derivatives: partial
    regressor: partial
    module: object


def derivatives_module(tree: KinematicTree) -> TreeDerivatives | None:
    """The engine's functions on this tree (its tables made now, once), or None where no
    compiler works or the kernel does not take the tree."""
    if not applies(tree):
        return None
    module = engine()
    if module is None:
        return None
    D = description(tree, {})
    handle = module.tree(D, tables(tree))
    regressor = partial(module.regressor, handle)  # the tree's bodies' columns alone
    return TreeDerivatives(partial(module.inverse_derivatives, handle),
                           partial(module.forward_derivatives, handle), regressor, module)


def runtime_values(tree: KinematicTree, parameters: Mapping[str, float]) -> np.ndarray:
    """P = [g times the tree's direction (m/s^2, 3), tau_<joint> (N m or N, one per
    coordinate; 0 where none), then per body m (kg), h = m c (kg m, 3) and J_O (kg m^2, 9,
    about its origin)], read-only: the description's numbers (describe), each body's in its
    canonical axes, as the kernel places it."""
    D = description(tree, parameters)
    n, nb = int(D[1]), int(D[0])
    records = D[HEADER + n:].reshape(nb, STRIDE)
    P = np.concatenate([D[2:5], D[HEADER:HEADER + n], records[:, 20:33].ravel()])
    P.flags.writeable = False
    return P


__all__ = ["COLUMN", "applies", "derivatives_module", "description", "engine", "kernel_source",
           "runtime_values", "tables"]
