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
from functools import lru_cache
from pathlib import Path

# the recursions (forward dynamics in a file of its own), the thread count shared with the other
# modules, then the batched Python bindings (one translation unit)
_SOURCES = tuple(Path(__file__).with_name(name)
                 for name in ("tree_kernel.c", "tree_kernel_forward.c", "batch_threads.c",
                              "tree_kernel_bindings.c"))


def _source() -> str:
    from ..emit.tree_c import _SINCOS

    head, rest = _SOURCES[0].read_text(encoding="utf-8").split("/* TK_SINCOS */")
    return "\n".join([head, _SINCOS, rest,
                      *(path.read_text(encoding="utf-8") for path in _SOURCES[1:])])

# Trees of more moving bodies than this get the compact kernel; smaller ones the unrolled
# module of tree_c.py: about 2x faster per call and, up to tree_emitter.VECTOR_LIMIT, several
# states per vector operation in a batch, while its cold compile stays under ~20 s (measured:
# docs/benchmarks.md, benchmarks/bench_tree_kernel.py --threshold).
COMPACT_ABOVE = 16


@lru_cache(maxsize=1)
def kernel_key() -> str:
    """The module's key: its C source (and this file), never a tree."""
    here = Path(__file__)
    return "compact-tree-kernel\n" + hashlib.sha256(
        b"".join(path.read_bytes() for path in (*_SOURCES, here, here.parents[1] / "emit" /
                                                "tree_c.py", here.parents[1] / "tree" /
                                                "description.py")
                 )).hexdigest()


def kernel_module():
    """The compiled compact kernel (built once, then from the verified cache)."""
    from ...compile import compiled
    from ...compile.codegen import GeneratedSource

    return compiled.load_keyed(kernel_key(), lambda: GeneratedSource(
        source=_source(), parameters=(), n=0, m=0), native=True)


__all__ = ["COMPACT_ABOVE", "kernel_key", "kernel_module"]
