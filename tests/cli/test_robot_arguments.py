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
