"""Robot arguments on the command line: --lock as a comma list (the rest of the issue's items,
coordinate names in a count error and a lock's unit and limit, are still to come)."""


def test_a_comma_list_locks_every_joint_it_names(cli):
    # two_link_arm has two joints: locking both in one --lock leaves none to move
    code, out, err = cli("kinematics", "two_link_arm", "--lock", "shoulder=0,elbow=30deg")
    assert code == 2
    assert "no joint left to move" in err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
