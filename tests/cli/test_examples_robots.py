"""`lagrangian examples --robots`: example-robot-data's URDFs by short name and path, and
load() / the CLI taking those names (a built-in example of the same name comes first)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

import lagrangian

ARM = Path(lagrangian.example_path("two_link_arm"))


@pytest.fixture
def robots(tmp_path, monkeypatch):
    """A robots/ folder laid out as example-robot-data's (PACKAGE/urdf/NAME.urdf), each file
    the built-in two-link arm."""
    for where in ("ur_description/urdf/ur5_robot.urdf", "ur_description/urdf/ur5_gripper.urdf",
                  "anymal_b_simple_description/robots/anymal.urdf",
                  "anymal_c_simple_description/urdf/anymal.urdf",
                  "talos_data/robots/talos_reduced.urdf",
                  "double_pendulum_description/urdf/double_pendulum.urdf"):
        path = tmp_path / where
        path.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(ARM, path)
    monkeypatch.setenv("EXAMPLE_ROBOT_DATA_DIR", str(tmp_path))
    return tmp_path


def test_short_names_follow_the_files_and_the_loaders(robots, cli):
    code, out, err = cli("examples", "--robots", "--json")
    assert code == 0, err
    listed = {r["name"]: (r["path"], r["shadowed"]) for r in json.loads(out)["robots"]}
    assert listed == {
        "anymal": (str(robots / "anymal_b_simple_description/robots/anymal.urdf"), False),
        "anymal_c": (str(robots / "anymal_c_simple_description/urdf/anymal.urdf"), False),
        "double_pendulum": (str(robots / "double_pendulum_description/urdf/"
                                         "double_pendulum.urdf"), True),
        "talos": (str(robots / "talos_data/robots/talos_reduced.urdf"), False),
        "talos_reduced": (str(robots / "talos_data/robots/talos_reduced.urdf"), False),
        "ur5": (str(robots / "ur_description/urdf/ur5_robot.urdf"), False),
        "ur5_gripper": (str(robots / "ur_description/urdf/ur5_gripper.urdf"), False),
        "ur5_robot": (str(robots / "ur_description/urdf/ur5_robot.urdf"), False),
    }
    code, out, _ = cli("examples", "--robots")
    assert code == 0
    line = next(x for x in out.splitlines() if x.startswith("double_pendulum "))
    assert "built-in example has this name" in line


def test_a_short_name_loads_the_robot_and_a_built_in_example_comes_first(robots, cli):
    by_name, by_path = lagrangian.load("ur5"), lagrangian.load(robots / "ur_description/urdf/"
                                                                "ur5_robot.urdf")
    assert by_name.joint_names == by_path.joint_names == {"shoulder": "shoulder",
                                                          "elbow": "elbow"}
    assert by_name.joint_limits == by_path.joint_limits
    # the built-in double pendulum (a model file, two particles), not the robot of that name
    assert lagrangian.load("double_pendulum").model.kinematic_tree is None
    code, _, err = cli("dynamics", "ur5", "--q", "1")
    assert code == 2 and "(shoulder, elbow), got 1" in err


def test_an_unknown_name_suggests_a_robot(robots, cli):
    code, _, err = cli("derive", "ur6")
    assert code == 2
    assert err.strip() == ("error: no such file or built-in example 'ur6'; did you mean 'ur5'? "
                           "(`lagrangian examples` lists them; `lagrangian examples --robots` "
                           "the robots)")


def test_without_example_robot_data_it_says_so(tmp_path, monkeypatch, cli):
    monkeypatch.setenv("EXAMPLE_ROBOT_DATA_DIR", str(tmp_path / "absent"))
    code, out, _ = cli("examples", "--robots")
    assert code == 0 and "example-robot-data is not installed" in out
    assert json.loads(cli("examples", "--robots", "--json").out) == {"robots": []}


def test_the_installed_panda_by_its_name():
    installed = {r["name"]: r for r in lagrangian.example_robots()}
    if "panda" not in installed:
        pytest.skip("example-robot-data is not installed")
    panda = lagrangian.load("panda")
    # the second finger is a mimic of the first: 7 arm joints and one finger coordinate
    assert [c.name for c in panda.model.coordinates] == \
        [f"panda_joint{i}" for i in range(1, 8)] + ["panda_finger_joint1"]
    assert Path(installed["panda"]["path"]).name == "panda.urdf"
    for name in ("ur5", "solo12", "talos"):
        assert name in installed


def test_the_documented_commands(cli):
    # docs/robotics.md's robotics-robots block: each command runs, each error: or warning:
    # line under it is what it prints (on the installed robots)
    import re
    import shlex
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from docs_blocks import block

    if "panda" not in {r["name"] for r in lagrangian.example_robots()}:
        pytest.skip("example-robot-data is not installed")
    (console,) = re.findall(r"```console\n(.*?)```", block("robotics-robots"), re.S)
    runs: list[tuple[list[str], list[str]]] = []
    for line in console.splitlines():
        if line.startswith("$ "):
            runs.append((shlex.split(line[2:])[1:], []))
        else:
            runs[-1][1].append(line)
    for args, expected in runs:
        code, out, err = cli(*args)
        assert code == (2 if any(x.startswith("error:") for x in expected) else 0), (args, err)
        for line in expected:
            assert line in err.splitlines(), (args, line, err)
        if "--json" in args:
            assert json.loads(out)["coordinates"][-1] == "panda_finger_joint1"
