"""`lagrangian codegen --lang c`: the standalone C compiles with the system compiler (C99, libm)
and gives the Python API's numbers."""

from __future__ import annotations

import ctypes
import shutil
import subprocess

import numpy as np
import pytest

import lagrangian

ARM = """<?xml version="1.0"?>
<robot name="two link arm">
  <link name="base"/>
  <link name="upper"><inertial><origin xyz="0.5 0 0"/><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.2" iyz="0" izz="0.2"/></inertial></link>
  <link name="fore"><inertial><origin xyz="0.4 0 0" rpy="0 0.2 0"/><mass value="1.5"/>
    <inertia ixx="0.01" ixy="0.002" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <axis xyz="0 -1 0"/><limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="1 0 0" rpy="0.3 0 0"/><axis xyz="0 -1 0"/>
    <limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
</robot>
"""


def compiler():
    return shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")


@pytest.mark.skipif(compiler() is None, reason="no C compiler")
def test_standalone_c_gives_the_python_numbers(cli, tmp_path):
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(ARM)
    code, out, err = cli("codegen", str(urdf), "--lang", "c", "--out", str(tmp_path / "gen"))
    assert code == 0, err
    source = tmp_path / "gen" / "two_link_arm.c"
    assert (tmp_path / "gen" / "two_link_arm.h").exists()
    assert "Python.h" not in source.read_text() and "malloc" not in source.read_text()
    library = tmp_path / "arm.so"
    subprocess.run([compiler(), "-std=c99", "-O2", "-Wall", "-Werror", "-pedantic", "-shared",
                    "-fPIC", str(source), "-o", str(library), "-lm"], check=True)
    c = ctypes.CDLL(str(library))
    n = 2
    vec = ctypes.c_double * n
    params = (ctypes.c_double * 3).in_dll(c, "two_link_arm_parameters")
    f = lagrangian.load(urdf).dynamics()
    rng = np.random.default_rng(5)
    c.two_link_arm_kinetic_energy.restype = ctypes.c_double
    c.two_link_arm_potential_energy.restype = ctypes.c_double
    for _ in range(5):
        q, v, a, tau = (rng.uniform(-2, 2, n) for _ in range(4))
        M = (ctypes.c_double * (n * n))()
        c.two_link_arm_mass_matrix(vec(*q), params, M)
        np.testing.assert_allclose(np.array(M).reshape(n, n), f.mass_matrix(q), rtol=1e-12)
        out = vec()
        c.two_link_arm_bias_forces(vec(*q), vec(*v), params, out)
        np.testing.assert_allclose(np.array(out), f.bias_forces(q, v), rtol=1e-12)
        c.two_link_arm_gravity(vec(*q), params, out)
        np.testing.assert_allclose(np.array(out), f.gravity(q), rtol=1e-12)
        c.two_link_arm_inverse_dynamics(vec(*q), vec(*v), vec(*a), params, out)
        np.testing.assert_allclose(np.array(out), f.inverse_dynamics(q, v, a), rtol=1e-12)
        assert c.two_link_arm_forward_dynamics(vec(*q), vec(*v), vec(*tau), params, out) == 0
        np.testing.assert_allclose(np.array(out), f.forward_dynamics(q, v, tau), rtol=1e-10)
        assert c.two_link_arm_kinetic_energy(vec(*q), vec(*v), params) == pytest.approx(
            float(f.kinetic_energy(q, v)), rel=1e-12)
        assert c.two_link_arm_potential_energy(vec(*q), params) == pytest.approx(
            float(f.potential_energy(q)), rel=1e-12)


def test_codegen_bad_input_exits_2(cli, tmp_path):
    code, _, err = cli("codegen", "pendulum", "--lang", "rust", "--out", str(tmp_path))
    assert code == 2 and "--lang" in err and "unknown language" in err
    blocker = tmp_path / "file"
    blocker.write_text("x")
    code, _, err = cli("codegen", "pendulum", "--out", str(blocker))
    assert code == 2 and "not a directory" in err
