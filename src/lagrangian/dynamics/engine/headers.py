"""The engine's two headers, spatial.h (the 3-vector algebra) and joint.h (the description's
layout and each joint kind's placement and subspace), spliced into each module's one
translation unit: ``#include "spatial.h"`` and ``#include "joint.h"`` by their text before
joint.h's JT_CORE_BEGIN, and each ``/* JT_CORE: joint.h's core, here */`` line (one a core:
once on one state, once on the lanes) by the text after it. ``HEADERS`` are in every module's
cache key."""

from __future__ import annotations

from pathlib import Path

HEADERS = tuple(Path(__file__).with_name(name) for name in ("spatial.h", "joint.h"))
CORE_LINE = "/* JT_CORE: joint.h's core, here */"


def spliced(source: str) -> str:
    """``source`` with the headers' text in place of their include lines and core lines."""
    spatial, joint = (path.read_text(encoding="utf-8") for path in HEADERS)
    head, core = joint.split("/* JT_CORE_BEGIN */")
    return (source.replace('#include "spatial.h"', spatial)
            .replace('#include "joint.h"', head).replace(CORE_LINE, core))


def header_bytes() -> bytes:
    """The headers' text, for a module's cache key."""
    return b"".join(path.read_bytes() for path in HEADERS)


__all__ = ["CORE_LINE", "HEADERS", "header_bytes", "spliced"]
