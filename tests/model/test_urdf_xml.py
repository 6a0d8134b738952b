"""The URDF reader on the standard library (model/urdf_xml.py): the specification's defaults
and rpy convention, entities refused (never expanded or fetched), and each fault named in
one line with its element."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import lagrangian
from lagrangian.errors import ModelError
from lagrangian.model.urdf_xml import parse_robot

ARM = (Path(lagrangian.__file__).parent / "model/examples/two_link_arm.urdf").read_text()
BODY = ARM.split("?>", 1)[-1]


@pytest.mark.parametrize("rpy", [(0.3, -0.7, 1.9), (np.pi / 2, 0, 0), (0.1, np.pi / 2, -2.5)])
def test_rpy_is_roll_pitch_yaw_about_fixed_axes(rpy):
    """R = Rz(yaw) Ry(pitch) Rx(roll): scipy's extrinsic x-y-z Euler angles, an independent
    construction of the same rotation."""
    text = (f'<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="fixed">'
            f'<parent link="a"/><child link="b"/><origin xyz="1 2 3" rpy="{rpy[0]!r} {rpy[1]!r} '
            f'{rpy[2]!r}"/></joint></robot>')
    origin = parse_robot(text, "r.urdf").joints[0].origin
    np.testing.assert_allclose(origin[:3, :3], Rotation.from_euler("xyz", rpy).as_matrix(),
                               atol=1e-15)
    np.testing.assert_array_equal(origin[:3, 3], [1, 2, 3])
    np.testing.assert_array_equal(origin[3], [0, 0, 0, 1])


def test_the_specifications_defaults():
    """No origin: none (the identity); no axis: x; a mimic's multiplier 1 and offset 0."""
    text = ('<robot name="r"><link name="a"/><link name="b"/><link name="c"/>'
            '<joint name="j" type="revolute"><parent link="a"/><child link="b"/></joint>'
            '<joint name="k" type="revolute"><parent link="b"/><child link="c"/>'
            '<origin/><axis/><mimic joint="j"/><limit upper="1"/></joint></robot>')
    j, k = parse_robot(text, "r.urdf").joints
    assert j.origin is None and j.limit is None and j.mimic is None
    np.testing.assert_array_equal(j.axis, [1, 0, 0])
    np.testing.assert_array_equal(k.origin, np.eye(4))
    np.testing.assert_array_equal(k.axis, [1, 0, 0])
    assert (k.mimic.joint, k.mimic.multiplier, k.mimic.offset) == ("j", 1.0, 0.0)
    assert (k.limit.lower, k.limit.upper) == (None, 1.0)


def test_visuals_and_meshes_are_never_read(tmp_path):
    """A mesh that does not exist, in visual and collision elements: the arm reads as before."""
    mesh = '<visual><geometry><mesh filename="package://gone/arm.stl"/></geometry></visual>' \
           '<collision><geometry><mesh filename="/nowhere.dae"/></geometry></collision>'
    text = ARM.replace('<link name="fore">', f'<link name="fore">{mesh}')
    path = tmp_path / "arm.urdf"
    path.write_text(text)
    M = lagrangian.load(path).dynamics().mass_matrix([0.3, 0.7])
    assert M[1, 1] == pytest.approx(0.34, rel=1e-12)


LAUGHS = ('<?xml version="1.0"?>\n<!DOCTYPE robot [<!ENTITY a "aaaaaaaaaa">'
          '<!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;"><!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;">]>')
EXTERNAL = '<?xml version="1.0"?>\n<!DOCTYPE robot [<!ENTITY x SYSTEM "file:///etc/passwd">]>'


@pytest.mark.parametrize("header, name, words", [
    (LAUGHS, "&c;", "an entity declaration"),
    (EXTERNAL, "&x;", "an entity declaration"),
    ('<!DOCTYPE robot SYSTEM "http://example.invalid/urdf.dtd">', "x", "an external DTD"),
    ("", "&x;", "undefined entity"),
])
def test_entities_are_refused_never_expanded(cli, tmp_path, header, name, words):
    path = tmp_path / "robot.urdf"
    path.write_text(header + BODY.replace('name="two_link_arm"', f'name="{name}"'))
    with pytest.raises(ModelError, match=words) as info:
        lagrangian.load(path)
    assert str(path) in str(info.value) and "\n" not in str(info.value)
    code, out, err = cli("derive", str(path))
    assert code == 2 and err.startswith("error: ") and err.count("\n") == 1 and not out


def test_a_doctype_without_entities_is_read(tmp_path):
    path = tmp_path / "robot.urdf"
    path.write_text('<?xml version="1.0"?>\n<!DOCTYPE robot>' + BODY)
    assert [str(q) for q in lagrangian.load(path).coordinates] == ["shoulder", "elbow"]


@pytest.mark.parametrize("edit, words", [
    (("<robot ", "<robt "), "not well-formed XML"),
    (('<robot name="two_link_arm">', '<model name="two_link_arm">'), None),
    (('<robot name="two_link_arm">', "<robot>"), "robot: a <robot> without a name"),
    (('<joint name="elbow"', "<joint"), "joint: a <joint> without a name"),
    (('<link name="fore">', "<link>"), "link: a <link> without a name"),
    (('<parent link="upper"/>', ""), "joint 'elbow': no <parent link"),
    (('<origin xyz="1 0 0" rpy="0 0 0"/>', '<origin xyz="1 0" rpy="0 0 0"/>'),
     "joint 'elbow'.origin: xyz=\"1 0\" is not 3 numbers"),
    (('<axis xyz="0 -1 0"/>', '<axis xyz="0 y 0"/>'),  # both joints: the first is named
     "joint 'shoulder'.axis: xyz=\"0 y 0\" is not 3 numbers"),
    (('<mass value="1.5"/>', '<mass value="heavy"/>'),
     "link 'fore'.inertial.mass.value: value=\"heavy\" is not a number"),
    (('lower="-3.1" upper="3.1" effort="30"', 'lower="-3.1" upper="pi" effort="30"'),
     "joint 'elbow'.limit.upper"),
])
def test_faults_are_named(tmp_path, edit, words):
    text = ARM.replace(*edit)
    assert text != ARM
    if words is None:  # the model's closing tag no longer matches: not well-formed either way
        text = text.replace("</robot>", "</model>")
        words = "the root element is <model>, not <robot>"
    path = tmp_path / "robot.urdf"
    path.write_text(text)
    with pytest.raises(ModelError) as info:
        lagrangian.load(path)
    assert words in str(info.value) and str(path) in str(info.value)
    assert "\n" not in str(info.value)
