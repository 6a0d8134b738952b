"""The compact tree kernel: one compiled module (tree_kernel.c) for every tree, the tree given
at run time as one array of doubles, so a 200-joint chain needs no code of its own and a link's
mass, centre of mass or inertia changes without a rebuild.

The tree reaches it as one array D (its layout and ``describe``: tree/description.py).

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


__all__ = ["kernel_key", "kernel_module"]
