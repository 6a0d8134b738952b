"""C(q, q_dot), the matrix of the Coriolis and centrifugal terms (issue 23): C q_dot is the bias
minus gravity, M_dot - 2 C is skew-symmetric, the double pendulum's C is the textbook one, it
agrees with Pinocchio's computeCoriolisMatrix on a spatial arm, and a model whose velocity terms
are not M's (a damper) is refused rather than given a wrong C."""

from __future__ import annotations

import numpy as np
import pytest

import lagrangian


def _laws(dynamics, q, v):
    C = dynamics.coriolis_matrix(q, v)
    np.testing.assert_allclose(C @ v, dynamics.bias_forces(q, v) - dynamics.gravity(q),
                               atol=1e-12)
    h = 1e-6  # M_dot along q_dot by central differences: M_dot - 2 C is skew
    M_dot = (dynamics.mass_matrix(q + h * v) - dynamics.mass_matrix(q - h * v)) / (2 * h)
    N = M_dot - 2 * C
    np.testing.assert_allclose(N, -N.T, atol=1e-7)


def test_double_pendulum_is_the_textbook_c():
    """With M12 = m2 l1 l2 cos(theta1 - theta2): C = m2 l1 l2 sin(theta1 - theta2)
    [[0, theta2_dot], [-theta1_dot, 0]]."""
    system = lagrangian.load("double_pendulum")
    values = {p.name: p.value for p in system.model.parameters}
    dynamics = system.dynamics()
    q, v = np.array([0.7, -0.4]), np.array([1.3, -0.6])
    k = values["m2"] * values["l1"] * values["l2"] * np.sin(q[0] - q[1])
    np.testing.assert_allclose(dynamics.coriolis_matrix(q, v),
                               k * np.array([[0.0, v[1]], [-v[0], 0.0]]), atol=1e-12)
    _laws(dynamics, q, v)


def test_batches_keep_their_shape():
    dynamics = lagrangian.load("double_pendulum").dynamics()
    rng = np.random.default_rng(2)
    q, v = rng.uniform(-1, 1, (4, 5, 2)), rng.uniform(-1, 1, (4, 5, 2))
    C = dynamics.coriolis_matrix(q, v)
    assert C.shape == (4, 5, 2, 2)
    np.testing.assert_allclose(C[2, 3], dynamics.coriolis_matrix(q[2, 3], v[2, 3]), atol=1e-14)


def test_a_damped_model_is_refused():
    """The damper's -c x_dot is a velocity term that is not M's: no C is printed for it."""
    with pytest.raises(lagrangian.DerivationError, match="Coriolis and centrifugal"):
        lagrangian.load("damped_oscillator").dynamics().coriolis_matrix([0.1], [0.2])


def test_spatial_arm_agrees_with_pinocchio(tmp_path):
    pin = pytest.importorskip("pinocchio")
    pytest.importorskip("yourdfpy")
    from tests.dynamics.test_dynamics_pinocchio import ARM

    path = tmp_path / "spatial.urdf"
    path.write_text(ARM)
    model = pin.buildModelFromXML(ARM)
    data = model.createData()
    rng = np.random.default_rng(9)
    for backend in ("numpy", "auto"):
        dynamics = lagrangian.load(path).dynamics(backend=backend)
        for _ in range(4):
            q, v = rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3)
            np.testing.assert_allclose(dynamics.coriolis_matrix(q, v),
                                       pin.computeCoriolisMatrix(model, data, q, v),
                                       atol=1e-12)
            _laws(dynamics, q, v)


def test_cli_prints_c_on_request_and_refuses_it_for_a_damper(cli):
    import json

    result = cli("dynamics", "double_pendulum", "--q", "0.7,-0.4", "--v", "1.3,-0.6",
                 "--coriolis", "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    C = np.array(document["coriolis_matrix"])
    assert np.allclose(C @ np.array(document["v"]),
                       np.array(document["bias_forces"]) - np.array(document["gravity"]))
    refused = cli("dynamics", "damped_oscillator", "--coriolis")
    assert refused.code == 2 and len(refused.err.strip().splitlines()) == 1
    assert "coriolis_matrix" not in cli("dynamics", "double_pendulum", "--json").out


@pytest.mark.parametrize("mimic", [False, True], ids=["two legs", "a mimic knee"])
def test_a_floating_base_with_branches_and_a_mimic_joint(tmp_path, mimic):
    """Two legs: the compiled C(q, v) sets each entry once and zeroes those between the legs
    (the reach tables' cset flag; the lanes' workspace is reused from state to state), A_g each
    column. A mimic joint's coordinate is another joint's: there both add both joints' terms
    into their entries. Either way as numpy's, with C v = bias - g, over enough states for the
    vector lanes and the one-by-one rest."""
    pytest.importorskip("yourdfpy")
    from tests.dynamics.test_reach_reports import TWO_LEGS

    text = TWO_LEGS if not mimic else TWO_LEGS.replace(
        '<joint name="r_knee" type="prismatic"><parent link="r_thigh"/><child link="r_shank"/>',
        '<joint name="r_knee" type="prismatic"><parent link="r_thigh"/><child link="r_shank"/>'
        '<mimic joint="l_knee" multiplier="-0.5" offset="0.01"/>')
    path = tmp_path / "mimic.urdf"
    path.write_text(text)
    compiled = lagrangian.load(path, floating_base=True).dynamics(backend="c")
    plain = lagrangian.load(path, floating_base=True).dynamics(backend="numpy")
    assert compiled.n == 6 + (3 if mimic else 4)  # l_hip, l_knee (r_knee's too), r_hip
    rng = np.random.default_rng(4)
    q = rng.uniform(-0.5, 0.5, (19, compiled.nq))
    q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=-1, keepdims=True)
    v = rng.uniform(-1, 1, (19, compiled.n))
    C = compiled.coriolis_matrix(q, v)
    np.testing.assert_allclose(C, plain.coriolis_matrix(q, v), rtol=0, atol=1e-12)
    if not mimic:  # the left knee's rows on the right leg's columns, and back
        assert not C[:, 7, 8:].any() and not C[:, 8:, 7].any()
    # A_g's columns likewise: set once each, or (the mimic knee) added up
    np.testing.assert_allclose(compiled.centroidal_momentum_matrix(q),
                               plain.centroidal_momentum_matrix(q), rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.einsum("kij,kj->ki", C, v),
                               compiled.bias_forces(q, v) - compiled.gravity(q), atol=1e-12)
