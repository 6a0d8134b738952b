"""`lagrangian dynamics` on a constrained model (the slider-crank: two loop constraints): its
forward dynamics is the multipliers' system, so the text must not title it M^-1 (tau - b), nor
its d q_ddot/d tau M^-1 (it is not: M^-1 is block-diagonal here, the constrained one is not);
the multipliers come with it, and they and q_ddot satisfy M q_ddot + Phi_q^T lambda = tau - b and
Phi_q q_ddot = gamma (0 at rest)."""

from __future__ import annotations

import json

import numpy as np

import lagrangian


def test_constrained_forward_dynamics_is_titled_and_solved_with_its_multipliers(cli):
    tau = [0.3, -0.1, 2.0]
    code, out, err = cli("dynamics", "slider_crank", "--tau", ",".join(map(str, tau)),
                         "--derivatives", "--json")
    assert code == 0, err
    document = json.loads(out)
    assert document["constraints"] == ["loop_y", "loop_x"]
    q, a = np.array(document["q"]), np.array(document["forward_dynamics"])
    lam = np.array(document["multipliers"])
    M, bias = np.array(document["mass_matrix"]), np.array(document["bias_forces"])
    dynamics = lagrangian.load("slider_crank").dynamics()
    jacobian = dynamics.constraint_rows(q, np.zeros(3))[0]  # Phi_q (holonomic)
    np.testing.assert_allclose(M @ a + jacobian.T @ lam, np.array(tau) - bias, atol=1e-9)
    np.testing.assert_allclose(jacobian @ a, 0.0, atol=1e-9)  # gamma = 0 at rest
    # d q_ddot/d tau is not M^-1: it maps onto the constraints' tangent space
    by_tau = np.array(document["dqdd_dtau"])
    assert not np.allclose(by_tau, np.linalg.inv(M))
    np.testing.assert_allclose(jacobian @ by_tau, 0.0, atol=1e-9)

    code, text, err = cli("dynamics", "slider_crank", "--tau", ",".join(map(str, tau)),
                          "--derivatives")
    assert code == 0, err
    titles = [line for line in text.splitlines() if not line.startswith(" ")]
    assert not any("M^-1" in line and "not M^-1" not in line for line in titles), titles
    assert any(line.startswith("multipliers lambda") for line in titles)
    assert "  loop_y" in text and "  loop_x" in text


def test_an_unconstrained_model_keeps_its_titles_and_document(cli):
    code, text, err = cli("dynamics", "double_pendulum", "--tau", "0,0", "--derivatives")
    assert code == 0, err
    assert "forward dynamics q_ddot = M^-1 (tau - C q_dot - g):" in text
    assert "d q_ddot/d tau = M^-1:" in text and "multipliers" not in text
    code, out, err = cli("dynamics", "double_pendulum", "--tau", "0,0", "--json")
    assert code == 0, err
    assert "constraints" not in json.loads(out) and "multipliers" not in json.loads(out)
