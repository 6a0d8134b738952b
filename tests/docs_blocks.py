"""Find a documented example wherever it lives: the README and the pages under docs/ mark each
runnable section with <!-- BEGIN name --> ... <!-- END name -->, and the tests that run those
sections read them through here, so a section can move between pages without its test losing it."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
DOCS = ROOT / "docs"


def pages() -> list[Path]:
    """The README and every Markdown page of the docs, in a fixed order."""
    return [README, *sorted(DOCS.rglob("*.md"))]


def block_file(name: str, page: str | None = None) -> Path:
    """The one page holding the block ``name``; ``page`` (relative to docs/) picks one where two
    pages use the same name."""
    begin = f"<!-- BEGIN {name} "
    found = [path for path in ([DOCS / page] if page else pages())
             if begin in path.read_text(encoding="utf-8")]
    assert len(found) == 1, f"block {name!r} is in {len(found)} pages, not one: {found}"
    return found[0]


def block(name: str, page: str | None = None) -> str:
    """The text of block ``name``, from its BEGIN marker to just before its END marker."""
    text = block_file(name, page).read_text(encoding="utf-8")
    start = text.index(f"<!-- BEGIN {name}")
    return text[start:text.index(f"<!-- END {name} -->", start)]
