"""J_dot q_dot, the centroidal momentum matrix, wrenches' generalized forces and a floating
base's C(q, v) in compiled C, for the C backend's speed per call: ONE module per installation
(reach_kernel.c and the files after it, with joint.h and spatial.h, keyed by their text and
this file's alone), every tree given at run time as its description D (tree/description.py,
the tree kernel's: each joint in canonical axes, placed by joint.h) and two small tables built
once here (``tables``), read once by the module's ``tree(D, INTS, FLOATS, INDEX)``, whose
methods are the functions. centroidal.py, wrenches.py and coriolis_tree.py are the same
formulas in numpy, used without a compiler and to name every bad input.

The tables of a tree of nv velocity numbers with nf frames:

- INTS (C int): nf, cset, nczero; then nf frame bodies (-1: the ground); then the nczero
  entries of C (row-major, nv x nv) that no body's pass sets. cset is 1 where no mimic joint
  shares a coordinate (each entry of C, A_g, J set once), else 0 (all zeroed, added to).
- FLOATS (float64): the quaternion's bounds on |q|^2, (1 -+ QUATERNION_TOLERANCE)^2; then the
  frames' rotations (9 each, row-major) and translations (3 each, m) in their bodies' canonical
  axes (description.canonical_frame).

INDEX, {frame name: frame number}, names the frames for the Tree's methods. reach_bindings.c
checks D and the tables once (sizes, a parent before its child, indices in range, numbers
finite).
"""

from __future__ import annotations

import hashlib
from functools import lru_cache, partial
from pathlib import Path

import numpy as np

from ...kinds import JointKind
from ...model.tree import KinematicTree
from ..emit.tree_c import _SINCOS, _VECTOR
from ..tree.description import canonical_frame, describe
from ..tree.free_flyer import QUATERNION_TOLERANCE
from ..tree.spherical import quaternion_slices
from .headers import header_bytes, spliced

# the walks, frames and the centre of mass, C(q, v), inverse dynamics with wrenches, then the
# batches and the Python bindings: one module's C, in this order; the first four's core (from
# reach_kernel.c's RK_CORE_BEGIN) twice, on one state and on LG_LANES states at once
_KERNELS = tuple(Path(__file__).with_name(name)
                 for name in ("reach_kernel.c", "reach_frames.c", "reach_coriolis.c",
                              "reach_inverse.c", "batch_threads.c", "reach_batch.c",
                              "reach_bindings.c"))
_CORE = 4
_SCALAR = """#define RK_T double
#define RK_ONE_STATE 1
#define RK_FN(name) rk_##name
#define RK_C(x) (x)
#define RK_SINCOS lg_sincos_inline"""
_LANES = """#undef RK_T
#undef RK_FN
#undef RK_C
#undef RK_SINCOS
#undef RK_ONE_STATE
#define RK_ONE_STATE 0
#define RK_T lg_v4
#define RK_FN(name) rk4_##name
#define RK_C(x) LG_V4(x)
#define RK_SINCOS lg_vsincos_inline"""


def _coriolis_zeros(tree: KinematicTree) -> tuple[bool, list[int]]:
    """Whether each entry of C (and of A_g's, J's columns) is one joint's (cset: no mimic joint
    shares another's coordinate), and the entries of C (row-major, nv x nv) that no body's pass
    sets, those of two joints on different branches (reach_coriolis.c sets the others once each
    and zeroes only these)."""
    free = tree.floating_base
    base = 6 if free else 0
    nv = tree.nv
    # each body's velocity numbers: the base's six, a ball's three, else one
    many = {JointKind.SPHERICAL: 3, JointKind.FREE_FLYER: 6}  # a flyer's below the root
    columns = [list(range(6)) if free and i == 0 else
               [base + tree.velocity_index(j.coordinate) + c
                for c in range(many.get(JointKind(j.kind), 1))]
               for i, j in enumerate(tree.joints)]
    coordinates = [j.coordinate for j in tree.joints[int(free):]]
    shared = len(set(coordinates)) < len(coordinates)
    nb = len(tree.joints)
    lineage = np.eye(nb, dtype=bool)  # [i, a]: a is i or an ancestor of i
    owns = np.zeros((nb, nv))  # [i, c]: column c is body i's joint's
    for i, j in enumerate(tree.joints):
        if j.parent >= 0:
            lineage[i] |= lineage[j.parent]
        owns[i, columns[i]] = 1.0
    related = (lineage | lineage.T).astype(float)
    written = owns.T @ related @ owns > 0.0  # two columns of a body and its ancestor's
    return not shared, np.flatnonzero(~written).tolist()


def tables(tree: KinematicTree) -> tuple[np.ndarray, np.ndarray]:
    """The tree's INTS and FLOATS (this module's docstring), for the module's ``tree``."""
    frames = tree.frames
    cset, zeros = _coriolis_zeros(tree)
    ints = [len(frames), int(cset), len(zeros), *(f.body for f in frames), *zeros]
    # a frame in its body's canonical axes, as D holds the body (A^T R_f, A^T t_f)
    axes = [canonical_frame(tree.joints[f.body]) if f.body >= 0 else np.eye(3) for f in frames]
    rotations = [A.T @ np.array(f.rotation, dtype=float) for A, f in zip(axes, frames, strict=True)]
    translations = [A.T @ np.array(f.translation, dtype=float)
                    for A, f in zip(axes, frames, strict=True)]
    # |quaternion|^2 within (1 -+ QUATERNION_TOLERANCE)^2, else numpy names the fault
    floats = [np.array([(1 - QUATERNION_TOLERANCE) ** 2, (1 + QUATERNION_TOLERANCE) ** 2]),
              np.array(rotations, dtype=float).reshape(-1),
              np.array(translations, dtype=float).reshape(-1)]
    return np.array(ints, dtype=np.intc), np.concatenate(floats)


def kernel_source():
    """The module's C: the kernels of _KERNELS in order, the core twice."""
    from ...compile.codegen import GeneratedSource

    source = "\n".join([
        "/* lagrangian: frame accelerations, centroidal momentum and wrenches of any tree */",
        "#define PY_SSIZE_T_CLEAN",
        "#include <Python.h>",
        "#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION",
        "#include <numpy/arrayobject.h>",
        "#include <math.h>",
        "#include <string.h>",
        _SINCOS, _VECTOR,
    ])
    texts = [path.read_text(encoding="utf-8") for path in _KERNELS]
    head, first = texts[0].split("/* RK_CORE_BEGIN */")
    core = "\n".join([first, *texts[1:_CORE]])
    source = spliced("\n".join([source, head, _SCALAR, core, _LANES, core, *texts[_CORE:]]))
    return GeneratedSource(source=source, parameters=(), n=0, m=0)


@lru_cache(maxsize=1)
def _key() -> str:
    """The module's cache key: its C's text and this generator's, no tree's."""
    text = kernel_source().source.encode() + Path(__file__).read_bytes() + header_bytes()
    return "reach engine\n" + hashlib.sha256(text).hexdigest()


def engine():
    """The one compiled module of every tree (cached on disk by its sources), or None where
    no compiler works."""
    from ...compile import compiled

    try:
        return compiled.load_keyed(_key(), kernel_source, native=True)
    except compiled.BackendUnavailable:
        return None


def reach_module(tree: KinematicTree):
    """The compiled module for this tree (the same for every tree: ``engine``), or None where
    no compiler works or a joint is one the kernel does not know. A ball joint and a free flyer
    below the root are their body's columns (three, six) in every function."""
    from ..tree.joint_models import ONE_DOF

    free = tree.floating_base  # a free flyer: body 0 (RK_FREE), or below the root
    if any(j.kind not in ONE_DOF and j.kind not in (JointKind.SPHERICAL, JointKind.FREE_FLYER)
           for j in tree.joints[int(free):]):
        return None  # a joint the kernel does not know: numpy's walks refuse it in one line
    return engine()


class ReachKernel:
    """The compiled functions with frames by name; inputs of one batch shape (..., n). Each
    returns its output, or (output, count of NaN rows) where a state's inputs are not all
    finite (its whole row NaN: reach_bindings.c); the frame functions NotImplemented for inputs
    they do not take (the front names the fault). The wrench functions still raise."""

    def __init__(self, module, tree: KinematicTree, massive: bool):
        self.module = module
        self.frame_index = {f.name: k for k, f in enumerate(tree.frames)}
        # the tree's description (gravity and actuators unused: 0) and tables read once into
        # the module's Tree (reach_bindings.c); its methods
        # bound here once: each call then goes straight to C
        self.compiled = compiled = module.tree(describe(tree, {}), *tables(tree),
                                               self.frame_index)
        # placement(Q, frame), jacobian(Q, frame, reference) and drift(Q, V, frame, reference)
        # with the frame and reference looked up by name in C: in Python the lookups cost a
        # single Jacobian's call a sixth of its time
        self.placement, self.jacobian = compiled.placement, compiled.jacobian
        self.drift = compiled.drift
        # A_g and the centre of mass need moving mass (else numpy refuses them in one line)
        self.centroidal = compiled.centroidal if massive else None
        self.center_of_mass = compiled.com if massive else None
        self.center_of_mass_jacobian = compiled.com_jacobian if massive else None
        # C by Pinocchio's factorization where v is not q's rate (a floating base, a ball, a free
        # flyer below the root); else C is M's Christoffel symbols (joint_space.py), which the
        # same factorization gives: None until checked_coriolis has compared the two, then the
        # compiled function or False
        manifold = tree.floating_base or bool(tree.quaternion_joints)
        self.coriolis = compiled.coriolis if manifold else None
        self.fixed_coriolis = None if not manifold else False
        self.tree = tree
        # inverse dynamics less wrenches in one pass (q, v, a, f_ext) -> tau: None until
        # fused_inverse has asked, then the compiled function or False
        self.inverse = None

    def checked_coriolis(self, dynamics):
        """A fixed base's C(q, v) compiled (reach_coriolis.c), where it is ``dynamics``' own
        Christoffel C (the rates of M's entries, from its bias forces), checked once at random
        states to 1e-9 relative: not where a parameter or an actuator makes the dynamics' M
        other than the tree's tables; else False (numpy's Christoffel C stays)."""
        if self.fixed_coriolis is not None:
            return self.fixed_coriolis
        self.fixed_coriolis = False
        rng = np.random.default_rng(0)
        q, v = rng.uniform(-1.0, 1.0, (2, 3, dynamics.n))
        ours = self.compiled.coriolis(q, v)
        if ours is NotImplemented:  # inputs it does not take (not these): numpy's C stays
            return False
        ours = np.asarray(ours, dtype=float)
        with np.errstate(all="ignore"):
            christoffel = np.asarray(dynamics._christoffel_coriolis(q, v), dtype=float)
        scale = 1.0 + np.abs(christoffel).max()
        if np.abs(ours - christoffel).max() <= 1e-9 * scale:
            self.fixed_coriolis = self.compiled.coriolis
        return self.fixed_coriolis

    def fused_inverse(self, dynamics):
        """Inverse dynamics less wrenches in one pass for ``dynamics`` (q, v, a, f_ext) -> tau,
        where its numbers are the dynamics' (not where a parameter sets a link's inertial or an
        actuator's force), checked once at random states against the dynamics' own inverse
        dynamics less J^T w (to 1e-9 relative); else False (the two calls stay)."""
        if self.inverse is not None:
            return self.inverse
        tree = self.tree
        g = dynamics.parameters.get(tree.gravity_parameter, 0.0) if tree.gravity_parameter else 0.0
        up = -g * np.array(tree.gravity_direction, dtype=float)  # the ground's acceleration
        one_pass = partial(self.compiled.inverse, up)
        rng = np.random.default_rng(0)
        q = rng.uniform(-1.0, 1.0, (3, len(dynamics.coordinates)))
        if tree.floating_base:
            q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=-1, keepdims=True)
        for _, _, at, _ in quaternion_slices(tree):  # each ball's and flyer's below the root
            q[:, at:at + 4] /= np.linalg.norm(q[:, at:at + 4], axis=-1, keepdims=True)
        v, a = rng.uniform(-1.0, 1.0, (2, 3, dynamics.n))
        wrenches = {f.name: rng.uniform(-5.0, 5.0, (3, 6)) for f in tree.frames if f.body >= 0}
        wrenches = dict(list(wrenches.items())[-1:])  # the last moving frame's
        fused = one_pass(q, v, a, wrenches)  # finite states: the output alone
        apart = np.array(dynamics.inverse_dynamics(q, v, a), dtype=float)
        if fused is NotImplemented or self.add_wrenches(q, wrenches, apart, -1.0) \
                is NotImplemented:  # a tree these do not take: the two calls stay
            self.inverse = False
            return False
        scale = 1.0 + np.abs(apart).max()
        self.inverse = one_pass if np.abs(fused - apart).max() <= 1e-9 * scale else False
        return self.inverse

    def add_wrenches(self, q, wrenches, out: np.ndarray, sign: float):
        """out += sign sum J^T w over the frames, in place (out: q's batch, nv wide), the rows of
        states not finite (q, a wrench, or out's row already) made NaN whole; their count.
        NotImplemented where a frame is not the tree's or the inputs are not plain or a
        quaternion is off (out then partly added to: the caller's own copy; the numpy path
        names the fault)."""
        wrench, bad = self.compiled.wrench, None
        for name, w in wrenches.items():
            index = self.frame_index.get(name) if isinstance(name, str) else None
            if index is None:
                return NotImplemented
            bad = wrench(q, index, w, out, sign)  # the last counts them all
            if bad is NotImplemented:
                return NotImplemented
        if bad is None:  # no wrench: the rows NaN already (the caller's dynamics')
            bad = int(np.isnan(out).reshape(-1, out.shape[-1]).any(axis=-1).sum())
        return bad


__all__ = ["ReachKernel", "engine", "kernel_source", "reach_module", "tables"]
