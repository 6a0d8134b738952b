"""simulate on a robot with a ball joint: refused in one line naming the joint (its quaternion is
not stepped by the integrators yet), on a floating base and on a fixed one."""

from __future__ import annotations

import pytest

import lagrangian
from lagrangian.errors import LagrangianError

ARM = """<mujoco model="arm"><worldbody><body name="upper" pos="0 0 1">{free}
<joint name="shoulder" type="ball"/>
<geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03" mass="1"/>
<body name="fore" pos="0 0 -0.3"><joint name="elbow" axis="0 1 0"/>
<geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03" mass="0.5"/>
</body></body></worldbody></mujoco>"""


@pytest.mark.parametrize("floating", [False, True])
def test_simulate_refuses_a_ball_joint_by_name(tmp_path, floating):
    path = tmp_path / "arm.xml"
    path.write_text(ARM.format(free=""))
    system = lagrangian.load(path, **({"floating_base": True} if floating else {}))
    with pytest.raises(LagrangianError, match="'shoulder' is a ball") as caught:
        system.simulate(0.1)
    assert "\n" not in str(caught.value)
