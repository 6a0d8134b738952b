"""The standalone C header is usable from C++ (issue 27): its declarations sit in an
``extern "C"`` block, so a C++ controller that includes it links against the C object, compiled
with ``g++ -Wall -Werror``, and gets the Python API's mass matrix."""

from __future__ import annotations

import shutil
import subprocess

import numpy as np
import pytest

import lagrangian
from lagrangian.output.files import write_c

PROGRAM = r"""
#include <cstdio>
#include <cstdlib>
#include "PREFIX.h"

int main(int argc, char **argv)
{
    double q[PREFIX_UPPER_N], M[PREFIX_UPPER_N * PREFIX_UPPER_N];
    if (argc != PREFIX_UPPER_N + 1) return 2;
    for (int i = 0; i < PREFIX_UPPER_N; i++) q[i] = std::strtod(argv[i + 1], nullptr);
    PREFIX_mass_matrix(q, PREFIX_parameters, M);
    for (int i = 0; i < PREFIX_UPPER_N * PREFIX_UPPER_N; i++) std::printf("%.17g\n", M[i]);
    return 0;
}
"""


def _missing():
    if shutil.which("g++") is None:
        return "g++ is not installed (Debian: apt-get install g++)"
    if shutil.which("gcc") is None and shutil.which("cc") is None:
        return "no C compiler"
    return None


def _mass_matrix_from_cpp(system, prefix, q, tmp_path):
    code = system.to_c(prefix=prefix)
    write_c(code, tmp_path)
    main = tmp_path / "main.cpp"
    main.write_text(PROGRAM.replace("PREFIX_UPPER", prefix.upper()).replace("PREFIX", prefix))
    cc = shutil.which("gcc") or shutil.which("cc")
    obj = tmp_path / f"{prefix}.o"
    subprocess.run([cc, "-std=c99", "-O2", "-Wall", "-Werror", "-c", str(tmp_path / f"{prefix}.c"),
                    "-o", str(obj)], check=True)
    exe = tmp_path / "controller"
    build = subprocess.run(["g++", "-std=c++11", "-O2", "-Wall", "-Werror", str(main), str(obj),
                            "-o", str(exe), "-lm"], capture_output=True, text=True)
    assert build.returncode == 0, build.stderr  # without extern "C": undefined reference
    out = subprocess.run([str(exe), *map(repr, q)], check=True, capture_output=True, text=True)
    n = len(q)
    return np.array([float(x) for x in out.stdout.split()]).reshape(n, n)


@pytest.mark.skipif(_missing() is not None, reason=str(_missing()))
def test_a_cpp_controller_links_the_urdf_arms_header(tmp_path):
    pytest.importorskip("yourdfpy")
    system = lagrangian.load("two_link_arm")
    header = system.to_c(prefix="arm").header
    assert '#ifdef __cplusplus\nextern "C" {' in header
    q = [0.4, -1.1]
    M = _mass_matrix_from_cpp(system, "arm", q, tmp_path)
    np.testing.assert_allclose(M, system.dynamics().mass_matrix(q), rtol=1e-13, atol=1e-15)
    assert np.allclose(M, M.T) and np.all(np.linalg.eigvalsh(M) > 0)  # symmetric, positive


@pytest.mark.skipif(_missing() is not None, reason=str(_missing()))
def test_a_cpp_controller_links_a_derived_models_header(tmp_path):
    system = lagrangian.load("pendulum")  # M = m L^2 = 1 * 0.5^2
    M = _mass_matrix_from_cpp(system, "pendulum", [0.7], tmp_path)
    assert M[0, 0] == pytest.approx(0.25, rel=1e-15)


@pytest.mark.skipif(_missing() is not None, reason=str(_missing()))
def test_a_cpp_controller_links_a_model_files_tree(tmp_path):
    """A chain of bodies on joints from a model file: the tree's C, its masses folded in as
    numbers, only gravity and the generalized force left in the parameter array."""
    from lagrangian.dynamics.recursive import TREE_PATH_BODIES

    b = lagrangian.SystemBuilder("chain")
    b.set_gravity(b.parameter("g", 9.81), (0, 0, -1))
    b.parameter("tau", 0.5)
    for i in range(TREE_PATH_BODIES):
        b.coordinate(f"q{i}", unit="rad")
        b.parameter(f"m{i}", 1.0 + i)
        joint = {"type": "revolute", "axis": "xy"[i % 2], "angle": f"q{i}"}
        if i:
            joint["at"] = [0, 0, -1]
        b.add_rigid_body(f"link{i}", f"m{i}", [0.1, 0.1, 0.02],
                         parent=f"link{i - 1}" if i else None, joint=joint, center=[0, 0, -0.5])
    b.add_generalized_force("q0", "tau")
    system = b.build()
    code = system.to_c(prefix="chain")
    assert "#define CHAIN_NP 2" in code.header
    q = [float(x) for x in np.linspace(-1.0, 1.0, TREE_PATH_BODIES)]
    M = _mass_matrix_from_cpp(system, "chain", q, tmp_path)
    np.testing.assert_allclose(M, system.dynamics().mass_matrix(q), rtol=1e-12, atol=1e-12)
