"""linearize_along(independent=...): A(t), B(t) of a constrained run on its constraint manifold,
against the closed form (the Cartesian pendulum's +-i sqrt(g/L), no spurious zeros), against
central differences of the reduced motion built independently (the dependent coordinates solved
from Phi = 0 by Newton, their rates from Phi_dot = 0, q_ddot from the run's own right-hand side),
and against a perturbed run."""

from __future__ import annotations

import json

import numpy as np
import pytest
from test_linearize_along import perturbed_pendulum_runs, transition_matrix

import lagrangian
from lagrangian.errors import InputError, ModelError


def _reduced_rhs(functions, free, t, q_guess):
    """z = [q_i; q_i_dot] -> z_dot, the dependent coordinates and rates found from the
    constraints (holonomic, without explicit time)."""
    n = functions.n
    tied = [k for k in range(n) if k not in free]

    def rhs(z):
        r = len(free)
        q = q_guess.copy()
        q[free] = z[:r]
        for _ in range(50):  # Newton on Phi(q_i, q_d) = 0 in q_d
            residual = functions.constraint_residual(q, np.zeros(n), t)
            if np.abs(residual).max() < 1e-14:
                break
            J = functions.constraint_jacobian(q, np.zeros(n), t)
            q[tied] -= np.linalg.solve(J[:, tied], residual)
        J = functions.constraint_jacobian(q, np.zeros(n), t)
        v = np.zeros(n)
        v[free] = z[r:]
        v[tied] = -np.linalg.solve(J[:, tied], J[:, free] @ z[r:])
        acceleration = functions.rhs(t, np.concatenate([q, v]))[n:]
        return np.concatenate([z[r:], acceleration[free]])

    return rhs


def test_the_hanging_cartesian_pendulum_has_only_its_pair():
    """On the manifold (x independent) A = [[0, 1], [-g/L, 0]] and B's x column 1/m: the two
    zero eigenvalues of the full A (off the rod) are gone."""
    system = lagrangian.load("cartesian_pendulum")
    run = system.simulate(0.5, initial={"x": 0.0, "y": -0.5}, samples=5)
    along = system.linearize_along(run, inputs=["x", "y"], independent=["x"])
    assert along.A.shape == (5, 2, 2) and along.B.shape == (5, 2, 2)
    assert along.state_names == ("x", "x_dot") and along.dependent == ("y",)
    np.testing.assert_allclose(along.A, np.broadcast_to([[0, 1], [-9.81 / 0.5, 0]], (5, 2, 2)),
                               atol=1e-9)
    np.testing.assert_allclose(along.B[:, 1], np.broadcast_to([1.0, 0.0], (5, 2)), atol=1e-9)
    assert system.linearize_along(run, independent="auto").state_names == ("x", "x_dot")


@pytest.mark.parametrize("name, start", [
    ("cartesian_pendulum", {"x": 0.3, "y": -0.4}),
    ("four_bar", None),
])
def test_a_of_t_is_the_reduced_motions_derivative(name, start):
    system = lagrangian.load(name)
    run = system.simulate(0.6, samples=4, rtol=1e-12, atol=1e-12,
                          **({} if start is None else {"initial": start}))
    along = system.linearize_along(run, independent="auto")
    functions, names = system.numeric(), system.dynamics().coordinates
    free = [names.index(c) for c in along.state_names[:len(along.state_names) // 2]]
    assert len(free) == functions.n - functions.m
    h = 1e-6
    for k, t in enumerate(run.t):
        rhs = _reduced_rhs(functions, free, t, run.q[k].copy())
        z = np.concatenate([run.q[k][free], run.q_dot[k][free]])
        columns = [(rhs(z + e) - rhs(z - e)) / (2 * h) for e in h * np.eye(len(z))]
        by_differences = np.stack(columns, axis=-1)
        scale = max(1.0, np.abs(by_differences).max())
        assert np.abs(along.A[k] - by_differences).max() < 1e-6 * scale


def test_a_perturbed_run_follows_the_reduced_transition_matrix():
    system, run, moved = perturbed_pendulum_runs()
    transition = transition_matrix(system.linearize_along(run, independent=["x"]), run.t)
    delta = np.array([moved.q[0, 0] - run.q[0, 0], 0.0])
    difference = np.array([moved.q[-1, 0] - run.q[-1, 0], moved.q_dot[-1, 0] - run.q_dot[-1, 0]])
    assert np.linalg.norm(difference - transition @ delta) < 1e-4 * np.linalg.norm(difference)


def test_bad_choices_are_one_line():
    system = lagrangian.load("cartesian_pendulum")
    run = system.simulate(0.2, initial={"x": 0.0, "y": -0.5}, samples=3)
    cases = [(["y"], "do not fix x"), (["x", "y"], "leave 1 independent"),
             (["z"], "'z' is not a coordinate")]
    for independent, words in cases:
        with pytest.raises(InputError, match=words) as caught:
            system.linearize_along(run, independent=independent)
        assert caught.value.field == "independent" and "\n" not in str(caught.value)
    coin = lagrangian.load("rolling_coin")
    with pytest.raises(ModelError, match="velocity constraint") as caught:
        coin.linearize_along(coin.simulate(0.1, samples=3), independent="auto")
    assert caught.value.field == "independent"
    pendulum = lagrangian.load("pendulum")
    with pytest.raises(InputError, match="no constraints"):
        pendulum.linearize_along(pendulum.simulate(0.1, samples=3), independent=["theta"])


def test_the_cli_gives_the_reduced_a_and_names_the_dependent(cli):
    result = cli("simulate", "cartesian_pendulum", "--t-end", "0.2", "--samples", "3",
                 "--initial", "x=0", "--initial", "y=-0.5", "--linearize-along",
                 "--independent", "x", "--json")
    assert result.code == 0, result.err
    along = json.loads(result.out)["linearize_along"]
    assert along["states"] == ["x", "x_dot"] and along["dependent"] == ["y"]
    np.testing.assert_allclose(along["A"][0], [[0, 1], [-19.62, 0]], atol=1e-9)
    text = cli("simulate", "cartesian_pendulum", "--t-end", "0.2", "--samples", "3",
               "--linearize-along", "--independent", "auto")
    assert text.code == 0 and "x, y" not in text.out and "y follow" in text.out
    bad = cli("simulate", "cartesian_pendulum", "--t-end", "0.2", "--independent", "x")
    assert bad.code == 2 and "--linearize-along" in bad.err
