"""lagrangian optimize --floating-base: a free-falling leg moved rest to rest by its joints."""

from __future__ import annotations

import json

import numpy as np
import pytest

from lagrangian.cli import main

pytest.importorskip("casadi")

LEG = """<mujoco model="leg"><worldbody><body name="trunk"><freejoint name="root"/>
<inertial pos="0 0 0" mass="5" diaginertia="0.1 0.2 0.25"/>
<body name="thigh" pos="0.2 0 0"><joint name="hip" axis="0 1 0"/>
<geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03"/>
</body></body></worldbody></mujoco>"""


def test_optimize_on_a_floating_base_from_the_command_line(tmp_path, capsys):
    """The goal reached by the hip's torque alone, the base's numbers states of their own (unit
    quaternions throughout), and the trunk falling: nothing holds it (the library's test,
    tests/control/test_optimize_floating.py, checks the free fall of the centre of mass)."""
    path = tmp_path / "leg.xml"
    path.write_text(LEG)
    with pytest.raises(SystemExit) as exit_info:
        main(["optimize", str(path), "--floating-base", "--to", "hip=1,hip_dot=0",
              "--t-final", "0.4", "--nodes", "15", "--method", "hermite-simpson",
              "--input", "hip", "--json"])
    assert exit_info.value.code == 0
    document = json.loads(capsys.readouterr().out)
    assert document["converged"]
    states = document["states"]
    assert list(states)[:7] == ["base_x", "base_y", "base_z", "base_qx", "base_qy", "base_qz",
                                "base_qw"]
    assert states["hip"][-1] == pytest.approx(1.0, abs=1e-9)
    assert states["hip_dot"][-1] == pytest.approx(0.0, abs=1e-9)
    quaternion = np.array([states[f"base_q{k}"] for k in "xyzw"])
    assert np.abs(np.linalg.norm(quaternion, axis=0) - 1).max() < 1e-6
    assert states["base_z"][-1] < 0.0  # nothing holds it: it falls


def test_optimize_floating_base_refuses_a_model_file_in_one_line(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["optimize", "pendulum", "--floating-base", "--to", "theta=1"])
    assert exit_info.value.code == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "Traceback" not in error
