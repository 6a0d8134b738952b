"""The held-out optima of tests/control/test_optimize.py and tests/test_docs_bridges.py: the
torque-limited pendulum's and the cart-pole's minimum-effort swing-ups, found by two tools that
share nothing with lagrangian.optimize (not its model, its transcription or its solver set-up).

Reproduce: ``python benchmarks/swing_up_references.py`` (about a minute). Each model is written
here from its textbook equations:

- pendulum: m l^2 theta_ddot + m g l sin(theta) = u (m = l = 1, g = 9.81), |u| <= 5 N m,
  rest at 0 to rest at pi in 3 s;
- cart-pole: (M + m) x_ddot + m l (cos(theta) theta_ddot - sin(theta) theta_dot^2) = F,
  cos(theta) x_ddot + l theta_ddot + g sin(theta) = 0 (M = 2, m = 0.5, l = 0.6), |F| <= 20 N,
  |x| <= 1 m, rest at the origin hanging to rest there upright in 2 s.

Tool 1: CasADi's Opti and IPOPT by direct multiple shooting, u piecewise constant over 200
intervals, each integrated by 4 classical Runge-Kutta substeps. Tool 2: SciPy's SLSQP on a
trapezoidal collocation of our own over 61 nodes (u piecewise linear), its constraint Jacobian
by hand. Both converge to the continuous optimum from either side well within 1 %.
"""

from __future__ import annotations

import math

import numpy as np

G = 9.81
PENDULUM = {"t_final": 3.0, "bound": 5.0, "start": [0, 0], "goal": [math.pi, 0]}
CART_POLE = {"t_final": 2.0, "bound": 20.0, "start": [0, 0, 0, 0], "goal": [0, math.pi, 0, 0],
             "x_bound": 1.0}


def pendulum_rhs(x, u, lib=np):
    return [x[1], u - G * lib.sin(x[0])]


def cart_pole_rhs(x, u, lib=np):
    """Solved for (x_ddot, theta_ddot) by Cramer's rule."""
    M, m, length = 2.0, 0.5, 0.6
    s, c, w = lib.sin(x[1]), lib.cos(x[1]), x[3]
    det = (M + m) * length - m * length * c * c
    b1, b2 = u + m * length * s * w * w, -G * s
    return [x[2], x[3], (b1 * length - m * length * c * b2) / det,
            ((M + m) * b2 - c * b1) / det]


def casadi_shooting(rhs, problem, n_x, intervals=200, substeps=4):
    import casadi

    opti = casadi.Opti()
    X = opti.variable(n_x, intervals + 1)
    U = opti.variable(1, intervals)
    h = problem["t_final"] / intervals / substeps

    def f(x, u):
        return casadi.vertcat(*rhs([x[i] for i in range(n_x)], u, casadi))

    for k in range(intervals):
        x = X[:, k]
        for _ in range(substeps):
            k1 = f(x, U[k])
            k2 = f(x + h / 2 * k1, U[k])
            k3 = f(x + h / 2 * k2, U[k])
            k4 = f(x + h * k3, U[k])
            x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        opti.subject_to(X[:, k + 1] == x)
    opti.subject_to(X[:, 0] == problem["start"])
    opti.subject_to(X[:, -1] == problem["goal"])
    opti.subject_to(opti.bounded(-problem["bound"], U, problem["bound"]))
    if "x_bound" in problem:
        opti.subject_to(opti.bounded(-problem["x_bound"], X[0, :], problem["x_bound"]))
    times = np.linspace(0, problem["t_final"], intervals + 1)
    for i in range(n_x):  # a straight line from start to goal
        opti.set_initial(X[i, :], np.interp(times, [0, times[-1]],
                                            [problem["start"][i], problem["goal"][i]]))
    opti.minimize(casadi.sumsqr(U) * problem["t_final"] / intervals)
    opti.solver("ipopt", {"print_time": False}, {"print_level": 0, "tol": 1e-10})
    return float(opti.solve().value(opti.f))


def scipy_trapezoidal(rhs, problem, n_x, nodes=61):
    from scipy.optimize import minimize

    h = problem["t_final"] / (nodes - 1)
    times = np.linspace(0, problem["t_final"], nodes)

    def split(z):
        return z[:n_x * nodes].reshape(nodes, n_x), z[n_x * nodes:]

    def cost(z):
        u = split(z)[1]
        return h * (np.sum(u * u) - (u[0] ** 2 + u[-1] ** 2) / 2)

    def cost_gradient(z):
        u = split(z)[1]
        weights = np.full(nodes, 2 * h)
        weights[[0, -1]] = h
        return np.r_[np.zeros(n_x * nodes), weights * u]

    def defects(z):
        x, u = split(z)
        f = np.array(rhs(x.T, u)).T
        return np.r_[(x[1:] - x[:-1] - h / 2 * (f[1:] + f[:-1])).ravel(),
                     x[0] - problem["start"], x[-1] - problem["goal"]]

    def defects_jacobian(z, step=1e-7):  # f's Jacobian per node by central differences
        x, u = split(z)
        dfdx = np.empty((nodes, n_x, n_x))
        for i in range(n_x):
            e = np.zeros(n_x)
            e[i] = step
            dfdx[:, :, i] = (np.array(rhs((x + e).T, u)).T
                             - np.array(rhs((x - e).T, u)).T) / (2 * step)
        dfdu = (np.array(rhs(x.T, u + step)).T - np.array(rhs(x.T, u - step)).T) / (2 * step)
        J = np.zeros(((nodes - 1) * n_x + 2 * n_x, (n_x + 1) * nodes))
        eye = np.eye(n_x)
        for k in range(nodes - 1):
            rows = slice(k * n_x, (k + 1) * n_x)
            J[rows, k * n_x:(k + 1) * n_x] = -eye - h / 2 * dfdx[k]
            J[rows, (k + 1) * n_x:(k + 2) * n_x] = eye - h / 2 * dfdx[k + 1]
            J[rows, n_x * nodes + k] = -h / 2 * dfdu[k]
            J[rows, n_x * nodes + k + 1] = -h / 2 * dfdu[k + 1]
        J[-2 * n_x:-n_x, :n_x] = eye
        J[-n_x:, n_x * (nodes - 1):n_x * nodes] = eye
        return J

    bounds = [(None, None)] * (n_x * nodes) + [(-problem["bound"], problem["bound"])] * nodes
    if "x_bound" in problem:
        for k in range(nodes):
            bounds[k * n_x] = (-problem["x_bound"], problem["x_bound"])
    guess = np.column_stack([np.interp(times, [0, times[-1]],
                                       [problem["start"][i], problem["goal"][i]])
                             for i in range(n_x)])
    result = minimize(cost, np.r_[guess.ravel(), np.zeros(nodes)], jac=cost_gradient,
                      method="SLSQP", bounds=bounds,
                      constraints=[{"type": "eq", "fun": defects, "jac": defects_jacobian}],
                      options={"maxiter": 1000, "ftol": 1e-12})
    assert result.success, result.message
    return float(result.fun)


def main() -> None:
    for name, rhs, problem, n_x in (("pendulum", pendulum_rhs, PENDULUM, 2),
                                    ("cart-pole", cart_pole_rhs, CART_POLE, 4)):
        print(f"{name}: CasADi multiple shooting {casadi_shooting(rhs, problem, n_x):.6g}, "
              f"SciPy SLSQP trapezoidal {scipy_trapezoidal(rhs, problem, n_x):.6g}")


if __name__ == "__main__":
    main()
