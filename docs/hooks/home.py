"""mkdocs hook: the site's home page is the README, its links rewritten from the repository root
to docs/ (``docs/x.md`` -> ``x.md``), so GitHub's front page and the site's never differ."""

from __future__ import annotations

import re
from pathlib import Path

from mkdocs.structure.files import File

README = Path(__file__).resolve().parents[2] / "README.md"


def home_markdown(readme: str) -> str:
    """The README with its links into docs/ made relative to docs/ (the site's root)."""
    return re.sub(r"\]\(docs/", "](", readme)


def on_files(files, config):
    """Add index.md, made from the README, to the site's files."""
    files.append(File.generated(config, "index.md",
                                content=home_markdown(README.read_text(encoding="utf-8"))))
    return files
