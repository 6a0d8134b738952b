"""Frame placements, Jacobians, J_dot v and the centre of mass in the standalone C of `codegen
--lang c` (C99, libm only), compiled with -std=c99 -pedantic -Werror, against Pinocchio's
updateFramePlacements, getFrameJacobian and getFrameClassicalAcceleration (a = 0) in the three
references, centerOfMass and jacobianCenterOfMass: a floating base (a URDF floating joint with an origin
of its own) and a fixed arm; a frame name that is not a C identifier reaches C only escaped."""

from __future__ import annotations

import ctypes
import shutil
import subprocess

import numpy as np
import pytest
from tests.dynamics.test_dynamics_pinocchio import ARM
from tests.dynamics.test_floating_base import FLOATING_URDF, _close, _layout, _pinocchio_frame

import lagrangian
from lagrangian.output.files import write_c

pin = pytest.importorskip("pinocchio")
pytest.importorskip("yourdfpy")
COMPILER = shutil.which("cc") or shutil.which("gcc")
pytestmark = pytest.mark.skipif(COMPILER is None, reason="no C compiler")
REFERENCES = ("world", "local", "local_world_aligned")
# the foot renamed to a name no C identifier could be: a quote, a comment's end, a backslash, é
ODD = 'foot &quot;*/ \\ &#233;'


def _library(tmp_path, urdf: str):
    path = tmp_path / "robot.urdf"
    path.write_text(urdf)
    system = lagrangian.load(path)
    code = system.to_c()
    write_c(code, tmp_path / "gen")
    library = tmp_path / "robot.so"
    subprocess.run([COMPILER, "-std=c99", "-O2", "-Wall", "-Werror", "-pedantic", "-shared",
                    "-fPIC", str(tmp_path / "gen" / f"{code.prefix}.c"), "-o", str(library),
                    "-lm"], check=True)
    return system, code.prefix, ctypes.CDLL(str(library))


@pytest.mark.parametrize("urdf", [FLOATING_URDF.replace('"foot"', f'"{ODD}"'), ARM],
                         ids=["floating", "fixed"])
def test_standalone_frames_match_pinocchio(tmp_path, urdf):
    system, prefix, c = _library(tmp_path, urdf)
    ours = system.dynamics(backend="numpy")
    model = pin.buildModelFromXML(urdf)
    data = model.createData()
    floating = ours.velocity_names is not None
    iq, iv = _layout(model, ours) if floating else (np.arange(model.nq), np.arange(model.nv))
    names = (ctypes.c_char_p * len(ours.frames)).in_dll(c, f"{prefix}_frame_names")
    assert [n.decode() for n in names] == list(ours.frames)
    if floating:
        assert 'foot "*/ \\ \u00e9' in ours.frames
    place, jacobian = c[f"{prefix}_frame_placement"], c[f"{prefix}_frame_jacobian"]
    drift = c[f"{prefix}_frame_jacobian_dot_times_v"]
    pointer = ctypes.c_void_p
    rng = np.random.default_rng(2)
    for _ in range(3):
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
        v = rng.uniform(-1, 1, model.nv)
        ours_q, ours_v = np.ascontiguousarray(q[iq]), np.ascontiguousarray(v[iv])
        centre, centre_jacobian = np.zeros(3), np.zeros(3 * model.nv)
        c[f"{prefix}_center_of_mass"](ours_q.ctypes.data_as(pointer),
                                      centre.ctypes.data_as(pointer))
        c[f"{prefix}_center_of_mass_jacobian"](ours_q.ctypes.data_as(pointer),
                                               centre_jacobian.ctypes.data_as(pointer))
        _close(centre, pin.centerOfMass(model, data, q))
        _close(centre_jacobian.reshape(3, model.nv),
               pin.jacobianCenterOfMass(model, data, q)[:, iv])
        pin.forwardKinematics(model, data, q, v, np.zeros(model.nv))
        pin.updateFramePlacements(model, data)
        pin.computeJointJacobians(model, data, q)
        for k, name in enumerate(ours.frames):
            frame = _pinocchio_frame(model, name)
            T = np.zeros(16)
            place(ours_q.ctypes.data_as(pointer), k, T.ctypes.data_as(pointer))
            _close(T.reshape(4, 4), data.oMf[frame].homogeneous)
            for r, ref in enumerate(REFERENCES):
                J = np.zeros(6 * model.nv)
                jacobian(ours_q.ctypes.data_as(pointer), k, r, J.ctypes.data_as(pointer))
                expected = pin.getFrameJacobian(model, data, frame,
                                                getattr(pin.ReferenceFrame, ref.upper()))
                _close(J.reshape(6, model.nv), expected[:, iv])
                a = np.zeros(6)
                drift(ours_q.ctypes.data_as(pointer), ours_v.ctypes.data_as(pointer), k, r,
                      a.ctypes.data_as(pointer))
                _close(a, pin.getFrameClassicalAcceleration(
                    model, data, frame, getattr(pin.ReferenceFrame, ref.upper())).vector)


def test_the_documented_c_program(cli, tmp_path, monkeypatch):
    """docs/robot-kinematics.md, the frames-c block: its command writes the C, its program
    compiles with -Wall -Werror and prints the library's placement, Jacobian and A_g."""
    import re
    import shlex

    from tests.docs_blocks import block

    monkeypatch.chdir(tmp_path)
    text = block("frames-c")
    command = re.findall(r"\$ lagrangian (.*)", text)[0].split()
    assert cli(*command).code == 0
    source = re.findall(r"```c\n(.*?)```", text, re.S)[0]
    (tmp_path / "frames.c").write_text(source)
    line = re.findall(r"/\* frames\.c: (gcc .*) \*/", source)[0]
    subprocess.run([COMPILER, *shlex.split(line)[1:]], check=True)
    out = subprocess.run(["./frames"], check=True, capture_output=True, text=True).stdout.split()
    arm = lagrangian.load("two_link_arm").dynamics()
    q = [0.3, 0.5]
    assert out[0] == arm.frames[2] == "fore"
    np.testing.assert_allclose([float(x) for x in out[2:5]], arm.placement(q, "fore")[:3, 3],
                               atol=1e-4)
    np.testing.assert_allclose([float(x) for x in out[5:7]], arm.jacobian(q, "fore")[0],
                               atol=1e-4)
    np.testing.assert_allclose([float(x) for x in out[7:9]],
                               arm.centroidal_momentum_matrix(q)[4], atol=1e-4)
    assert "fore at 0.9553 0.0000 0.2955" in source and "-0.2955 0.0000" in source
    assert "-0.9523 -0.3876" in source
