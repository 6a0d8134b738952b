"""J_dot q_dot, the centroidal momentum matrix, wrenches' generalized forces and a floating
base's C(q, v) in compiled C (reach_kernel.c over the tree's numbers written as static tables),
for the C backend's speed per call; centroidal.py, wrenches.py and coriolis_tree.py are the same
formulas in numpy, used without a compiler and to name every bad input."""

from __future__ import annotations

import hashlib
from functools import partial
from pathlib import Path

import numpy as np

from ..compile.codegen import c_table
from ..model.tree import KinematicTree
from .free_flyer import QUATERNION_TOLERANCE
from .joint_models import joint_model
from .tree_c import _SINCOS, _VECTOR

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


def _turn_tables(joints) -> list[str]:
    """R0 u u^T, R0 (1 - u u^T) and R0 [u]x per joint: R0 Rot(u, th) = P + cos th C + sin th S."""
    P, C, S = [], [], []
    for j in joints:
        R0, u = np.array(j.rotation, dtype=float), np.array(j.axis, dtype=float)
        uu = np.outer(u, u)
        skew = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
        P.append((R0 @ uu).ravel().tolist())
        C.append((R0 @ (np.eye(3) - uu)).ravel().tolist())
        S.append((R0 @ skew).ravel().tolist())
    return [c_table("rk_P", "double", P), c_table("rk_C", "double", C), c_table("rk_S", "double", S)]


def _axis_tables(joints) -> list[str]:
    """Per joint: k where its axis is +-e_k exactly (else -1), that sign, and whether its R0
    is exactly 1: there R0 Rot(e_k, th) is a turn of two columns (reach_kernel.c's body)."""
    axis, sign, plain = [], [], []
    for j in joints:
        u = [float(x) for x in j.axis]
        k = next((k for k in range(3) if abs(u[k]) == 1.0 and u[k - 1] == u[k - 2] == 0.0), -1)
        axis.append(k)
        sign.append(u[k] if k >= 0 else 1.0)
        plain.append(np.array_equal(np.array(j.rotation, dtype=float), np.eye(3)))
    return [c_table("rk_axis", "int", axis), c_table("rk_axsign", "double", sign),
            c_table("rk_R0id", "int", plain)]


def _coriolis_tables(tree: KinematicTree) -> list[str]:
    """The entries of C (row-major, nv x nv) that no body's pass sets, those of two joints on
    different branches (reach_coriolis.c sets the others once each and zeroes only these), and
    RK_CSET: 0 where a mimic joint shares another joint's coordinate (its entries then add
    up: the whole of C, and of A_g, is zeroed first)."""
    free = tree.floating_base
    base = 6 if free else 0
    nv = base + len(tree.coordinates)
    columns = [list(range(6)) if free and i == 0 else [base + j.coordinate]
               for i, j in enumerate(tree.joints)]
    coordinates = [j.coordinate for j in tree.joints[int(free):]]
    shared = len(set(coordinates)) < len(coordinates)
    written = set()
    for i in range(len(tree.joints)):
        a = i
        while a >= 0:  # i's ancestors and i itself
            for r in columns[a]:
                for c in columns[i]:
                    written.update({(r, c), (c, r)})
            a = tree.joints[a].parent
    unset = [r * nv + c for r in range(nv) for c in range(nv) if (r, c) not in written]
    return [f"#define RK_CSET {int(not shared)}", f"#define RK_NCZERO {len(unset)}",
            c_table("rk_czero", "int", unset)]


def kernel_source(tree: KinematicTree):
    """The module's C: the tables, then the kernels of _KERNELS in order."""
    from ..compile.codegen import GeneratedSource

    joints, frames = tree.joints, tree.frames
    flat = [[x for row in j.rotation for x in row] for j in joints]
    models = [joint_model(j.kind) for j in joints]
    source = "\n".join([
        "/* lagrangian: frame accelerations, centroidal momentum and wrenches of a tree */",
        "#define PY_SSIZE_T_CLEAN",
        "#include <Python.h>",
        "#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION",
        "#include <numpy/arrayobject.h>",
        "#include <math.h>",
        f"#define RK_NB {len(joints)}",
        f"#define RK_N {len(tree.coordinates)}",
        f"#define RK_FB {int(tree.floating_base)}",
        # |quaternion|^2 within (1 -+ QUATERNION_TOLERANCE)^2, else numpy names the fault
        f"#define RK_QLOW {(1 - QUATERNION_TOLERANCE) ** 2!r}",
        f"#define RK_QHIGH {(1 + QUATERNION_TOLERANCE) ** 2!r}",
        f"#define RK_NF {len(frames)}",
        c_table("rk_parent", "int", [j.parent for j in joints]),
        c_table("rk_coord", "int", [j.coordinate for j in joints]),
        # a free flyer neither turns nor slides about an axis (body 0, read by RK_FREE)
        c_table("rk_turns", "int", [getattr(m, "turns", False) for m in models]),
        c_table("rk_slides", "int", [getattr(m, "slides", False) for m in models]),
        c_table("rk_mult", "double", [j.multiplier for j in joints]),
        c_table("rk_off", "double", [j.offset for j in joints]),
        c_table("rk_R0", "double", flat),
        *_turn_tables(joints),
        *_axis_tables(joints),
        c_table("rk_t0", "double", [list(j.translation) for j in joints]),
        c_table("rk_u", "double", [list(j.axis) for j in joints]),
        c_table("rk_m", "double", [j.mass for j in joints]),
        c_table("rk_h", "double", [list(j.first_moment) for j in joints]),
        c_table("rk_J", "double", [[x for row in j.inertia for x in row] for j in joints]),
        c_table("rk_fbody", "int", [f.body for f in frames]),
        c_table("rk_fR", "double", [[x for row in f.rotation for x in row] for f in frames]),
        c_table("rk_ft", "double", [list(f.translation) for f in frames]),
        *_coriolis_tables(tree),
        _SINCOS, _VECTOR,
    ])
    texts = [path.read_text(encoding="utf-8") for path in _KERNELS]
    head, first = texts[0].split("/* RK_CORE_BEGIN */")
    core = "\n".join([first, *texts[1:_CORE]])
    source = "\n".join([source, head, _SCALAR, core, _LANES, core, *texts[_CORE:]])
    return GeneratedSource(source=source, parameters=(), n=len(tree.coordinates), m=0)


def reach_module(tree: KinematicTree):
    """The compiled module of this tree (cached on disk by its numbers and this generator),
    or None where no compiler works."""
    from ..compile import compiled
    from .centroidal import ONE_DOF

    free = tree.floating_base  # a free flyer: body 0 only (RK_FREE)
    if any(j.kind not in ONE_DOF for j in tree.joints[int(free):]):
        return None  # a joint the kernel does not know: numpy's walks refuse it in one line
    here = Path(__file__)
    generator = hashlib.sha256(b"".join(path.read_bytes() for path in _KERNELS)
                               + here.read_bytes()
                               + here.with_name("tree_c.py").read_bytes()).hexdigest()
    key = "\n".join(["reach", generator, repr(tree), repr(tree.frames)])
    try:
        return compiled.load_keyed(key, lambda: kernel_source(tree), native=True)
    except compiled.BackendUnavailable:
        return None


class ReachKernel:
    """The compiled functions with frames by name; inputs of one batch shape (..., n). Each
    returns its output, or (output, count of NaN rows) where a state's inputs are not all
    finite (its whole row NaN: reach_bindings.c)."""

    def __init__(self, module, tree: KinematicTree, massive: bool):
        self.module = module
        self.frame_index = {f.name: k for k, f in enumerate(tree.frames)}
        # placement(Q, frame), jacobian(Q, frame, reference) and drift(Q, V, frame, reference)
        # with the frame and reference looked up by name in C (reach_bindings.c): in Python the
        # lookups cost a single Jacobian's call a sixth of its time
        self.placement, self.jacobian, self.drift = module.frames(self.frame_index)
        # A_g and the centre of mass need moving mass (else numpy refuses them in one line)
        self.centroidal = module.centroidal if massive else None
        self.center_of_mass = module.com if massive else None
        self.center_of_mass_jacobian = module.com_jacobian if massive else None
        # a floating base's C by Pinocchio's factorization; a fixed base's is M's Christoffel
        # symbols (joint_space.py), which the same factorization gives: None until
        # checked_coriolis has compared the two, then the compiled function or False
        self.coriolis = module.coriolis if tree.floating_base else None
        self.fixed_coriolis = None if not tree.floating_base else False
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
        try:
            compiled = np.asarray(self.module.coriolis(q, v), dtype=float)
            with np.errstate(all="ignore"):
                christoffel = np.asarray(dynamics._christoffel_coriolis(q, v), dtype=float)
        except (ValueError, TypeError):
            return False
        scale = 1.0 + np.abs(christoffel).max()
        if np.abs(compiled - christoffel).max() <= 1e-9 * scale:
            self.fixed_coriolis = self.module.coriolis
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
        one_pass = partial(self.module.inverse, self.frame_index, up)
        rng = np.random.default_rng(0)
        q = rng.uniform(-1.0, 1.0, (3, len(dynamics.coordinates)))
        if tree.floating_base:
            q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=-1, keepdims=True)
        v, a = rng.uniform(-1.0, 1.0, (2, 3, dynamics.n))
        wrenches = {f.name: rng.uniform(-5.0, 5.0, (3, 6)) for f in tree.frames if f.body >= 0}
        wrenches = dict(list(wrenches.items())[-1:])  # the last moving frame's
        try:
            fused = one_pass(q, v, a, wrenches)  # finite states: the output alone
            apart = np.array(dynamics.inverse_dynamics(q, v, a), dtype=float)
            self.add_wrenches(q, wrenches, apart, -1.0)
        except (ValueError, TypeError, KeyError):
            self.inverse = False
            return False
        scale = 1.0 + np.abs(apart).max()
        self.inverse = one_pass if np.abs(fused - apart).max() <= 1e-9 * scale else False
        return self.inverse

    def add_wrenches(self, q, wrenches, out: np.ndarray, sign: float) -> int:
        """out += sign sum J^T w over the frames, in place (out: q's batch, nv wide), the rows of
        states not finite (q, a wrench, or out's row already) made NaN whole; their count.
        ValueError or KeyError where the inputs are not plain or a base quaternion is off (the
        numpy path then names the fault)."""
        wrench, bad = self.module.wrench, None
        for name, w in wrenches.items():
            bad = wrench(q, self.frame_index[name], w, out, sign)  # the last counts them all
        if bad is None:  # no wrench: the rows NaN already (the caller's dynamics')
            bad = int(np.isnan(out).reshape(-1, out.shape[-1]).any(axis=-1).sum())
        return bad


__all__ = ["ReachKernel", "kernel_source", "reach_module"]
