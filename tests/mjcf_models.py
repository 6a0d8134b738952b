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
