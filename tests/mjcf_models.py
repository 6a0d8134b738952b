"""MJCF robots shared by the tests of the MJCF reader, CasADi and optimize."""

from __future__ import annotations


def leg(trunk_height: float = 0.0) -> str:
    """A floating two-joint leg: a 5 kg trunk on a free joint (full inertia, its centre of mass
    off the origin), a hip about y and a knee about (1, 1, 0) (its thigh turned by euler)."""
    at = "" if trunk_height == 0.0 else f' pos="0 0 {trunk_height:g}"'
    return f"""
<mujoco model="leg">
  <worldbody>
    <body name="trunk"{at}>
      <freejoint name="root"/>
      <inertial pos="0.01 0.02 -0.01" mass="5" fullinertia="0.1 0.2 0.25 0.01 -0.02 0.03"/>
      <body name="thigh" pos="0.2 0.1 0" euler="10 0 20">
        <joint name="hip" axis="0 1 0" pos="0 0 0.02"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03"/>
        <body name="shin" pos="0 0 -0.3">
          <joint name="knee" axis="1 1 0"/>
          <geom type="box" size="0.02 0.03 0.15" pos="0 0 -0.15"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


# a ball, then a hinge, then a ball, each body turned and offset, under tilted gravity
BALL_HINGE_BALL = """<mujoco model="ball_hinge_chain">
  <compiler angle="radian"/>
  <option gravity="0.5 -1 -9.7"/>
  <worldbody>
    <body name="upper" pos="0.1 0 1" quat="0.9 0.1 0.3 0.2">
      <joint name="shoulder" type="ball"/>
      <inertial pos="0 0.03 -0.3" mass="2.0" diaginertia="0.05 0.04 0.02"/>
      <body name="lower" pos="0 0.05 -0.6" euler="0.2 0.1 0">
        <joint name="elbow" type="hinge" axis="0.3 1 0.1" pos="0 0 0.02"/>
        <inertial pos="0.02 0 -0.25" quat="0.8 0.2 0.1 0.3" mass="1.1" diaginertia="0.03 0.02 0.01"/>
        <body name="hand" pos="0 0 -0.5">
          <joint name="wrist" type="ball" pos="0.01 0 0"/>
          <inertial pos="0 0.01 -0.05" mass="0.4" diaginertia="0.002 0.003 0.001"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>"""

# the chain on MuJoCo's free joint instead of its shoulder (a ball wrist below)
FREE_HINGE_BALL = BALL_HINGE_BALL.replace('<joint name="shoulder" type="ball"/>',
                                          '<freejoint name="root"/>')
