"""The derivatives of a tree's dynamics in compiled C: d tau/dq, d tau/dq_dot of Newton-Euler
and d q_ddot/dq, d q_ddot/dq_dot, M^-1 of forward dynamics (derivatives_kernel.c: analytic,
O(n^2) per state; a floating base's q derivatives along its own axes, q (+) dq, as Pinocchio's),
and the joint-torque regressor Y (fixed base); a batch in one call on vector lanes and
threads (derivatives_bindings.c), over the tree's joints written as static tables, one module
per tree's kinematics (cached on disk by its numbers). Gravity, the actuator parameters
tau_<joint> and the bodies' inertials are given at run time. Revolute and prismatic joints;
the complex step of derivatives.py is the fallback (and the check). Units SI."""

from __future__ import annotations

import hashlib
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ..compile.codegen import c_table
from ..model.tree import KinematicTree
from .free_flyer import QUATERNION_TOLERANCE
from .joint_models import JOINT_MODELS
from .tree_c import _SINCOS, _VECTOR

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


def _flat(matrix) -> list[float]:
    return [float(x) for row in matrix for x in row]


def _pairs(tree: KinematicTree) -> list[tuple[int, int]]:
    """(k, j) for every body k and each j on its path to the ground, k itself first."""
    out = []
    for k in range(len(tree.joints)):
        j = k
        while j >= 0:
            out.append((k, j))
            j = tree.joints[j].parent
    return out


def _column_rows(tree: KinematicTree, pairs: list[tuple[int, int]]) -> list[list[int]]:
    """For each coordinate j, the coordinates k whose d tau_k/dq_j, d tau_k/dq_dot_j can be
    nonzero: the entries the kernel's pairs write (a path to the ground through both joints; a
    floating base's six with every coordinate), ascending."""
    floating = bool(tree.floating_base)
    base = range(6) if floating else range(0)

    def coordinates(body: int):
        if floating and body == 0:
            return base
        return [6 * floating + tree.joints[body].coordinate]

    n = len(tree.coordinates) + 6 * floating
    rows: list[set[int]] = [set() for _ in range(n)]
    for k, j in pairs:
        for a in coordinates(k):
            for b in coordinates(j):
                rows[b].add(a)
                rows[a].add(b)
    return [sorted(r) for r in rows]


def _coordinate_parents(tree: KinematicTree) -> list[int] | None:
    """Each velocity coordinate's parent coordinate (-1 at a root; a floating base's six a chain
    under which its children hang), or None where the coordinates are not a tree numbered
    parents first, one body each (a mimic joint's coordinate moves two bodies)."""
    floating = bool(tree.floating_base)
    n = len(tree.coordinates) + 6 * floating
    parents = [c - 1 for c in range(6)] if floating else []
    parents += [None] * (n - len(parents))
    for b, joint in enumerate(tree.joints):
        if floating and b == 0:
            continue
        c = 6 * floating + joint.coordinate
        p = joint.parent
        parent = -1 if p < 0 else 5 if floating and p == 0 \
            else 6 * floating + tree.joints[p].coordinate
        if parents[c] is not None or parent >= c:
            return None
        parents[c] = parent
    return None if None in parents else parents


def factored_along_the_tree(tree: KinematicTree,
                            parents: list[int] | None = None) -> list[int] | None:
    """The coordinates' parents where forward dynamics' M is factored along the tree (M =
    L^T D L, no fill-in: _tree_factor) rather than by a dense Cholesky: a tree that branches
    (two legs, or more), its coordinates one body's each, numbered parents first; else None.
    On a chain both do the same work and the dense loops are the simpler. ``parents``:
    _coordinate_parents(tree), where the caller has it."""
    if parents is None:
        parents = _coordinate_parents(tree)
    if parents is None:
        return None
    children = [parents.count(c) for c in range(-1, len(parents))]
    return parents if max(children) > 1 else None


def _tree_factor(parents: list[int]) -> str:
    """derivatives_kernel.c's factor, solve and inverse_from_factor for M = L^T D L on this
    tree of coordinates, written out (Featherstone's LTDL: the entries follow the parents)."""
    n = len(parents)

    def chain(c):  # c's ancestors, nearest first
        out = []
        while parents[c] >= 0:
            c = parents[c]
            out.append(c)
        return out

    def at(i, j):
        return f"[{i * n + j}]"

    lines = ["static int DK_FN(factor)(DK_T *restrict H, DK_T *restrict inverse)", "{",
             "    DK_MASK failed = {0};"]
    for k in reversed(range(n)):
        lines.append(f"    {{ const DK_T d = H{at(k, k)}; failed |= DK_FAILED(d); "
                     f"const DK_T r = 1.0 / d; inverse[{k}] = r;")
        for i in chain(k):
            updates = " ".join(f"H{at(i, j)} -= a * H{at(k, j)};" for j in [i, *chain(i)])
            lines.append(f"      {{ const DK_T a = H{at(k, i)} * r; {updates} H{at(k, i)} = a; }}")
        lines.append("    }")
    lines += ["    return DK_BITS(failed);", "}", "",
              "static void DK_FN(solve)(const DK_T *restrict L, const DK_T *restrict inverse, "
              "DK_T *restrict b)", "{"]
    for i in reversed(range(n)):
        lines += [f"    b[{j}] -= L{at(i, j)} * b[{i}];" for j in chain(i)]
    lines += [f"    b[{i}] *= inverse[{i}];" for i in range(n)]
    for i in range(n):
        if chain(i):
            terms = " + ".join(f"L{at(i, j)} * b[{j}]" for j in chain(i))
            lines.append(f"    b[{i}] -= {terms};")
    lines += ["}", "",
              "static void DK_FN(inverse_from_factor)(const DK_T *restrict L, "
              "const DK_T *restrict inverse, DK_T *restrict Minv)", "{",
              f"    DK_T W[{n * n}];"]
    for i in range(n):  # W = L^-1, row by row: W_ik = -sum over m between of L_im W_mk
        for k in chain(i):
            terms = [f"L{at(i, k)}"] + [f"L{at(i, m)} * W{at(m, k)}"
                                        for m in chain(i) if m != k and k in chain(m)]
            lines.append(f"    W{at(i, k)} = -({' + '.join(terms)});")
    for i in range(n):
        for j in range(i + 1):
            common = [c for c in [i, *chain(i)] if c in [j, *chain(j)]]

            def w(row, k):
                return "" if row == k else f" * W{at(row, k)}"

            terms = [f"inverse[{k}]{w(i, k)}{w(j, k)}" for k in common]
            value = " + ".join(terms) if terms else "DK_C(0.0)"
            lines.append(f"    Minv{at(i, j)} = {value};" if i == j else
                         f"    Minv{at(i, j)} = Minv{at(j, i)} = {value};")
    lines.append("}")
    return "\n".join(lines)


def kernel_source(tree: KinematicTree):
    """The module's C: the tree's tables, then derivatives_kernel.c."""
    from ..compile.codegen import GeneratedSource

    joints = tree.joints
    P, C, S = [], [], []
    for j in joints:  # R0 Rot(u, th) = R0 u u^T + cos th R0 (1 - u u^T) + sin th R0 [u]x
        R0, u = np.array(j.rotation, dtype=float), np.array(j.axis, dtype=float)
        uu = np.outer(u, u)
        skew = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
        P.append((R0 @ uu).ravel().tolist())
        C.append((R0 @ (np.eye(3) - uu)).ravel().tolist())
        S.append((R0 @ skew).ravel().tolist())
    models = [JOINT_MODELS[j.kind] for j in joints]
    n = len(tree.coordinates)
    floating = int(bool(tree.floating_base))
    pairs = _pairs(tree)
    rows = _column_rows(tree, pairs)
    starts = np.cumsum([0] + [len(r) for r in rows]).tolist()
    # on the lanes, the products -M^-1 d tau/dq, -M^-1 d tau/dq_dot skip the zero entries where
    # a quarter or more are zero (a floating base's legs: 36% fewer multiply-adds on Solo12); a
    # denser pattern (a serial arm: none) keeps the row by row loops, unrolled whole on an arm
    sparse = starts[-1] <= 0.75 * (n + 6 * floating) ** 2
    one_body = _coordinate_parents(tree)  # None where a coordinate moves two bodies (mimic)
    parents = factored_along_the_tree(tree, one_body)
    text = _KERNEL.read_text(encoding="utf-8")
    head, rest = text.split("/* DK_CORE_BEGIN */")
    core = rest.split("/* DK_CORE_END */")[0] + _REGRESSOR.read_text(encoding="utf-8")
    marker = "/* DK_FACTOR: derivatives_factor.c, here"
    at = core.index(marker)
    core = (core[:at] + _FACTOR.read_text(encoding="utf-8") + core[core.index("\n", at):]).replace(
        "DK_TREE_FACTOR", _tree_factor(parents) if parents is not None else "")
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
        f"#define DK_NB {len(joints)}",
        f"#define DK_NJ {n}",  # the joints' coordinates; a floating base's come first:
        f"#define DK_FF {floating}",
        f"#define DK_QO {7 * floating}",
        f"#define DK_VO {6 * floating}",
        f"#define DK_NQ {n + 7 * floating}",
        f"#define DK_NV {n + 6 * floating}",
        f"#define DK_NP {len(pairs)}",
        f"#define DK_QTOL {QUATERNION_TOLERANCE!r}",
        c_table("dk_parent", "int", [j.parent for j in joints]),
        c_table("dk_coord", "int", [j.coordinate for j in joints]),
        c_table("dk_turns", "int", [getattr(m, "turns", False) for m in models]),
        c_table("dk_slides", "int", [getattr(m, "slides", False) for m in models]),
        c_table("dk_pair", "int", [list(p) for p in pairs]),
        f"#define DK_SPARSE {int(sparse)}",
        c_table("dk_row0", "int", starts),
        c_table("dk_rows", "int", [k for r in rows for k in r]),
        f"#define DK_LTDL {int(parents is not None)}",
        f"#define DK_ONCE {int(one_body is not None)}",
        c_table("dk_mult", "double", [j.multiplier for j in joints]),
        c_table("dk_off", "double", [j.offset for j in joints]),
        c_table("dk_R0", "double", [_flat(j.rotation) for j in joints]),
        c_table("dk_P", "double", P), c_table("dk_C", "double", C), c_table("dk_Sk", "double", S),
        c_table("dk_t0", "double", [list(j.translation) for j in joints]),
        c_table("dk_u", "double", [list(j.axis) for j in joints]),
        c_table("dk_R0u", "double", [(np.array(j.rotation, dtype=float)
                                     @ np.array(j.axis, dtype=float)).tolist() for j in joints]),
        _SINCOS, _VECTOR,
        head, _SCALAR, core, _LANES, core, bindings,
    ])
    return GeneratedSource(source=source, parameters=(), n=len(tree.coordinates), m=0)


# The kernel keeps a state's work on the stack (per body and n x n per output, LG_LANES states
# at once): up to this many bodies and coordinates, about a megabyte; larger trees keep the
# complex step of derivatives.py.
LARGEST = 64


def applies(tree: KinematicTree | None) -> bool:
    """Whether the kernel takes this tree: revolute and prismatic joints on a fixed base or a
    floating one (a free flyer at the root), at most LARGEST bodies and coordinates."""
    from ..kinds import JointKind

    if tree is None or not tree.joints or len(tree.joints) > LARGEST \
            or len(tree.coordinates) > LARGEST:
        return False
    kinds = [j.kind for j in tree.joints]
    if tree.floating_base:
        if kinds[0] != JointKind.FREE_FLYER:
            return False
        kinds = kinds[1:]
    return all(k in (JointKind.REVOLUTE, JointKind.PRISMATIC) for k in kinds)


def derivatives_module(tree: KinematicTree):
    """The compiled module of this tree (built once, then from the verified cache), or None
    where no compiler works or the kernel does not take the tree."""
    from ..compile import compiled

    if not applies(tree):
        return None
    here = Path(__file__)
    generator = hashlib.sha256(_KERNEL.read_bytes() + _FACTOR.read_bytes() + _THREADS.read_bytes()
                               + _BINDINGS.read_bytes() + _REGRESSOR.read_bytes()
                               + here.read_bytes()
                               + here.with_name("tree_c.py").read_bytes()).hexdigest()
    # the joints' kinematics only: the inertials are given at run time (runtime_values), so a
    # payload or an identification's trial inertials reuse the module
    kinematic = [(j.parent, str(j.kind), j.rotation, j.translation, j.axis, j.coordinate,
                  j.multiplier, j.offset) for j in tree.joints]
    key = "\n".join(["derivatives", generator, repr(kinematic), repr(tree.coordinates),
                     repr(bool(tree.floating_base)), repr(QUATERNION_TOLERANCE)])
    try:
        return compiled.load_keyed(key, lambda: kernel_source(tree), native=True)
    except compiled.BackendUnavailable:
        return None


def runtime_values(tree: KinematicTree, parameters: Mapping[str, float]) -> np.ndarray:
    """P = [g times the tree's direction (m/s^2, 3), tau_<joint> (N m or N, one per
    coordinate; 0 where none), then per body m (kg), h = m c (kg m, 3) and J_O (kg m^2, 9,
    about its origin in its axes)], read-only."""
    g = float(parameters.get(tree.gravity_parameter, 0.0) or 0.0) \
        if tree.gravity_parameter is not None else 0.0
    actuators = [float(parameters.get(a, 0.0) or 0.0) if a is not None else 0.0
                 for a in tree.actuators]
    inertials = [[j.mass, *j.first_moment, *_flat(j.inertia)] for j in tree.joints]
    P = np.concatenate([g * np.array(tree.gravity_direction, dtype=float), actuators,
                        np.ravel(np.array(inertials, dtype=float))])
    P.flags.writeable = False
    return P


__all__ = ["applies", "derivatives_module", "kernel_source", "runtime_values"]
