"""Built-in example models, shipped as model files (TOML) and robots (URDF) beside this module."""

from __future__ import annotations

import re
import tomllib
from importlib import resources
from pathlib import Path

from ...errors import ModelError, did_you_mean


def _files() -> dict[str, Path]:
    folder = resources.files(__package__)
    return {
        Path(entry.name).stem: Path(str(entry))
        for entry in folder.iterdir()
        if entry.name.endswith((".toml", ".urdf"))
    }


def example_names() -> list[str]:
    """Names of the built-in examples, in the order the course introduces them."""
    files = _files()
    return sorted(files, key=lambda name: (_order(files[name]), name))


def example_path(name: str) -> Path:
    """Path of a built-in example's model file (or URDF)."""
    files = _files()
    if name not in files:
        from ..robots import installed_robots  # example-robot-data's names, where installed

        robots = [robot for robot in installed_robots() if robot not in files]
        where = "; `lagrangian examples --robots` the robots" if robots else ""
        raise ModelError(f"no such file or built-in example '{name}'"
                         f"{did_you_mean(name, [*files, *robots])} "
                         f"(`lagrangian examples` lists them{where})")
    return files[name]


def example_summary(name: str) -> dict[str, str]:
    """{'name': ..., 'title': ..., 'description': ...} of a built-in example."""
    path = example_path(name)
    if path.suffix == ".urdf":  # title and description from its first comment
        comments = re.findall(r"<!--(.*?)-->", path.read_text(encoding="utf-8"), re.S)
        text = next((" ".join(c.split()) for c in comments
                     if not c.strip().startswith("order:")), name)
        title, _, rest = text.partition(":")
        return {"name": name, "title": f"{title[:1].upper()}{title[1:]} (URDF)",
                "description": rest.strip()}
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    return {"name": name, "title": data.get("name", name),
            "description": data.get("description", "")}


def example_text(name: str) -> str:
    """A built-in example's file as a user would write it: without the "order: N" line that
    places it in `lagrangian examples`' list."""
    lines = example_path(name).read_text(encoding="utf-8").splitlines(keepends=True)
    return "".join(line for line in lines if not _ORDER.fullmatch(line.rstrip("\n")))


_ORDER = re.compile(r"(?:#|<!--)\s*order:\s*(\d+)\s*(?:-->)?\s*")


def _order(path: Path) -> int:
    head = path.read_text(encoding="utf-8").splitlines()[:2]
    for line in head:  # "# order: N" (TOML) or "<!-- order: N -->" (URDF)
        found = _ORDER.fullmatch(line)
        if found:
            return int(found.group(1))
    return 1000
