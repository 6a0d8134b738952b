"""Bodies in space animated: their frames in 3D (geometry asserted against the rotation's closed
form), projected from a viewpoint, written as GIF/HTML; the --view flag and its bad input."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

import lagrangian
from lagrangian.cli import main
from lagrangian.errors import ModelError
from lagrangian.output.animation import check_view
from lagrangian.output.geometry import mechanism, view_projection


@pytest.fixture(scope="module")
def top_run():
    return lagrangian.load("heavy_top").simulate(0.5, samples=201)


def test_heavy_top_frames_follow_the_euler_angles_at_every_sample(top_run):
    model = top_run.model
    values = {p.name: p.value for p in model.parameters}
    m, l, a, c = values["m"], values["l"], values["A"], values["C"]
    space = mechanism(model).space_frame(top_run.q, top_run.q_dot, top_run.t)
    phi, theta = top_run["phi"], top_run["theta"]
    origin, centre, rotation = space.origins[:, 0], space.centres[:, 0], space.rotations[:, 0]
    # the pivot stays put and the centre of mass stays at distance l from it, on the symmetry
    # axis R e3 = (sin th sin phi, -sin th cos phi, cos th) for z-x-z Euler angles
    assert np.allclose(origin, 0.0, atol=1e-15)
    assert np.allclose(np.linalg.norm(centre - origin, axis=-1), l, rtol=1e-12)
    axis = np.column_stack([np.sin(theta) * np.sin(phi), -np.sin(theta) * np.cos(phi),
                            np.cos(theta)])
    assert np.allclose(rotation[..., 2], axis, atol=1e-12)
    assert np.allclose(centre, l * axis, atol=1e-12)
    # the drawn body axes stay orthonormal and right-handed
    assert np.allclose(np.swapaxes(rotation, -1, -2) @ rotation, np.eye(3), atol=1e-12)
    assert np.allclose(np.linalg.det(rotation), 1.0, atol=1e-12)
    # the box has the top's mass and inertia: I = m (b^2 + c^2) / 3 about each principal axis
    half = np.sort(space.half_extents[:, 0], axis=-1)
    expected = np.sort([np.sqrt(3 * c / (2 * m))] * 2 + [np.sqrt(3 * (2 * a - c) / (2 * m))])
    assert np.allclose(half, expected, rtol=1e-12)
    # the link drawn is pivot -> centre of mass
    assert np.allclose(space.links[:, 0, 0], origin) and np.allclose(space.links[:, 0, 1], centre)


def test_a_joint_tree_draws_the_link_from_the_parent_joint_to_the_child_joint(tmp_path):
    source = """
name = "Two links"
[coordinates]
a = { unit = "rad", initial = 0.4 }
b = { unit = "rad", initial = -0.7 }
[parameters]
L = { value = 0.5, unit = "m" }
[[bodies]]
name = "upper"
mass = 1
inertia = [0.02, 0.02, 0.001]
joint = { type = "revolute", axis = "x", angle = "a" }
center = [0, 0, "-L/2"]
[[bodies]]
name = "lower"
parent = "upper"
mass = 1
inertia = [0.02, 0.02, 0.001]
joint = { type = "revolute", axis = "y", angle = "b", at = [0, 0, "-L"] }
center = [0, 0, "-L/2"]
"""
    (tmp_path / "links.toml").write_text(source)
    model = lagrangian.load(tmp_path / "links.toml").model
    space = mechanism(model).space_frame(np.array([[0.4, -0.7]]), np.zeros((1, 2)),
                                         np.zeros(1))
    joint = np.array([0.0, 0.5 * np.sin(0.4), -0.5 * np.cos(0.4)])  # upper's tip
    assert np.allclose(space.origins[0, 1], joint, atol=1e-12)
    parent_to_child = space.links[0, 2]  # after the two origin -> centre links
    assert np.allclose(parent_to_child, [[0, 0, 0], joint], atol=1e-12)


def test_view_projection_looks_from_the_given_direction():
    side = view_projection(0.0, 0.0)  # from +x: y to the right, z up
    assert np.allclose(side, [[0, 1, 0], [0, 0, 1]], atol=1e-15)
    top = view_projection(-90.0, 90.0)  # from above
    assert np.allclose(top, [[1, 0, 0], [0, 1, 0]], atol=1e-15)
    p = view_projection(37.0, 21.0)
    direction = [np.cos(np.radians(21)) * np.cos(np.radians(37)),
                 np.cos(np.radians(21)) * np.sin(np.radians(37)), np.sin(np.radians(21))]
    assert np.allclose(p @ p.T, np.eye(2)) and np.allclose(p @ direction, 0.0)


def test_heavy_top_gif_shows_the_top_turning(top_run, tmp_path):
    top_run.animate(tmp_path / "top.gif", fps=10, view=(30, 20))
    with Image.open(tmp_path / "top.gif") as gif:
        assert gif.n_frames == 6  # 0.5 s at 10 frames a second, both ends included
        first = np.asarray(gif.convert("RGB")).copy()
        gif.seek(gif.n_frames - 1)
        last = np.asarray(gif.convert("RGB")).copy()
    assert np.mean(np.any(first != last, axis=-1)) > 0.002


def test_torque_free_body_animates_to_html(tmp_path):
    run = lagrangian.load("torque_free_body").simulate(0.4, samples=41)
    run.animate(tmp_path / "body.html", fps=10)
    html = (tmp_path / "body.html").read_text()
    assert "<script" in html and html.count("frames[") >= 5


@pytest.mark.parametrize("view", ["45", "a,b", "10,95", "nan,10", (1, 2, 3)])
def test_bad_viewpoints_are_refused(view):
    with pytest.raises(ModelError) as info:
        check_view(view)
    assert info.value.field == "view"


def cli(capsys, *args):
    with pytest.raises(SystemExit) as info:
        main(["simulate", *map(str, args)])
    out, err = capsys.readouterr()
    return info.value.code, out, err


def test_cli_view_flag(capsys, tmp_path):
    gif = tmp_path / "top.gif"
    code, out, err = cli(capsys, "heavy_top", "--t-end", "0.1", "--samples", "11",
                         "--animate", gif, "--view", "60,10")
    assert code == 0 and gif.exists()
    code, out, err = cli(capsys, "heavy_top", "--t-end", "0.1", "--animate", gif,
                         "--view", "60")
    assert code == 2 and err.startswith("error: --view: expected AZIMUTH,ELEVATION")
    code, out, err = cli(capsys, "heavy_top", "--t-end", "0.1", "--view", "60,10")
    assert code == 2 and err == "error: --view: a viewpoint is only used with --animate\n"


def test_a_rolling_wheel_is_drawn_as_its_rim_touching_the_ground():
    """The coin (radius r, axle = body y): its rim is a circle of radius r about the centre in
    the plane normal to R e_y, and its lowest point touches the ground z = 0."""
    run = lagrangian.load("rolling_coin").simulate(0.5, samples=26)
    geometry = mechanism(run.model, run.parameters)
    r = {p.name: p.value for p in run.model.parameters}["r"]
    (body, radius, axle, normal), = geometry.wheels
    assert radius == r and axle == (0.0, 1.0, 0.0) and normal == (0.0, 0.0, 1.0)
    space = geometry.space_frame(run.q, run.q_dot, run.t)
    rims, contacts = geometry.wheel_frame(space)
    centre = space.origins[:, body]
    assert np.allclose(np.linalg.norm(rims[:, 0] - centre[:, None], axis=-1), r, rtol=1e-12)
    world_axle = space.rotations[:, body] @ np.array(axle)
    assert np.allclose(np.einsum("kpi,ki->kp", rims[:, 0] - centre[:, None], world_axle), 0,
                       atol=1e-12)
    assert np.allclose(contacts[:, 0, 2], 0.0, atol=1e-9)  # on the ground (the constraint)
    assert np.allclose(rims[:, 0, :, 2].min(axis=1), contacts[:, 0, 2], atol=1e-3 * r)
    frames = run.animate(fps=10)
    frames.draw(len(frames.times) - 1)
    labels = {line.get_label() for line in frames._fig.axes[0].get_lines()}
    assert {"ground", "wheel", "track"} <= labels
