"""Griffe extension for the API page: a docstring's ``>>>`` example (a doctest, run as one) is
shown as a Python console block instead of being read by Markdown as a quotation."""

from __future__ import annotations

import re

from griffe import Extension

# A run of lines starting with ">>> " and the output lines after it, up to a blank line.
EXAMPLE = re.compile(r"(?m)^(>>> .*\n(?:(?!\s*\n).*\n?)*)")


def fenced(text: str) -> str:
    """``text`` with each doctest run put between ```pycon fences."""
    return EXAMPLE.sub(lambda m: "```pycon\n" + m.group(1).rstrip("\n") + "\n```\n", text)


class DoctestBlocks(Extension):
    """Fence the doctests of every docstring griffe reads."""

    def on_instance(self, *, obj, **kwargs) -> None:
        if obj.docstring is not None and ">>> " in obj.docstring.value:
            obj.docstring.value = fenced(obj.docstring.value)
