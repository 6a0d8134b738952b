"""3D bodies in the model file and SystemBuilder: rotation sequences, joints, inertia tensors."""

import random

import pytest
import sympy as sp
from sympy.physics.mechanics import dynamicsymbols

import lagrangian
from lagrangian.errors import ModelError
from lagrangian.model.builder import ModelBuilder

t = sp.Symbol("t")

TOP = """
[coordinates]
phi = "rad"
theta = "rad"
psi = "rad"
[parameters]
m = 0.5
g = 9.81
l = 0.04
A = 4e-4
C = 6e-4
[gravity]
g = "g"
direction = [0, 0, -1]
[[bodies]]
name = "top"
mass = "m"
inertia = ["A", "A", "C"]
origin = [0, 0, 0]
rotation = [["z", "phi"], ["x", "theta"], ["z", "psi"]]
center = [0, 0, "l"]
"""


def _omega_from_rotation(body, model):
    """Body-axes omega from omega~ = R^T R_dot, by sympy's own time derivative of R(q(t))."""
    to_time = {c.symbol: dynamicsymbols(c.name) for c in model.coordinates}
    back = {dynamicsymbols(c.name).diff(t): c.velocity for c in model.coordinates}
    back.update({dynamicsymbols(c.name): c.symbol for c in model.coordinates})
    R = sp.Matrix(body.rotation).xreplace(to_time)
    skew = (R.T * R.diff(t)).xreplace(back).xreplace(back)
    return (skew[2, 1], skew[0, 2], skew[1, 0]), skew


def _random_point(model, seed):
    rng = random.Random(seed)
    point = {c.symbol: rng.uniform(-2, 2) for c in model.coordinates}
    point.update({c.velocity: rng.uniform(-2, 2) for c in model.coordinates})
    point.update({p.symbol: p.value for p in model.parameters})
    return point


def test_angular_velocity_is_RT_Rdot_for_euler_angles_and_a_tree():
    b = ModelBuilder("arm")
    for name in ("a", "b", "c", "d", "s"):
        b.coordinate(name, "rad")
    b.add_rigid_body("base", 1, [1, 2, 2.5], position=[0, 0, 0],
                     rotation=[["z", "a"], ["y", "b"], ["x", "c"]])
    b.add_rigid_body("link", 1, [1, 1, 1], parent="base",
                     joint={"type": "revolute", "axis": [1, 1, 0], "angle": "d",
                            "at": [0.3, 0, 0.1]}, center=[0, 0, -0.5])
    b.add_rigid_body("slider", 1, [1, 1, 1], parent="link",
                     joint={"type": "prismatic", "axis": "-z", "distance": "s"})
    model = b.build_model()
    for body in model.rigid_bodies:
        expected, skew = _omega_from_rotation(body, model)
        for seed in range(3):
            point = _random_point(model, seed)
            assert float((skew + skew.T).xreplace(point).norm()) < 1e-12  # skew-symmetric
            for ours, theirs in zip(body.angular_velocity, expected, strict=True):
                assert float(ours.xreplace(point)) == pytest.approx(
                    float(theirs.xreplace(point)), abs=1e-12)
            R = sp.Matrix(body.rotation).xreplace(point)
            assert float((R.T * R - sp.eye(3)).norm()) < 1e-12


def test_a_joint_tree_places_the_child_where_the_chain_says():
    b = ModelBuilder("arm")
    b.coordinate("q1", "rad")
    b.coordinate("q2", "rad")
    b.coordinate("s", "m")
    b.add_rigid_body("upper", 1, [1, 1, 1], joint={"type": "revolute", "axis": "z",
                                                   "angle": "q1"}, center=[0.5, 0, 0])
    b.add_rigid_body("lower", 1, [1, 1, 1], parent="upper",
                     joint={"type": "revolute", "axis": "y", "angle": "q2", "at": [1, 0, 0]},
                     center=[0, 0, -0.5])
    b.add_rigid_body("tool", 1, [1, 1, 1], parent="lower",
                     joint={"type": "prismatic", "axis": "x", "distance": "s",
                            "at": [0, 0, -1]})
    model = b.build_model()
    q1, q2, s = sp.symbols("q1 q2 s")
    # Hand-expanded: the elbow at (cos q1, sin q1, 0); the lower arm turns about the upper
    # arm's y axis (-sin q1, cos q1, 0).
    elbow = sp.Matrix([sp.cos(q1), sp.sin(q1), 0])
    ex = sp.Matrix([sp.cos(q1) * sp.cos(q2), sp.sin(q1) * sp.cos(q2), -sp.sin(q2)])
    ez = sp.Matrix([sp.cos(q1) * sp.sin(q2), sp.sin(q1) * sp.sin(q2), sp.cos(q2)])
    lower = elbow - ez / 2
    tool = elbow - ez + s * ex
    for body, expected in zip(model.rigid_bodies[1:], (lower, tool), strict=True):
        assert sp.simplify(sp.Matrix(body.position) - expected) == sp.zeros(3, 1)


def test_toml_and_builder_give_the_same_model():
    model = lagrangian.parse_model(TOP)
    b = ModelBuilder()
    for name in ("phi", "theta", "psi"):
        b.coordinate(name, "rad")
    for name, value in (("m", 0.5), ("g", 9.81), ("l", 0.04), ("A", 4e-4), ("C", 6e-4)):
        b.parameter(name, value)
    b.set_gravity("g", [0, 0, -1])
    b.add_rigid_body("top", "m", ["A", "A", "C"], origin=[0, 0, 0], center=[0, 0, "l"],
                     rotation=[["z", "phi"], ["x", "theta"], ["z", "psi"]])
    assert b.build_model().rigid_bodies == model.rigid_bodies
    top = model.rigid_bodies[0]
    phi, theta, l = sp.symbols("phi theta l")
    assert top.position == (l * sp.sin(phi) * sp.sin(theta), -l * sp.sin(theta) * sp.cos(phi),
                            l * sp.cos(theta))


def test_full_inertia_tensor_with_products_of_inertia_is_read():
    text = TOP.replace('inertia = ["A", "A", "C"]',
                       'inertia = [["A", 1e-5, 0], [1e-5, "A", "-2e-5"], [0, "-2e-5", "C"]]')
    top = lagrangian.parse_model(text).rigid_bodies[0]
    assert float(top.inertia[0][1]) == float(top.inertia[1][0]) == 1e-5
    assert float(top.inertia[1][2]) == -2e-5


def _error(text):
    with pytest.raises(ModelError) as info:
        lagrangian.parse_model(text, source="bad.toml")
    return str(info.value)


@pytest.mark.parametrize("old, new, field, words", [
    ('inertia = ["A", "A", "C"]', 'inertia = [["A", 1e-5, 0], [2e-5, "A", 0], [0, 0, "C"]]',
     "bodies[0].inertia", "not symmetric"),
    ('inertia = ["A", "A", "C"]', 'inertia = ["A", "-A", "C"]', "bodies[0].inertia",
     "not positive definite"),
    ('inertia = ["A", "A", "C"]', 'inertia = [1, 1, 3]', "bodies[0].inertia",
     "triangle inequality"),
    ('inertia = ["A", "A", "C"]', 'inertia = [[1, 2, 0], [2, 1, 0], [0, 0, 1]]',
     "bodies[0].inertia", "not positive definite"),
    ('["x", "theta"]', '["w", "theta"]', "bodies[0].rotation[1][0]", "unknown axis 'w'"),
    ('["x", "theta"]', '["z", "theta"]', "bodies[0].rotation[1]", "same axis in a row"),
    ('rotation = [["z", "phi"], ["x", "theta"], ["z", "psi"]]', 'rotation = "zxz"',
     "bodies[0].rotation", "list of [axis, angle] pairs"),
    ('inertia = ["A", "A", "C"]', 'inertia = ["A", "C"]', "bodies[0].inertia", "[Ixx, Iyy, Izz]"),
    ('["x", "theta"]', '[1, "theta"]', "bodies[0].rotation[1][0]", "an axis is x, y or z"),
    ('center = [0, 0, "l"]', 'center = [0, 0, "l"]\nangle = "phi"', "bodies[0].angle",
     "'angle' is for a planar body"),
])
def test_bad_3d_bodies_are_named(old, new, field, words):
    assert old in TOP
    message = _error(TOP.replace(old, new))
    assert f"bad.toml: {field}" in message and words in message, message


TREE = TOP + """
[[bodies]]
name = "arm"
mass = 1
inertia = [1, 1, 1]
parent = "top"
joint = { type = "revolute", axis = [1, 0, 0], angle = "psi" }
"""


@pytest.mark.parametrize("old, new, field, words", [
    ('axis = [1, 0, 0]', 'axis = [0, 0, 0]', "bodies[1].joint.axis", "zero length"),
    ('parent = "top"', 'parent = "tpo"', "bodies[1].parent", "did you mean 'top'"),
    ('type = "revolute"', 'type = "hinge"', "bodies[1].joint.type", "unknown joint type"),
    ('angle = "psi" }', 'distance = "psi" }', "bodies[1].joint.distance",
     "unknown key 'distance'"),
    ('parent = "top"', 'parent = "arm"', "bodies[1].parent", "cycle"),
])
def test_bad_joints_and_trees_are_named(old, new, field, words):
    assert old in TREE
    message = _error(TREE.replace(old, new))
    assert f"bad.toml: {field}" in message and words in message, message


def test_a_cycle_of_two_bodies_is_named():
    text = TOP.replace('origin = [0, 0, 0]\n', 'parent = "arm"\n').replace(
        'rotation = [["z", "phi"], ["x", "theta"], ["z", "psi"]]',
        'joint = { type = "spherical", rotation = [["z", "phi"], ["x", "theta"], ["z", "psi"]] }'
    ) + TREE[len(TOP):]
    message = _error(text)
    assert "cycle (top -> arm -> top)" in message or "cycle (arm -> top -> arm)" in message


def test_children_may_come_before_their_parent_in_the_file():
    text = TOP + TREE[len(TOP):]
    reordered = text[:text.index("[[bodies]]")] + TREE[len(TOP):] + text[text.index("[[bodies]]"):]
    assert lagrangian.parse_model(reordered).rigid_bodies == \
        lagrangian.parse_model(TREE).rigid_bodies


def test_bad_3d_body_exits_2_naming_the_field(cli, tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(TOP.replace('["x", "theta"]', '["x", "theta"], ["x", "psi"]'))
    code, out, err = cli("derive", str(path))
    assert code == 2
    assert "rotation[2]" in err and "same axis" in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1


def test_a_planar_body_still_needs_its_angle():
    text = """
[coordinates]
x = "m"
[[bodies]]
name = "b"
mass = 1
inertia = 1
position = ["x", 0]
"""
    assert "missing key 'angle'" in _error(text)
