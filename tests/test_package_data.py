"""Every file the package reads at run time ships with it: each file under src/lagrangian that is
not Python (the C sources the kernels compile, the examples) matches a package-data pattern of
pyproject.toml, so that an installed copy (as CI and the README's Quick start install it) finds
it. A new .c file beside the tree kernels once passed every test in the source tree and failed
in a fresh install."""

from __future__ import annotations

import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "src" / "lagrangian"


def test_every_data_file_is_package_data():
    settings = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    patterns = settings["tool"]["setuptools"]["package-data"]["lagrangian"]
    shipped = {path for pattern in patterns for path in PACKAGE.glob(pattern)}
    data = {path for path in PACKAGE.rglob("*") if path.is_file()
            and path.suffix not in (".py", ".pyc") and "__pycache__" not in path.parts}
    assert data, "no data files found: the test looks in the wrong place"
    missing = sorted(str(path.relative_to(PACKAGE)) for path in data - shipped)
    assert not missing, f"not in pyproject.toml's package-data: {missing}"
