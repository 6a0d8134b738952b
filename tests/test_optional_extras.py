"""The lean default install (issue 22): URDF robots, Parquet and parameter studies are optional
extras, each refused in one line naming the extra to install when its packages are missing,
through the CLI (exit 2, one `error:` line) and the API (MissingExtraError); the Quick start
needs none of them. A missing package is simulated: sys.modules[name] = None makes `import name`
fail as if it were not installed, in this process or in a fresh interpreter (as a lean
install would run)."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
import tomllib
from pathlib import Path

import pytest

import lagrangian
from lagrangian.errors import InputError, MissingExtraError

ROOT = Path(__file__).resolve().parents[1]
# what each extra installs, as imported by the library
EXTRA_MODULES = {"parquet": ["pyarrow"],
                 "sweep": ["dask", "distributed", "xarray", "h5netcdf", "h5py", "zarr"],
                 "urdf": ["yourdfpy", "lxml"]}
# what yourdfpy pulls in besides (its mesh stack)
MESH_STACK = ["trimesh", "six"]


def missing(monkeypatch, *names: str) -> None:
    """Make ``names`` unimportable for the rest of the test, as if not installed."""
    for name in names:
        monkeypatch.setitem(sys.modules, name, None)


def one_line_refusal(result, extra: str) -> str:
    assert result.code == 2, (result.out, result.err)
    assert result.err.startswith("error: ") and result.err.count("\n") == 1, result.err
    assert "Traceback" not in result.err
    assert f'pip install "lagrangian[{extra}]"' in result.err
    return result.err


# -- Parquet ----------------------------------------------------------------------------------

def test_parquet_without_pyarrow_cli(cli, monkeypatch, tmp_path):
    missing(monkeypatch, "pyarrow")
    out = tmp_path / "run.parquet"
    result = cli("simulate", "pendulum", "--t-end", "0.1", "--out", str(out))
    assert "pyarrow" in one_line_refusal(result, "parquet")
    assert not out.exists()
    # CSV needs no extra
    csv = tmp_path / "run.csv"
    assert cli("simulate", "pendulum", "--t-end", "0.1", "--out", str(csv)).code == 0
    assert csv.read_text().startswith("t,theta,theta_dot")


def test_parquet_without_pyarrow_api(monkeypatch, tmp_path):
    run = lagrangian.load("pendulum").simulate(t_end=0.1)
    missing(monkeypatch, "pyarrow")
    with pytest.raises(MissingExtraError) as info:
        run.save(tmp_path / "run.parquet")
    error = info.value
    assert error.extra == "parquet" and error.module == "pyarrow"
    assert isinstance(error, InputError)  # caught as bad input, as before
    assert "\n" not in str(error) and 'pip install "lagrangian[parquet]"' in str(error)
    assert not (tmp_path / "run.parquet").exists()


# -- parameter studies ------------------------------------------------------------------------

@pytest.mark.parametrize("module, out", [
    ("dask", None), ("distributed", None), ("xarray", None),
    ("h5netcdf", "study.nc"), ("h5py", "study.nc"), ("zarr", "study.zarr"),
])
def test_sweep_without_its_packages_cli(cli, monkeypatch, tmp_path, module, out):
    missing(monkeypatch, module)
    args = ["sweep", "pendulum", "--vary", "L=1,2", "--workers", "1", "--json"]
    if out is not None:
        args += ["--out", str(tmp_path / out)]
    err = one_line_refusal(cli(*args), "sweep")
    assert f"{module} is not installed" in err
    assert list(tmp_path.iterdir()) == []  # refused before any work: nothing written


@pytest.mark.parametrize("module", ["dask", "xarray"])
def test_sweep_without_its_packages_api(monkeypatch, module):
    pendulum = lagrangian.load("pendulum")
    missing(monkeypatch, module)
    with pytest.raises(MissingExtraError, match=r'pip install "lagrangian\[sweep\]"') as info:
        pendulum.sweep({"L": [1.0, 2.0]}, workers=1)
    assert info.value.extra == "sweep" and info.value.module == module
    assert "\n" not in str(info.value)


def test_a_zarr_study_needs_no_netcdf_writer(monkeypatch, tmp_path):
    """Each file format asks only for its own writer: .zarr does not need h5netcdf."""
    from lagrangian.output.sweep import require_study_packages

    missing(monkeypatch, "h5netcdf", "h5py")
    require_study_packages(tmp_path / "study.zarr")
    with pytest.raises(MissingExtraError, match="h5netcdf"):
        require_study_packages(tmp_path / "study.nc")


def test_a_broken_package_keeps_its_reason(monkeypatch):
    """Installed but failing to import (a shared library of its own missing): the extra is
    still named, with the import's own reason."""
    from lagrangian.errors import require_extra

    def broken(name, *args, **kwargs):
        raise ImportError("libhdf5.so.310: cannot open shared object file")

    monkeypatch.setattr("importlib.import_module", broken)
    with pytest.raises(MissingExtraError) as info:
        require_extra("sweep", ["h5py"], "writing a study as .nc")
    assert "libhdf5.so.310" in str(info.value) and "[sweep]" in str(info.value)


# -- the default install: the Quick start and URDF need no extra ------------------------------

BLOCKER = textwrap.dedent("""
    import sys

    # None in sys.modules: `import name` fails and importlib.util.find_spec(name) is None, as
    # for a package that is not installed (pint asks find_spec("dask") at import)
    for name in sys.argv[1].split(","):
        sys.modules[name] = None
    sys.argv = ["lagrangian", *sys.argv[2:]]
    from lagrangian.cli import main
    main()
""")


def lean(*args: str, blocked=None) -> subprocess.CompletedProcess:
    """The CLI in a fresh interpreter where no optional package can be imported."""
    if blocked is None:
        blocked = [m for modules in EXTRA_MODULES.values() for m in modules] + MESH_STACK
    return subprocess.run([sys.executable, "-c", BLOCKER, ",".join(blocked), *args],
                          capture_output=True, text=True, timeout=300,
                          env={**__import__("os").environ, "PYTHONPATH": str(ROOT / "src")})


def test_quick_start_needs_no_extra_and_urdf_names_its_own():
    """The README's first command with every optional package missing; a URDF arm is refused
    in one line naming the [urdf] extra."""
    derive = lean("derive", "pendulum", "--json")
    assert derive.returncode == 0, derive.stderr
    equations = json.loads(derive.stdout)
    assert "sin(theta)" in json.dumps(equations)
    arm = lean("dynamics", "two_link_arm", "--q", "0,0", "--json")
    assert arm.returncode == 2
    assert arm.stderr.count("\n") == 1 and arm.stderr.startswith("error: ")
    assert 'pip install "lagrangian[urdf]"' in arm.stderr and "Traceback" not in arm.stderr


def test_urdf_with_its_extra_gives_the_closed_form():
    """With [urdf] (and nothing else optional): the two-link arm's M at q = 0, from its file's
    note: M11 = 2.54 + 1.2 cos(elbow), M12 = 0.34 + 0.6 cos(elbow), M22 = 0.34."""
    pytest.importorskip("yourdfpy")
    blocked = [m for name, modules in EXTRA_MODULES.items() if name != "urdf" for m in modules]
    arm = lean("dynamics", "two_link_arm", "--q", "0,0", "--json", blocked=blocked)
    assert arm.returncode == 0, arm.stderr
    M = json.loads(arm.stdout)["mass_matrix"]
    assert sum(M, []) == pytest.approx([3.74, 0.94, 0.94, 0.34], rel=1e-12)


def test_urdf_without_its_extra_api(monkeypatch):
    missing(monkeypatch, "yourdfpy")
    with pytest.raises(MissingExtraError) as info:
        lagrangian.load("two_link_arm")
    assert info.value.extra == "urdf" and "\n" not in str(info.value)


def test_a_lean_install_refuses_a_sweep_in_one_line():
    result = lean("sweep", "pendulum", "--vary", "L=1,2", "--workers", "1")
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and result.stderr.startswith("error: ")
    assert 'pip install "lagrangian[sweep]"' in result.stderr and "Traceback" not in result.stderr


def test_the_test_extra_installs_every_optional_extra():
    """CI installs .[test]: each extra's requirements are in it, so every test runs there."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    extras = project["optional-dependencies"]
    for name in ("urdf", "parquet", "sweep", "mp4"):
        assert set(extras[name]) <= set(extras["test"]), name
    declared = " ".join(project["dependencies"])
    for module in EXTRA_MODULES["parquet"] + ["dask", "xarray", "h5netcdf", "zarr", "yourdfpy"]:
        assert module not in declared, module
