"""The robots of example-robot-data (a package of URDFs beside Pinocchio, pip's
``example-robot-data``), where it is installed: their short names and paths, so that
``load("panda")`` and ``lagrangian dynamics ur5`` find them.

A short name is the URDF's file name without ``.urdf`` (``panda``, ``solo12``), and, where that
is free, example-robot-data's own loader names: ``ur5`` for ``ur5_robot.urdf`` (a ``_robot``
suffix dropped), ``talos`` for ``talos_reduced.urdf``, ``hyq`` for ``hyq_no_sensors.urdf``. A
file name found in two packages (``anymal.urdf``) is the first package's (sorted); the other is
named by its package (``anymal_c``). A built-in example of the same name (``double_pendulum``)
comes first: such a robot is listed as shadowed and loads by its path."""

from __future__ import annotations

import os
import re
import sys
from functools import lru_cache
from pathlib import Path

_SHARE = Path("share") / "example-robot-data" / "robots"
# example-robot-data's loaders (robot_loaders.py) whose name is not the file's
_LOADER_NAMES = {"talos": "talos_reduced", "hyq": "hyq_no_sensors"}


def robots_folder() -> Path | None:
    """example-robot-data's robots/ folder where the package is installed, else None
    (its wheel puts it under the cmeel prefix of site-packages; ``EXAMPLE_ROBOT_DATA_DIR``
    names another)."""
    given = os.environ.get("EXAMPLE_ROBOT_DATA_DIR")
    if given:
        return Path(given) if Path(given).is_dir() else None
    try:
        from importlib import metadata

        found = Path(str(metadata.distribution("example-robot-data")
                         .locate_file(Path("cmeel.prefix") / _SHARE)))
        if found.is_dir():
            return found
    except Exception:  # noqa: BLE001 - not installed, or installed without metadata
        pass
    for entry in sys.path:  # a prefix on the path without the package's metadata
        candidate = Path(entry) / "cmeel.prefix" / _SHARE
        if candidate.is_dir():
            return candidate
    return None


@lru_cache(maxsize=4)
def _robots(folder: Path | None) -> dict[str, Path]:
    if folder is None:
        return {}
    files = sorted(folder.glob("*/*/*.urdf"), key=lambda p: (p.parts[-3], p.name))
    names: dict[str, Path] = {}
    for path in files:  # each file's own name first
        name = path.stem if re.fullmatch(r"\w+", path.stem) else None
        if name is None:
            continue
        if name in names:  # anymal.urdf in anymal_c_simple_description: anymal_c
            package = re.sub(r"(_simple)?_(description|data)$", "", path.parts[-3])
            name = package if package not in names else path.parts[-3]
        names.setdefault(name, path)
    for path in files:  # then the loaders' names, where free
        if path.stem.endswith("_robot"):
            names.setdefault(path.stem.removesuffix("_robot"), path)
    for alias, stem in _LOADER_NAMES.items():
        found = [p for p in files if p.stem == stem]
        if found:
            names.setdefault(alias, found[0])
    return dict(sorted(names.items(), key=lambda item: item[0].lower()))


def installed_robots() -> dict[str, Path]:
    """Short name -> URDF path of each installed example-robot-data robot ({} when the package
    is not installed), in name order."""
    return _robots(robots_folder())


def example_robot(name: str) -> Path | None:
    """The URDF of the example-robot-data robot ``name``, or None."""
    return installed_robots().get(name) if re.fullmatch(r"\w+", name) else None


def example_robots() -> list[dict[str, object]]:
    """Each robot as {"name", "path", "package", "shadowed"}: ``shadowed`` when a built-in
    example has the same name (that example is what the name loads; the robot loads by path)."""
    builtin = _built_in_names()
    return [{"name": name, "path": str(path), "package": path.parts[-3],
             "shadowed": name in builtin} for name, path in installed_robots().items()]


def shadowed(name: str) -> bool:
    """Whether a built-in example has the name ``name`` (it comes first)."""
    return name in _built_in_names()


def _built_in_names() -> set[str]:
    """The built-in examples' names (model/examples' files, read here without importing that
    module, which names these robots in its own refusal)."""
    from importlib import resources

    folder = resources.files("lagrangian.model.examples")
    return {Path(entry.name).stem for entry in folder.iterdir()
            if entry.name.endswith((".toml", ".urdf"))}
