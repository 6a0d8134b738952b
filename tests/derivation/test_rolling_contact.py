"""Rolling contact from the model file ([[contacts]]) and the builder (add_rolling_contact): the
generated no-slip constraints give the disc's motion of sympy's LagrangesMethod with hand-written
contact constraints, its critical speed sqrt(g r/3), and a holonomic normal constraint exactly
where the contact height is not identically zero; bad input is named."""

import math
import random

import numpy as np
import pytest
import sympy as sp
from sympy.physics.mechanics import dynamicsymbols

import lagrangian
from lagrangian.errors import ModelError
from lagrangian.model.builder import ModelBuilder
from lagrangian.model.examples import example_path
from lagrangian.model.reader import parse_model
from rolling_disc_models import VALUES, sympy_disc

COIN = example_path("rolling_coin").read_text()


def test_the_coin_file_generates_the_two_no_slip_constraints_and_no_normal_one():
    model = parse_model(COIN)
    (contact,) = model.contacts
    assert [c.name for c in model.constraints] == ["rolling_friction_x", "rolling_friction_y"]
    assert contact.constraints == ("rolling_friction_x", "rolling_friction_y")
    assert not contact.holonomic
    x, y = sp.symbols("x y")
    assert tuple(sp.simplify(c) for c in contact.contact_point) == (x, y, 0)
    # the no-slip rows are v_contact = v_G + omega x (r_C - r_G) = 0: x_dot = r spin_dot cos(yaw)
    r, yaw, spin_dot, x_dot, y_dot = sp.symbols("r yaw spin_dot x_dot y_dot")
    rows = [c.expression for c in model.constraints]
    assert sp.simplify(rows[0] - (x_dot - r * spin_dot * sp.cos(yaw))) == 0
    assert sp.simplify(rows[1] - (y_dot - r * spin_dot * sp.sin(yaw))) == 0


@pytest.mark.slow
def test_coin_accelerations_and_friction_equal_lagranges_method_with_hand_written_contact():
    system = lagrangian.System(parse_model(COIN))
    eom = system.equations_of_motion()
    numeric = system.numeric(backend="numpy")
    q, method = sympy_disc()
    t = dynamicsymbols._t
    constants = {sp.Symbol(k): v for k, v in VALUES.items()}
    model = system.model
    disc = model.rigid_bodies[0]
    rng = random.Random(5)
    for _ in range(3):
        qv = np.array([rng.uniform(-3, 3), rng.uniform(-0.8, 0.8), rng.uniform(-3, 3),
                       rng.uniform(-1, 1), rng.uniform(-1, 1)])
        free = np.array([rng.uniform(-2, 2) for _ in range(3)])
        A = np.array(eom.constraint_jacobian.xreplace(dict(zip(model.q, qv, strict=True)))
                     .xreplace(constants), dtype=float)
        v = np.concatenate([free, -A[:, :3] @ free])  # x_dot, y_dot so that the coin rolls
        ours, multipliers = numeric.accelerations_and_multipliers(qv, v)
        point = {s.diff(t): value for s, value in zip(q, v, strict=True)}
        point |= dict(zip(q, qv, strict=True)) | constants
        full = np.linalg.solve(np.array(method.mass_matrix_full.xreplace(point), dtype=float),
                               np.array(method.forcing_full.xreplace(point), dtype=float).ravel())
        assert np.ravel(ours) == pytest.approx(full[5:10], rel=1e-9, abs=1e-9)
        # sympy's multipliers of the same rows: LagrangesMethod writes M q_ddot = f + A^T lambda,
        # we write M q_ddot + A^T lambda = f
        assert np.ravel(multipliers) == pytest.approx(-full[10:12], rel=1e-9, abs=1e-9)
        # Newton: m a_G = friction horizontally, and the friction is -lambda
        state = dict(zip(model.q, qv, strict=True)) | dict(zip(model.q_dot, v, strict=True))
        state |= constants
        accelerations = dict(zip(model.q_ddot, np.ravel(ours), strict=True))
        for axis in range(2):
            r = disc.position[axis]
            a = sum(r.diff(s) * qdd for s, qdd in zip(model.q, model.q_ddot, strict=True))
            a += sum(r.diff(s1).diff(s2) * v1 * v2
                     for s1, v1 in zip(model.q, model.q_dot, strict=True)
                     for s2, v2 in zip(model.q, model.q_dot, strict=True))
            force = VALUES["m"] * float(a.xreplace(accelerations).xreplace(state))
            assert force == pytest.approx(-multipliers.ravel()[axis], rel=1e-9, abs=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("factor", [0.98, 1.02])
def test_upright_coin_critical_speed_from_modes_steady_cli(cli, factor):
    import json

    speed = factor * math.sqrt(VALUES["g"] * VALUES["r"] / 3)
    code, out, err = cli("modes", "rolling_coin", "--about", "lean=0,yaw=0,x=0,y=0,spin=0",
                         "--steady", f"spin_dot={speed / VALUES['r']!r},x_dot={speed!r}",
                         "--json")
    assert code == 0, err
    assert json.loads(out)["stable"] == (factor > 1)


def _free_disc(**contact):
    """A disc whose centre is free (x, y, z): its contact height z - r cos(lean) is not
    identically zero, so the contact adds the normal constraint."""
    b = ModelBuilder("free disc")
    for name in ("yaw", "lean", "spin"):
        b.coordinate(name, "rad")
    for name in ("x", "y", "z"):
        b.coordinate(name)
    for k, v in VALUES.items():
        b.parameter(k, v)
    b.set_gravity("g", (0, 0, -1))
    b.add_rigid_body("disc", "m", ["m*r^2/4", "m*r^2/2", "m*r^2/4"], position=["x", "y", "z"],
                     rotation=[["z", "yaw"], ["x", "lean"], ["y", "spin"]])
    b.add_rolling_contact("wheel", contact.get("body", "disc"), contact.get("radius", "r"),
                          contact.get("axle", "y"), normal=contact.get("normal"))
    return b.build_model()


def test_a_contact_height_that_is_not_identically_zero_becomes_the_normal_constraint():
    model = _free_disc()
    names = [c.name for c in model.constraints]
    assert names == ["wheel_friction_x", "wheel_friction_y", "wheel_normal"]
    normal = model.constraints[2]
    z, r, lean = sp.symbols("z r lean")
    assert normal.kind == "holonomic"
    assert sp.simplify(normal.expression - (z - r * sp.cos(lean))) == 0
    # standing upright at rest, the normal force m g is -lambda_normal; no friction
    system = lagrangian.System(model)
    numeric = system.numeric(backend="numpy")
    q = np.array([0.3, 0.0, 0.0, 0.0, 0.0, VALUES["r"]])
    accelerations, multipliers = numeric.accelerations_and_multipliers(q, np.zeros(6))
    assert np.ravel(accelerations) == pytest.approx(np.zeros(6), abs=1e-12)
    assert np.ravel(multipliers) == pytest.approx([0, 0, -VALUES["m"] * VALUES["g"]], abs=1e-9)


def test_the_ground_normal_may_be_given_and_names_the_tangents():
    # gravity down -z, ground normal given as +z explicitly: same constraints as the default
    model = _free_disc(normal=[0, 0, 2])
    assert [c.name for c in model.constraints] == ["wheel_friction_x", "wheel_friction_y",
                                                   "wheel_normal"]
    assert model.contacts[0].normal == (0, 0, 1)


@pytest.mark.parametrize(("contact", "field", "message"), [
    ({"body": "wheel"}, "contact 'wheel'.body", "not a 3D body"),
    ({"radius": "-r"}, "contact 'wheel'.radius", "must be positive"),
    ({"radius": 0}, "contact 'wheel'.radius", "must be positive"),
    ({"radius": "x"}, "contact 'wheel'.radius", "parameters only"),
    ({"axle": [0, 0, 0]}, "contact 'wheel'.axle", "zero length"),
    ({"axle": "w"}, "contact 'wheel'.axle", "unknown axis"),
    ({"normal": [0, 0, 0]}, "contact 'wheel'.normal", "zero vector"),
])
def test_bad_contacts_are_named(contact, field, message):
    with pytest.raises(ModelError, match=message) as info:
        _free_disc(**contact)
    assert info.value.field == field


def test_bad_contacts_in_a_file_exit_2_naming_the_field(cli, tmp_path):
    cases = {
        'body = "disk"': "contacts[0].body: 'disk' is not a 3D body",
        'radius = "-r"': "contacts[0].radius: the radius must be positive",
        "axle = [0, 0, 0]": "contacts[0].axle: the axis has zero length",
    }
    for replacement, expected in cases.items():
        key = replacement.split(" =")[0]
        text = "\n".join(replacement if line.startswith(f"{key} =") and "contacts" not in line
                         and i > COIN.index("[[contacts]]") else line
                         for i, line in _positions(COIN))
        path = tmp_path / "coin.toml"
        path.write_text(text)
        code, out, err = cli("derive", str(path))
        assert code == 2
        assert expected in err, err
        assert "Traceback" not in err
    path.write_text(COIN.replace('axle = "y"', 'axle = "y"\nfriction = 0.5'))
    code, _, err = cli("derive", str(path))
    assert code == 2 and "contacts[0].friction" in err


def _positions(text):
    position = 0
    for line in text.split("\n"):
        yield position, line
        position += len(line) + 1


def test_newton_euler_crosscheck_agrees_on_the_coin_from_the_contacts_key(cli):
    code, out, err = cli("crosscheck", "rolling_coin")
    assert code == 0, err
    assert out.rstrip().endswith("agree")
