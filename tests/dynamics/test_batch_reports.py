"""Batches report, not fail (issue 27): a state that is not finite, or (forward dynamics) whose
mass matrix is not positive definite, gives NaN in its own row; every other row equals the call
for that state alone, bit for bit; one DynamicsWarning per call counts the states. For every
backend: the robot's generated C, its recursions in numpy, and a derived model in C and numpy."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import lagrangian
from lagrangian.compile.functions import numeric
from lagrangian.dynamics.joint_space import Dynamics

# Two links of 1 m in a vertical plane, the first massless, a 1 kg point at the far end:
# M = [[2 + 2c, 1 + c], [1 + c, 1]] (kg m^2), det M = sin^2(elbow): singular at elbow = 0
# (M = [[4, 2], [2, 1]], exact in floating point), positive definite elsewhere.
POINT_ARM = """<?xml version="1.0"?>
<robot name="point_arm">
  <link name="base"/>
  <link name="upper"><inertial><mass value="0"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
  <link name="fore"><inertial><origin xyz="1 0 0"/><mass value="1"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <axis xyz="0 -1 0"/><limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="1 0 0"/><axis xyz="0 -1 0"/>
    <limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
</robot>
"""

# A derived model whose M = diag(m, m x^2) is singular at x = 0 (a polar-like coordinate).
RADIAL = """
name = "radial"
[coordinates]
x = { unit = "m", initial = 1.0 }
y = { unit = "rad", initial = 0.0 }
[parameters]
m = { value = 2.0, unit = "kg" }
g = { value = 9.81, unit = "m/s^2" }
[energy]
T = "1/2*m*(x_dot^2 + x^2*y_dot^2)"
V = "m*g*x"
"""

FUNCTIONS = [  # name, inputs (q, v, a-or-tau), axes of one state's output
    ("mass_matrix", "q", 2), ("bias_forces", "qv", 1), ("gravity", "q", 1),
    ("inverse_dynamics", "qva", 1), ("forward_dynamics", "qva", 1),
    ("kinetic_energy", "qv", 0), ("potential_energy", "q", 0),
]


def _robot(tmp_path):
    pytest.importorskip("yourdfpy")
    path = tmp_path / "point_arm.urdf"
    path.write_text(POINT_ARM)
    return lagrangian.load(path)


def _radial(tmp_path):
    path = tmp_path / "radial.toml"
    path.write_text(RADIAL)
    return lagrangian.load(path)


def backends(tmp_path):
    robot, radial = _robot(tmp_path), _radial(tmp_path)
    eom = radial.equations_of_motion()
    return {"recursive C": robot.dynamics(backend="c"),
            "recursive C compact": robot.dynamics(backend="c", kernel="compact"),
            "recursive numpy": robot.dynamics(backend="numpy"),
            "derived C": Dynamics(numeric(eom, backend="c")),
            "derived numpy": Dynamics(numeric(eom, backend="numpy"))}


def _call(f, name, inputs, rows):
    return getattr(f, name)(*(rows[k] for k in inputs))


@pytest.mark.parametrize("backend", ["recursive C", "recursive C compact", "recursive numpy",
                                     "derived C", "derived numpy"])
def test_a_state_not_finite_is_nan_in_its_row_the_others_exact(tmp_path, backend):
    f = backends(tmp_path)[backend]
    rng = np.random.default_rng(3)
    count = 11
    rows = {k: rng.uniform(0.2, 1.5, (count, 2)) for k in "qva"}
    rows["q"][2, 1] = np.nan
    rows["v"][5, 0] = np.inf
    rows["a"][7, 1] = -np.inf
    for name, inputs, axes in FUNCTIONS:
        bad = {2} | ({5} if "v" in inputs else set()) | ({7} if "a" in inputs else set())
        with pytest.warns(lagrangian.DynamicsWarning) as record:
            out = _call(f, name, inputs, rows)
        assert len(record) == 1, name  # once per call, with the count
        assert record[0].message.count == len(bad) and record[0].message.total == count
        assert f"{len(bad)} of {count} states" in str(record[0].message)
        assert out.shape == (count,) + (2,) * axes
        for k in range(count):
            if k in bad:
                assert np.isnan(out[k]).all(), (name, k)
            else:
                with warnings.catch_warnings():
                    warnings.simplefilter("error")  # a good state alone warns of nothing
                    alone = _call(f, name, inputs, {key: x[k] for key, x in rows.items()})
                np.testing.assert_array_equal(out[k], alone, err_msg=name)


@pytest.mark.parametrize("backend", ["recursive C", "recursive C compact"])
def test_ten_thousand_states_with_one_nan(tmp_path, backend):
    f = backends(tmp_path)[backend]
    rng = np.random.default_rng(9)
    q, v, tau = (rng.uniform(0.2, 1.5, (10_000, 2)) for _ in range(3))
    q[4321, 0] = np.nan
    with pytest.warns(lagrangian.DynamicsWarning, match="1 of 10000 states"):
        a = f.forward_dynamics(q, v, tau)
    assert np.isnan(a[4321]).all() and np.isfinite(np.delete(a, 4321, axis=0)).all()
    # the physics of the good rows: M a + b = tau
    M, b = f.mass_matrix(q[:100]), f.bias_forces(q[:100], v[:100])
    np.testing.assert_allclose(np.einsum("kij,kj->ki", M, a[:100]) + b, tau[:100], rtol=1e-10)


@pytest.mark.parametrize("backend", ["recursive C", "recursive C compact", "recursive numpy",
                                     "derived C", "derived numpy"])
def test_a_state_whose_mass_matrix_is_singular_is_nan_in_forward_dynamics(tmp_path, backend):
    f = backends(tmp_path)[backend]
    q = np.array([[0.3, 0.7], [0.0, 0.0], [1.1, -0.4]])  # row 1: elbow 0 or x = 0, M singular
    if backend.startswith("recursive"):
        np.testing.assert_array_equal(f.mass_matrix(q[1]), [[4.0, 2.0], [2.0, 1.0]])
    else:
        np.testing.assert_array_equal(f.mass_matrix(q[1]), [[2.0, 0.0], [0.0, 0.0]])
    v = np.full((3, 2), 0.5)
    tau = np.ones((3, 2))
    with pytest.warns(lagrangian.DynamicsWarning, match="1 of 3 states") as record:
        a = f.forward_dynamics(q, v, tau)
    assert len(record) == 1
    assert np.isnan(a[1]).all()
    for k in (0, 2):
        np.testing.assert_array_equal(a[k], f.forward_dynamics(q[k], v[k], tau[k]))
        M, b = f.mass_matrix(q[k]), f.bias_forces(q[k], v[k])
        np.testing.assert_allclose(M @ a[k] + b, tau[k], rtol=1e-12)


def test_good_batches_warn_of_nothing(tmp_path):
    f = backends(tmp_path)["recursive C"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert np.isfinite(f.forward_dynamics(np.full((40, 2), 0.5), np.zeros(2), np.zeros(2))).all()


@pytest.mark.parametrize("json_", [False, True])
def test_the_cli_reports_a_singular_state_in_one_warning_line(cli, tmp_path, json_):
    pytest.importorskip("yourdfpy")
    path = tmp_path / "point_arm.urdf"
    path.write_text(POINT_ARM)
    result = cli("dynamics", str(path), "--q", "0.2,0", "--tau", "1,1",
                 *(("--json",) if json_ else ()))
    assert result.code == 0, result.err
    lines = result.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("warning: ") and "forward dynamics" in lines[0]
    if json_:
        import json

        document = json.loads(result.out)
        assert document["forward_dynamics"] == [None, None]
        assert document["mass_matrix"] == [[4.0, 2.0], [2.0, 1.0]]  # the rest as always
        assert any("forward dynamics" in w for w in document["warnings"])
    else:
        assert "nan" in result.out


def test_a_floating_robots_batch_rows_are_its_single_calls_bit_for_bit():
    """Solo12 (18 velocities): its batches run on vector lanes, its single calls on the scalar
    functions; every row of M, bias, g, ID, FD and the energies equals that state's call alone,
    bit for bit. The module is compiled without contracting a * b + c into fused multiply-adds,
    which the compiler places differently in the two (with them, g differed in the last bit in
    162 of 400 states)."""
    pytest.importorskip("yourdfpy")
    from robot_data import robots

    robot = lagrangian.load(robots() / "solo_description/robots/solo12.urdf",
                            floating_base=True).dynamics(backend="c")
    if getattr(robot, "kernel", None) != "unrolled":
        pytest.skip("no compiler: the numpy recursions")
    rng = np.random.default_rng(3)
    count = 67  # eight lanes' worth and more, and a remainder
    q = rng.uniform(-1, 1, (count, robot.nq))
    q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=-1, keepdims=True)
    rows = {"q": q, "v": rng.uniform(-1, 1, (count, robot.nv)),
            "a": rng.uniform(-1, 1, (count, robot.nv))}
    for name, inputs, _ in FUNCTIONS:
        out = _call(robot, name, inputs, rows)
        for k in range(count):
            alone = _call(robot, name, inputs, {key: x[k] for key, x in rows.items()})
            np.testing.assert_array_equal(out[k], alone, err_msg=f"{name}, state {k}")
