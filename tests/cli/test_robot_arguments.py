"""Robot arguments on the command line: --lock as a comma list, the coordinates named in a
count error of --q and --v (a floating base's q and v differ), a lock's unit and limit."""

import pytest

pytest.importorskip("yourdfpy")


def test_a_comma_list_locks_every_joint_it_names(cli):
    # two_link_arm has two joints: locking both in one --lock leaves none to move
    code, out, err = cli("kinematics", "two_link_arm", "--lock", "shoulder=0,elbow=30deg")
    assert code == 2
    assert "no joint left to move" in err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1


def _one_line(result):
    code, _, err = result
    assert code == 2 and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1, err
    return err.strip()


def test_a_wrong_count_names_the_coordinates(cli):
    line = _one_line(cli("dynamics", "two_link_arm", "--q", "1,2,3"))
    assert line == "error: --q: expected 2 comma-separated values (shoulder, elbow), got 3"
    line = _one_line(cli("kinematics", "two_link_arm", "--v", "1"))
    assert "(shoulder, elbow), got 1" in line


def test_a_floating_base_names_q_with_its_quaternion_and_v_with_its_twist(cli):
    # q: the base's position and unit quaternion (7) and the joints; v: its twist (6), the rates
    line = _one_line(cli("dynamics", "two_link_arm", "--floating-base", "--q", "0,0"))
    assert ("expected 9 comma-separated values (base_x, base_y, base_z, base_qx, base_qy, "
            "base_qz, base_qw, shoulder, elbow), got 2") in line
    line = _one_line(cli("dynamics", "two_link_arm", "--floating-base", "--v", "0,0"))
    assert ("expected 8 comma-separated values (base_vx, base_vy, base_vz, base_wx, base_wy, "
            "base_wz, shoulder, elbow), got 2") in line


SLIDER = """<?xml version="1.0"?>
<robot name="slider">
  <link name="base"/>
  <link name="carriage"><inertial><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <link name="arm"><inertial><origin xyz="0.5 0 0"/><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="slide" type="prismatic"><parent link="base"/><child link="carriage"/>
    <axis xyz="0 0 1"/><limit lower="0" upper="0.5" effort="5" velocity="1"/></joint>
  <joint name="hinge" type="revolute"><parent link="carriage"/><child link="arm"/>
    <axis xyz="0 -1 0"/><limit lower="-1" upper="1" effort="5" velocity="2"/></joint>
</robot>
"""


@pytest.fixture(scope="module")
def slider(tmp_path_factory):
    path = tmp_path_factory.mktemp("robot") / "slider.urdf"
    path.write_text(SLIDER)
    return str(path)


@pytest.mark.parametrize(("lock", "message"), [
    ("hinge=1kg", "error: --lock hinge: '1kg' is not an angle (joint 'hinge' is revolute)"),
    ("hinge=1m", "error: --lock hinge: '1m' is not an angle (joint 'hinge' is revolute)"),
    ("slide=30deg", "error: --lock slide: '30deg' is not a length (joint 'slide' is prismatic)"),
    ("slide=2kg", "error: --lock slide: '2kg' is not a length (joint 'slide' is prismatic)"),
])
def test_a_lock_in_the_wrong_dimension_is_refused_in_one_line(cli, slider, lock, message):
    assert _one_line(cli("dynamics", slider, "--lock", lock)) == message


def test_a_lock_takes_its_joints_unit(cli, slider):
    # the carriage locked 20 cm up a vertical slide (welded to the world, it no longer moves),
    # the arm (2 kg, centre 0.5 m out) turning about -y: V = 2 g (s + 0.5 sin q), torque
    # 2 g 0.5 cos q; read as 20 m (or 20 rad), V would be a hundred times larger
    import json
    import math

    code, out, err = cli("dynamics", slider, "--lock", "slide=20cm", "--q", "0.3", "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["coordinates"] == ["hinge"]
    assert doc["gravity"] == pytest.approx([2 * 9.81 * 0.5 * math.cos(0.3)], rel=1e-12)
    potential = 2 * 9.81 * (0.2 + 0.5 * math.sin(0.3))
    assert doc["potential_energy"] == pytest.approx(potential, rel=1e-12)


def test_a_lock_beyond_the_limit_is_warned_as_q_is(cli, slider):
    # --q hinge=3 and --lock hinge=3: the same warning, by the flag that gave it
    code, _, err_q = cli("dynamics", slider, "--lock", "slide=0.1", "--q", "3")
    assert code == 0
    code, _, err_lock = cli("dynamics", slider, "--lock", "hinge=3")
    assert code == 0
    tail = "=3 rad is beyond the position limit [-1, 1] rad of URDF joint 'hinge'"
    assert f"warning: --q hinge{tail}" in err_q
    assert f"warning: --lock hinge{tail}" in err_lock
    code, _, err = cli("dynamics", slider, "--lock", "slide=0.6m")  # a length past its 0.5 m
    assert "warning: --lock slide=0.6 m is beyond the position limit [0, 0.5] m" in err


def test_python_lock_texts_and_limits(slider):
    import warnings

    import lagrangian

    def lock_warnings(lock):
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            system = lagrangian.load(slider, lock=lock)
        return system, [str(w.message) for w in seen
                        if issubclass(w.category, lagrangian.ModelWarning)
                        and "beyond" in str(w.message)]

    system, lines = lock_warnings({"slide": "30cm"})  # a text with its unit: within 0..0.5 m
    assert lines == [] and system.model.potential_energy is not None
    _, lines = lock_warnings({"hinge": 2.0})  # a number: SI (rad)
    assert lines == ["lock hinge=2 rad is beyond the position limit [-1, 1] rad of URDF joint "
                     "'hinge'"]
    with pytest.raises(lagrangian.ModelError, match="not an angle"):
        lagrangian.load(slider, lock={"hinge": "1kg"})


def test_a_lock_warns_exactly_as_q_does(cli):
    # 100 rad on the two-link arm's shoulder: a bare angle beyond a turn, and beyond its limit
    code, _, err_q = cli("dynamics", "two_link_arm", "--q", "100,0")
    assert code == 0
    code, _, err_lock = cli("dynamics", "two_link_arm", "--lock", "shoulder=100")
    assert code == 0
    from_q = [line.replace("--q ", "", 1) for line in err_q.splitlines() if "--q " in line]
    from_lock = [line.replace("--lock ", "", 1) for line in err_lock.splitlines()
                 if "--lock " in line]
    assert from_q == from_lock and len(from_q) == 2
    assert "is read as 100 rad (5729.58 deg); write 100deg for degrees" in from_q[0]
