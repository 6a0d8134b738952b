"""The compact tree kernel: one compiled module (tree_kernel.c) for every tree, the tree given
at run time as one array of doubles, so a 200-joint chain needs no code of its own and a link's
mass, centre of mass or inertia changes without a rebuild.

The tree reaches it as one array D (its layout and ``describe``: tree/description.py).

A new joint kind is a new code in JOINT_CODES and its branch in joint.h (jt_place for the
placement, tk_subspace for S), which the reach and derivatives modules read too; the recursions
themselves ask only for those. The module
(tree_kernel.c, tree_kernel_forward.c, then its Python bindings tree_kernel_bindings.c) is keyed
by its source alone, never the tree's numbers. The recursions are compiled twice, on one state
and on LG_LANES states at once (a batch's several states per vector instruction), from one text.
"""

from __future__ import annotations

import hashlib
from functools import lru_cache
from pathlib import Path

from .headers import HEADERS, spliced

# the recursions (forward dynamics in a file of its own), the thread count shared with the other
# modules, then the batched Python bindings (one translation unit)
_SOURCES = tuple(Path(__file__).with_name(name)
                 for name in ("tree_kernel.c", "tree_kernel_forward.c", "batch_threads.c",
                              "bound_call.c", "tree_kernel_bindings.c"))


# the recursions' core (tree_kernel.c from TK_CORE_BEGIN, then tree_kernel_forward.c) twice:
# on one state, then on LG_LANES states at once
_SCALAR = """#define TK_SCALAR 1
#define TK_T double
#define TK_FN(name) tk_##name
#define TK_C(x) (x)
#define TK_SINCOS lg_sincos_inline
#define TK_SQRT sqrt
#define TK_MASK int
#define TK_FINE 0
#define TK_NOT_POSITIVE(d) (!((d) > 0.0))
#define TK_NOT_FINITE(x) (!isfinite(x))
#define TK_GIVE_UP(bad) do { if (bad) return bad; } while (0)"""
_LANES = """#undef TK_SCALAR
#undef TK_T
#undef TK_FN
#undef TK_C
#undef TK_SINCOS
#undef TK_SQRT
#undef TK_MASK
#undef TK_FINE
#undef TK_NOT_POSITIVE
#undef TK_NOT_FINITE
#undef TK_GIVE_UP
typedef long long lg_i4 __attribute__((vector_size(sizeof(lg_v4))));
#define TK_SCALAR 0
#define TK_T lg_v4
#define TK_FN(name) tk4_##name
#define TK_C(x) LG_V4(x)
#define TK_SINCOS lg_vsincos_inline
#define TK_SQRT lg_vsqrt
#define TK_MASK lg_i4
#define TK_FINE ((lg_i4){0})
#define TK_NOT_POSITIVE(d) (~((d) > TK_C(0.0)))
#define TK_NOT_FINITE(x) (~(((x) - (x)) == ((x) - (x))))
#define TK_GIVE_UP(bad) ((void)0)"""


def _source() -> str:
    from ..emit.tree_c import _SINCOS, _VECTOR

    first, forward, threads, bound, bindings = (path.read_text(encoding="utf-8")
                                                for path in _SOURCES)
    head, core = first.split("/* TK_CORE_BEGIN */")
    before, after = head.split("/* TK_SINCOS */")
    core = "\n".join([core, forward])
    return spliced("\n".join([before, _SINCOS, _VECTOR, after, _SCALAR, core, _LANES, core,
                               threads, bound, bindings]))


@lru_cache(maxsize=1)
def kernel_key() -> str:
    """The module's key: its C source (and this file), never a tree."""
    here = Path(__file__)
    return "compact-tree-kernel\n" + hashlib.sha256(
        b"".join(path.read_bytes() for path in (*_SOURCES, *HEADERS, here, here.parents[1] /
                                                "emit" / "tree_c.py", here.parents[1] / "tree"
                                                / "description.py"))).hexdigest()


def kernel_module():
    """The compiled compact kernel (built once, then from the verified cache)."""
    from ...compile import compiled
    from ...compile.codegen import GeneratedSource

    # exact: no fused multiply-adds, which the compiler places differently in the scalar and
    # the lanes' functions, so that a batch's row equals its state's single call bit for bit
    return compiled.load_keyed(kernel_key(), lambda: GeneratedSource(
        source=_source(), parameters=(), n=0, m=0), native=True, exact=True)


__all__ = ["kernel_key", "kernel_module"]
