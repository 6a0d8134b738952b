"""Payloads (issue 27): ``load(path, payload={link: (mass, (x, y, z))})`` and
``--payload LINK=MASS[@X,Y,Z]`` fix a point mass to a link; the dynamics equal those of the
URDF edited by hand to carry it, and the two-link arm's closed form."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import lagrangian

pytest.importorskip("yourdfpy")

ARM = """<?xml version="1.0"?>
<robot name="tilted">
  <link name="base"/>
  <link name="upper"><inertial><origin xyz="0.5 0 0"/><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.2" iyz="0" izz="0.2"/></inertial></link>
  <link name="fore"><inertial><origin xyz="0.4 0 0" rpy="0 0.2 0"/><mass value="1.5"/>
    <inertia ixx="0.01" ixy="0.002" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="1 0 0" rpy="0.3 0 0"/><axis xyz="0 -1 0"/>
    <limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
  EXTRA
</robot>
"""

EDITED = """<link name="gripper"><inertial><origin xyz="0.3 0.05 -0.02"/><mass value="1.25"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
  <joint name="mount" type="fixed"><parent link="fore"/><child link="gripper"/></joint>"""


def _systems(tmp_path):
    plain, edited = tmp_path / "arm.urdf", tmp_path / "edited.urdf"
    plain.write_text(ARM.replace("EXTRA", ""))
    edited.write_text(ARM.replace("EXTRA", EDITED))
    carried = lagrangian.load(plain, payload={"fore": (1.25, (0.3, 0.05, -0.02))})
    return carried, lagrangian.load(edited)


@pytest.mark.parametrize("backend", ["auto", "numpy"])
def test_a_payload_equals_the_edited_urdf(tmp_path, backend):
    carried, edited = (s.dynamics(backend=backend) for s in _systems(tmp_path))
    rng = np.random.default_rng(4)
    q, v, a = (rng.uniform(-1.5, 1.5, (6, 2)) for _ in range(3))
    for name, args in (("mass_matrix", (q,)), ("bias_forces", (q, v)), ("gravity", (q,)),
                       ("inverse_dynamics", (q, v, a)), ("forward_dynamics", (q, v, a)),
                       ("kinetic_energy", (q, v)), ("potential_energy", (q,))):
        np.testing.assert_allclose(getattr(carried, name)(*args), getattr(edited, name)(*args),
                                   rtol=1e-13, atol=1e-13, err_msg=name)


def test_the_arms_mass_matrix_gains_the_point_mass():
    # 2 kg at 0.5 m along the forearm: M22 += m r^2, M12 += m (r^2 + l r cos), M11 += m (l^2 +
    # r^2 + 2 l r cos), with l = 1 m the upper arm
    m, r, q2 = 2.0, 0.5, 0.5
    base = lagrangian.load("two_link_arm").dynamics().mass_matrix([0.3, q2])
    carried = lagrangian.load("two_link_arm", payload={"fore": (m, (r, 0, 0))})
    added = carried.dynamics().mass_matrix([0.3, q2]) - base
    c = math.cos(q2)
    np.testing.assert_allclose(added, [[m * (1 + r * r + 2 * r * c), m * (r * r + r * c)],
                                       [m * (r * r + r * c), m * r * r]], rtol=1e-12)
    at_origin = lagrangian.load("two_link_arm", payload={"fore": m})  # at the elbow
    np.testing.assert_allclose(at_origin.dynamics().mass_matrix([0.3, q2]) - base,
                               [[m, 0], [0, 0]], atol=1e-12)


@pytest.mark.parametrize("payload, words", [
    ({"forearm": 1.0}, "no link 'forearm'"), ({"fore": -1.0}, "positive"),
    ({"fore": float("inf")}, "positive and finite"), ({"fore": (1.0, (0, 0))}, "three"),
    ({"fore": (1.0,)}, "expected a mass"), ({"fore": "heavy"}, "is not a mass"),
])
def test_bad_payloads_are_refused(payload, words):
    with pytest.raises(lagrangian.InputError, match=words):
        lagrangian.load("two_link_arm", payload=payload)


def test_a_model_file_has_no_links():
    with pytest.raises(lagrangian.InputError, match="only a URDF"):
        lagrangian.load("pendulum", payload={"bob": 1.0})


def test_cli_payload(cli):
    result = cli("dynamics", "two_link_arm", "--q", "0.3,0.5", "--payload", "fore=2kg@0.5,0,0",
                 "--json")
    assert result.code == 0, result.err
    M = np.array(json.loads(result.out)["mass_matrix"])
    assert M[1, 1] == pytest.approx(0.34 + 2 * 0.25, rel=1e-12)
    for text, words in (("fore=2@1,2", "MASS@X,Y,Z"), ("fore", "NAME=VALUE"),
                        ("hand=1", "no link 'hand'"), ("fore=2m", "--payload fore")):
        bad = cli("dynamics", "two_link_arm", "--payload", text)
        assert bad.code == 2 and bad.err.count("\n") == 1 and words in bad.err, (text, bad.err)
