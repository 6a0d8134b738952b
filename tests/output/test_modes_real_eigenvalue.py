"""A real eigenvalue has no damping ratio: JSON says null where the text says '–' (issue 40)."""

from __future__ import annotations

import math

import lagrangian
from lagrangian.output.modes import modes_document


def test_the_inverted_pendulum_grows_at_sqrt_g_over_L_with_no_damping_ratio():
    pendulum = lagrangian.load("pendulum")
    values = {p.name: p.value for p in pendulum.model.parameters}
    modes = pendulum.modes(about={"theta": math.pi})
    (mode,) = modes_document(modes)["modes"]
    # theta = pi + u: u_ddot = (g/L) u, eigenvalues +-sqrt(g/L), real: a saddle, not an oscillation
    assert math.isclose(mode["growth_rate"], math.sqrt(values["g"] / values["L"]), rel_tol=1e-9)
    assert mode["frequency"] == 0 and mode["damping_ratio"] is None
