"""Frames of a model file (dynamics/model_frames.py): the double pendulum's bobs and centre of
mass against their closed forms, a rigid body's angular Jacobian against the derivative of its
rotation, and a model-file spatial chain against the same chain read as a URDF (frames.py)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import InputError

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
L1, L2, M1, M2 = 1.5, 0.7, 2.0, 1.0
REFERENCES = ("world", "local", "local_world_aligned")


@pytest.fixture(scope="module")
def pendulum():
    return lagrangian.load("double_pendulum").dynamics(
        {"l1": L1, "l2": L2, "m1": M1, "m2": M2, "g": 9.81})


def test_double_pendulum_bob_and_its_jacobian_are_the_closed_form(pendulum):
    rng = np.random.default_rng(3)
    q, v = rng.uniform(-3, 3, (7, 2)), rng.uniform(-2, 2, (7, 2))
    s1, c1, s2, c2 = np.sin(q[:, 0]), np.cos(q[:, 0]), np.sin(q[:, 1]), np.cos(q[:, 1])
    T = pendulum.placement(q, "bob2")
    assert T.shape == (7, 4, 4)
    assert np.allclose(T[:, :3, :3], np.eye(3), atol=1e-15)  # a point: the world's axes
    assert np.allclose(T[:, :3, 3], np.stack([L1 * s1 + L2 * s2, -L1 * c1 - L2 * c2,
                                              0 * s1], axis=1), atol=1e-14)
    J = pendulum.jacobian(q, "bob2")
    assert J.shape == (7, 6, 2)
    assert np.allclose(J[:, 0], np.stack([L1 * c1, L2 * c2], axis=1), atol=1e-14)
    assert np.allclose(J[:, 1], np.stack([L1 * s1, L2 * s2], axis=1), atol=1e-14)
    assert np.allclose(J[:, 2:], 0.0)
    # the bob's acceleration at rest rates' second derivative: -l w^2 toward each pivot
    a = pendulum.jacobian_dot_times_v(q, v, "bob2")
    w1, w2 = v[:, 0] ** 2, v[:, 1] ** 2
    assert np.allclose(a[:, 0], -L1 * s1 * w1 - L2 * s2 * w2, atol=1e-13)
    assert np.allclose(a[:, 1], L1 * c1 * w1 + L2 * c2 * w2, atol=1e-13)
    assert np.allclose(a[:, 2:], 0.0)


def test_double_pendulum_centre_of_mass_by_hand(pendulum):
    q = np.array([0.4, -1.1])
    r1 = L1 * np.array([np.sin(q[0]), -np.cos(q[0]), 0.0])
    r2 = r1 + L2 * np.array([np.sin(q[1]), -np.cos(q[1]), 0.0])
    assert np.allclose(pendulum.center_of_mass(q), (M1 * r1 + M2 * r2) / (M1 + M2), atol=1e-15)
    J1 = L1 * np.array([[np.cos(q[0]), 0.0], [np.sin(q[0]), 0.0], [0.0, 0.0]])
    J2 = J1 + L2 * np.array([[0.0, np.cos(q[1])], [0.0, np.sin(q[1])], [0.0, 0.0]])
    assert np.allclose(pendulum.center_of_mass_jacobian(q), (M1 * J1 + M2 * J2) / (M1 + M2),
                       atol=1e-15)


def test_rigid_body_angular_jacobian_is_the_rotation_rate():
    """R^T R_dot = [w_local]x and R_dot R^T = [w_world]x, R_dot by central differences."""
    top = lagrangian.load("heavy_top").dynamics()
    frame = top.frames[0]
    rng = np.random.default_rng(5)
    for _ in range(3):
        q, v = rng.uniform(0.3, 1.2, 3), rng.uniform(-2, 2, 3)
        h = 1e-6
        R = top.placement(q, frame)[:3, :3]
        R_dot = (top.placement(q + h * v, frame) - top.placement(q - h * v, frame))[:3, :3] / (2 * h)
        local = R.T @ R_dot
        world = R_dot @ R.T
        w_local = top.jacobian(q, frame, "local")[3:] @ v
        w_world = top.jacobian(q, frame, "local_world_aligned")[3:] @ v
        assert np.allclose(local, -local.T, atol=1e-8)
        assert np.allclose([local[2, 1], local[0, 2], local[1, 0]], w_local, atol=1e-8)
        assert np.allclose([world[2, 1], world[0, 2], world[1, 0]], w_world, atol=1e-8)


@pytest.mark.parametrize("n", [3, 6])  # derived equations; the tree's recursions (6 bodies)
def test_model_file_chain_agrees_with_the_same_chain_as_urdf(tmp_path, n):
    pytest.importorskip("yourdfpy")
    sys.path.insert(0, str(BENCHMARKS))
    try:
        from model_files import spatial_chain, spatial_chain_urdf
    finally:
        sys.path.remove(str(BENCHMARKS))
    (tmp_path / "chain.toml").write_text(spatial_chain(n), encoding="utf-8")
    (tmp_path / "chain.urdf").write_text(spatial_chain_urdf(n), encoding="utf-8")
    model = lagrangian.load(str(tmp_path / "chain.toml")).dynamics()
    urdf = lagrangian.load(str(tmp_path / "chain.urdf")).dynamics()
    rng = np.random.default_rng(n)
    q, v = rng.uniform(-2, 2, (5, n)), rng.uniform(-2, 2, (5, n))
    for frame in (f"link{i}" for i in range(n)):
        assert np.abs(model.placement(q, frame) - urdf.placement(q, frame)).max() < 1e-12
        for reference in REFERENCES:
            assert np.abs(model.jacobian(q, frame, reference)
                          - urdf.jacobian(q, frame, reference)).max() < 1e-12
            assert np.abs(model.jacobian_dot_times_v(q, v, frame, reference)
                          - urdf.jacobian_dot_times_v(q, v, frame, reference)).max() < 1e-12
    assert np.abs(model.center_of_mass(q) - urdf.center_of_mass(q)).max() < 1e-12
    assert np.abs(model.center_of_mass_jacobian(q) - urdf.center_of_mass_jacobian(q)).max() < 1e-12
    assert np.abs(model.kinematics.centroidal_momentum_matrix(q)
                  - urdf.centroidal_momentum_matrix(q)).max() < 1e-12


def test_bad_frames_and_shapes_are_refused_in_one_line(pendulum):
    with pytest.raises(InputError, match=r"no frame named 'bob3'; did you mean 'bob2'") as e:
        pendulum.placement([0.1, 0.2], "bob3")
    assert e.value.field == "frame"
    with pytest.raises(InputError, match="named by a string, not a list") as e:
        pendulum.placement([0.1, 0.2], ["bob1"])
    with pytest.raises(InputError, match="expected 2 values") as e:
        pendulum.jacobian([0.1, 0.2, 0.3], "bob1")
    with pytest.raises(InputError, match="unknown reference"):
        pendulum.jacobian([0.1, 0.2], "bob1", "global")


def test_cli_frames_of_a_model_file(cli):
    import json

    result = cli("kinematics", "double_pendulum", "--q", "0.3,-0.4", "--frame", "bob2",
                 "--v", "1,0", "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    p = np.array(document["placement"])[:3, 3]
    assert np.allclose(p, [np.sin(0.3) + np.sin(-0.4), -np.cos(0.3) - np.cos(-0.4), 0.0])
    assert np.allclose(document["jacobian_dot_times_v"][:2], [-np.sin(0.3), np.cos(0.3)])
    bad = cli("kinematics", "double_pendulum", "--frame", "bob")
    assert bad.code == 2
    assert bad.err.strip().startswith("error: --frame: no frame named 'bob'")
    assert len(bad.err.strip().splitlines()) == 1


def test_a_force_on_a_bob_is_its_jacobian_transpose(pendulum):
    """A force f at bob2 does virtual work f . dr: Q = [l1 (c1 fx + s1 fy), l2 (c2 fx + s2 fy)];
    a moment on a point does none."""
    q, v, a = np.array([0.3, -0.8]), np.array([0.5, 1.0]), np.array([0.1, -0.2])
    f = np.array([2.0, -3.0, 0.0])
    expected = np.array([L1 * (np.cos(q[0]) * f[0] + np.sin(q[0]) * f[1]),
                         L2 * (np.cos(q[1]) * f[0] + np.sin(q[1]) * f[1])])
    wrench = {"bob2": [*f, 0.0, 0.0, 5.0]}
    tau = pendulum.inverse_dynamics(q, v, a, f_ext=wrench)
    assert np.allclose(pendulum.inverse_dynamics(q, v, a) - tau, expected, atol=1e-12)
    assert np.allclose(pendulum.forward_dynamics(q, v, tau, f_ext=wrench), a, atol=1e-12)


def test_docs_example_runs_and_its_command_is_the_closed_form(capsys, cli):
    import json
    import re

    from tests.docs_blocks import block

    text = block("model-frames")
    code = re.findall(r"```python\n(.*?)```", text, re.S)[0]
    exec(compile(code, "model-frames", "exec"), {})
    assert "('bob1', 'bob2')" in capsys.readouterr().out
    command = re.findall(r"\$ lagrangian (.*)", text)[0].split()
    result = cli(*command)
    assert result.code == 0, result.err
    document = json.loads(result.out)
    q1, q2 = 0.3, -0.4  # l1 = l2 = 1 m; the bob moves at l1 per rad of q1, across the rod
    assert document["frame"] == "bob2" and document["coordinates"] == ["theta1", "theta2"]
    assert np.allclose(np.array(document["jacobian"])[:2],
                       [[np.cos(q1), np.cos(q2)], [np.sin(q1), np.sin(q2)]], atol=1e-12)
    assert np.allclose(document["center_of_mass"],
                       [np.sin(q1) + np.sin(q2) / 2, -np.cos(q1) - np.cos(q2) / 2, 0.0])


def test_planar_body_turns_about_z_and_moves_across_its_arm():
    """A uniform link pinned at the origin: its centre at L/2 (sin t, -cos t), its axes turned
    by t; in its own axes the centre moves at L/2 per rad along its x, and w = t_dot about z."""
    link = lagrangian.load("virtual_work_link").dynamics()
    theta, half = 0.5, 0.25
    T = link.placement([theta], "link")
    c, s = np.cos(theta), np.sin(theta)
    assert np.allclose(T[:3, :3], [[c, -s, 0], [s, c, 0], [0, 0, 1]], atol=1e-15)
    assert np.allclose(T[:3, 3], [half * s, -half * c, 0.0], atol=1e-15)
    assert np.allclose(link.jacobian([theta], "link", "local")[:, 0], [half, 0, 0, 0, 0, 1])
    # the point at the world's origin moving with the link is the pin: at rest
    assert np.allclose(link.jacobian([theta], "link", "world")[:3, 0], 0.0, atol=1e-15)


def test_frames_that_move_with_time_are_refused_in_one_line():
    shaken = lagrangian.load("support_pendulum").dynamics()
    with pytest.raises(InputError, match="moves with t") as e:
        shaken.placement([0.1], "bob")
    assert e.value.field == "frame"
    with pytest.raises(InputError, match="kinematic tree or a model file's particles"):
        lagrangian.load("pendulum").dynamics().placement([0.1], "bob")


def test_centroidal_momentum_by_hand(pendulum):
    """Two bobs: l = sum m r_dot, k_G = sum m (r - c) x r_dot; a lone link: k_G = I theta_dot."""
    q, v = np.array([0.4, -1.1]), np.array([0.7, -0.3])
    s1, c1, s2, c2 = np.sin(q[0]), np.cos(q[0]), np.sin(q[1]), np.cos(q[1])
    r1, r2 = L1 * np.array([s1, -c1, 0]), L1 * np.array([s1, -c1, 0]) + L2 * np.array([s2, -c2, 0])
    u1 = L1 * np.array([c1, s1, 0]) * v[0]
    u2 = u1 + L2 * np.array([c2, s2, 0]) * v[1]
    c = (M1 * r1 + M2 * r2) / (M1 + M2)
    h = pendulum.centroidal_momentum_matrix(q) @ v
    assert np.allclose(h[:3], M1 * u1 + M2 * u2, atol=1e-13)
    assert np.allclose(h[3:], M1 * np.cross(r1 - c, u1) + M2 * np.cross(r2 - c, u2), atol=1e-13)
    link = lagrangian.load("virtual_work_link").dynamics()  # m = 1 kg, L = 0.5 m
    assert np.allclose(link.centroidal_momentum_matrix([0.5])[3:, 0], [0, 0, 0.5**2 / 12])
