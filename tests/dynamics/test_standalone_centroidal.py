"""The centroidal momentum matrix A_g in the standalone C of `codegen --lang c` (C99, libm only),
compiled with -std=c99 -pedantic -Werror, against Pinocchio's ccrba on the Panda (fixed base) and
Solo12 (floating base, buildModelFromUrdf(path, JointModelFreeFlyer())), and its physics without
Pinocchio: A_g v is the total linear momentum m c_dot (c_dot = Jc v from the same C)."""

from __future__ import annotations

import ctypes
import shutil
import subprocess

import numpy as np
import pytest
from tests.dynamics.test_floating_base import FLOATING_URDF, _close, _layout

import lagrangian
from lagrangian.output.files import write_c
from robot_data import robots as _robots

pytest.importorskip("yourdfpy")
COMPILER = shutil.which("cc") or shutil.which("gcc")
pytestmark = pytest.mark.skipif(COMPILER is None, reason="no C compiler")
LOCK = {"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0}
POINTER = ctypes.c_void_p




def _library(tmp_path, system):
    """The system's standalone C compiled as a shared library (-O0: the check is of the C, not
    of its speed), and its prefix."""
    code = system.to_c()
    write_c(code, tmp_path / "gen")
    library = tmp_path / "robot.so"
    subprocess.run([COMPILER, "-std=c99", "-O0", "-Wall", "-Werror", "-pedantic", "-shared",
                    "-fPIC", str(tmp_path / "gen" / f"{code.prefix}.c"), "-o", str(library),
                    "-lm"], check=True)
    return code.prefix, ctypes.CDLL(str(library))


def _call(c, name, nv, *arrays, rows=6):
    out = np.zeros(rows * nv)
    c[name](*(np.ascontiguousarray(x, dtype=float).ctypes.data_as(POINTER) for x in arrays),
            out.ctypes.data_as(POINTER))
    return out.reshape(rows, nv)


@pytest.mark.parametrize("robot", ["panda", "solo12"])
def test_standalone_centroidal_momentum_matrix_is_pinocchios_ccrba(tmp_path, robot):
    import pinocchio as pin

    if robot == "panda":
        path = _robots() / "panda_description/urdf/panda.urdf"
        model = pin.buildModelFromUrdf(str(path))
        model = pin.buildReducedModel(model, [model.getJointId(j) for j in LOCK],
                                      pin.neutral(model))
        system = lagrangian.load(path, lock=LOCK)
    else:
        path = _robots() / "solo_description/robots/solo12.urdf"
        model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
        system = lagrangian.load(path, floating_base=True)
    data = model.createData()
    ours = system.dynamics(backend="numpy")
    floating = ours.velocity_names is not None
    iq, iv = _layout(model, ours) if floating else (np.arange(model.nq), np.arange(model.nv))
    prefix, c = _library(tmp_path, system)
    rng = np.random.default_rng(3)
    for _ in range(4):
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
        v = rng.uniform(-1, 1, model.nv)
        A = _call(c, f"{prefix}_centroidal_momentum_matrix", model.nv, q[iq])
        expected = pin.ccrba(model, data, q, v)[:, iv]
        _close(A, expected)
        _close(A, ours.centroidal_momentum_matrix(q[iq]))  # the numpy twin, same formulas
        _close(A @ v[iv], data.hg.vector)


def test_centroidal_momentum_is_the_mass_times_the_centre_of_mass_velocity(tmp_path):
    """Without Pinocchio: the linear rows of A_g v are m c_dot, with c_dot = Jc v from the same
    C, on a hopper whose URDF floats its trunk (4.35 kg)."""
    path = tmp_path / "hopper.urdf"
    path.write_text(FLOATING_URDF)
    prefix, c = _library(tmp_path, lagrangian.load(path))
    rng = np.random.default_rng(4)
    q = np.r_[rng.uniform(-1, 1, 3), [0.0, 0.6, 0.0, 0.8], rng.uniform(-1, 1, 3)]
    v = rng.uniform(-1, 1, 9)
    A = _call(c, f"{prefix}_centroidal_momentum_matrix", 9, q)
    Jc = _call(c, f"{prefix}_center_of_mass_jacobian", 9, q, rows=3)
    np.testing.assert_allclose(A[:3] @ v, 4.35 * Jc @ v, rtol=1e-13, atol=1e-13)
