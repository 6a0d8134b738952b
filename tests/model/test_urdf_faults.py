"""URDF files read as a robot's file says, or refused in one line (issue 21): duplicate link or
joint names are refused (urdfdom refuses them; keeping the last made M 80-100x too large), a
link of mass 0 with an inertia tensor keeps its rotational inertia (as Pinocchio does), and
numbers that are not finite are named with their joint."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import ModelError

pytestmark = pytest.mark.smoke  # pytest -m smoke: the quick subset

ARM = (Path(lagrangian.__file__).parent / "model/examples/two_link_arm.urdf").read_text()


def load(tmp_path, text, name="robot.urdf"):
    path = tmp_path / name
    path.write_text(text)
    return lagrangian.load(path)


def test_the_arm_as_written_is_its_closed_form(tmp_path):
    """M11 = 2.54 + 1.2 cos(elbow), M12 = 0.34 + 0.6 cos(elbow), M22 = 0.34 (the file's note)."""
    arm = load(tmp_path, ARM).dynamics()
    for elbow in (0.0, 0.7, 2.0):
        M = arm.mass_matrix([0.3, elbow])
        np.testing.assert_allclose(M, [[2.54 + 1.2 * np.cos(elbow), 0.34 + 0.6 * np.cos(elbow)],
                                       [0.34 + 0.6 * np.cos(elbow), 0.34]], rtol=1e-12)


@pytest.mark.parametrize("kind, text", [
    ("link", ARM.replace('<link name="fore">', '<link name="upper">')),
    ("joint", ARM.replace('<joint name="elbow"', '<joint name="shoulder"')),
])
def test_two_items_of_one_name_are_refused(tmp_path, kind, text):
    with pytest.raises(ModelError, match=f"two {kind}s are named '(upper|shoulder)'") as error:
        load(tmp_path, text)
    assert "robot.urdf" in str(error.value) and "\n" not in str(error.value)


def test_a_massless_link_keeps_its_inertia_tensor(tmp_path):
    """The forearm with mass 0 but I_yy = 0.1 about its centre 0.4 m out: only the tensor
    remains, so M22 = 0.1, M12 = 0.1, M11 = 0.2 + 2 * 0.25 + 0.1 (upper arm 0.2 + m c^2)."""
    text = ARM.replace('<mass value="1.5"/>', '<mass value="0.0"/>')
    arm = load(tmp_path, text)
    for backend in ("auto", "numpy"):
        M = arm.dynamics(backend=backend).mass_matrix([0.3, 1.1])
        np.testing.assert_allclose(M, [[0.2 + 2.0 * 0.25 + 0.1, 0.1], [0.1, 0.1]], rtol=1e-12)
    # the derived equations agree with the recursive algorithms
    eom = arm.equations_of_motion()
    symbolic = np.array(eom.mass_matrix.subs({arm.symbol("shoulder"): 0.3,
                                              arm.symbol("elbow"): 1.1}), dtype=float)
    np.testing.assert_allclose(symbolic, [[0.8, 0.1], [0.1, 0.1]], rtol=1e-12)


def test_a_massless_link_matches_pinocchio(tmp_path):
    pin = pytest.importorskip("pinocchio")
    text = ARM.replace('<mass value="1.5"/>', '<mass value="0.0"/>').replace(
        '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.1"', '<inertia ixx="0.03" ixy="0.01" ixz="0" iyy="0.1"')
    path = tmp_path / "robot.urdf"
    path.write_text(text)
    ours = lagrangian.load(path).dynamics()
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    rng = np.random.default_rng(3)
    for _ in range(5):
        q, v, a = rng.normal(size=(3, 2))
        np.testing.assert_allclose(ours.mass_matrix(q), pin.crba(model, data, q), atol=1e-14)
        np.testing.assert_allclose(ours.inverse_dynamics(q, v, a),
                                   pin.rnea(model, data, q, v, a), atol=1e-13)


@pytest.mark.parametrize("edit, field", [
    (('<origin xyz="1 0 0" rpy="0 0 0"/>', '<origin xyz="inf 0 0" rpy="0 0 0"/>'),
     "joint 'elbow'.origin"),
    (('<limit lower="-3.1" upper="3.1" effort="30"', '<mimic joint="shoulder" multiplier="nan"/>'
      '<limit lower="-3.1" upper="3.1" effort="30"'), "joint 'elbow'.mimic.multiplier"),
    (('<axis xyz="0 -1 0"/>\n    <limit lower="-3.1" upper="3.1" effort="30"',
      '<axis xyz="0 nan 0"/>\n    <limit lower="-3.1" upper="3.1" effort="30"'),
     "joint 'elbow'.axis"),
])
def test_numbers_that_are_not_finite_are_named(tmp_path, edit, field):
    text = ARM.replace(*edit)
    assert text != ARM
    with pytest.raises(ModelError, match="not finite") as error:
        load(tmp_path, text)
    assert field in str(error.value)


def test_the_cli_says_it_in_one_line(cli, tmp_path):
    path = tmp_path / "robot.urdf"
    path.write_text(ARM.replace('<link name="fore">', '<link name="upper">'))
    result = cli("dynamics", str(path), "--q", "0,0")
    assert result.code == 2 and result.err.count("\n") == 1 and result.err.startswith("error: ")


@pytest.mark.parametrize("edit, field, words", [
    # yourdfpy reads a missing value as 0 and a missing moment as 1 (kg m^2): urdfdom refuses
    (('<mass value="1.5"/>', '<mass/>'), "link 'fore'.inertial.mass", "no value"),
    (('<mass value="1.5"/>', ''), "link 'fore'.inertial.mass", "no <mass>"),
    (('iyy="0.1" ', ''), "link 'fore'.inertial.inertia", "iyy"),
    (('<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/>', ''),
     "link 'fore'.inertial.inertia", "no <inertia>"),
])
def test_an_inertial_missing_a_number_is_refused(tmp_path, edit, field, words):
    text = ARM.replace(*edit)
    assert text != ARM
    with pytest.raises(ModelError, match=words) as error:
        load(tmp_path, text)
    assert field in str(error.value) and "\n" not in str(error.value)


@pytest.mark.parametrize("edit, field", [
    (('<mass value="1.5"/>', '<mass value="1e308"/>'), "link 'fore'.inertial.mass"),
    (('<origin xyz="1 0 0" rpy="0 0 0"/>', '<origin xyz="1e200 0 0" rpy="0 0 0"/>'),
     "joint 'elbow'.origin"),
    (('iyy="0.1"', 'iyy="1e250"'), "link 'fore'.inertial.inertia"),
])
def test_numbers_too_large_to_multiply_are_refused(tmp_path, edit, field):
    """M = m r^2 of a mass of 1e308 or a length of 1e200 is inf: printed as a result before."""
    text = ARM.replace(*edit)
    assert text != ARM
    with pytest.raises(ModelError, match="too large") as error:
        load(tmp_path, text)
    assert field in str(error.value)


def test_a_large_but_finite_robot_is_still_read(tmp_path):
    """A 1000 kg forearm 20 m out: M22 = I + m c^2 = 0.1 + 1000 * 8^2 (c = 0.4 * 20)."""
    text = ARM.replace('<mass value="1.5"/>', '<mass value="1000"/>').replace(
        '<origin xyz="0.4 0 0" rpy="0 0 0"/>', '<origin xyz="8 0 0" rpy="0 0 0"/>')
    M = load(tmp_path, text).dynamics().mass_matrix([0.0, 0.3])
    assert M[1, 1] == pytest.approx(0.1 + 1000 * 64, rel=1e-12)


def test_huge_joint_limits_are_only_a_range(tmp_path):
    text = ARM.replace('lower="-3.1" upper="3.1" effort="30"',
                       'lower="-1.79769e+308" upper="1.79769e+308" effort="30"')
    assert text != ARM
    M = load(tmp_path, text).dynamics().mass_matrix([0.3, 0.0])
    assert M[1, 1] == pytest.approx(0.34, rel=1e-12)
