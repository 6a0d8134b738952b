"""Chains of point masses through their segments (derivation/chains.py): the same Lagrange
equations as an independent derivation, and entry for entry what the particle-by-particle path
writes; particles the premise does not hold for go that way."""

from __future__ import annotations

import random

import pytest
import sympy as sp

import lagrangian
from lagrangian.derivation import inertia
from lagrangian.derivation.chains import particle_chains
from lagrangian.derivation.kinematics import Differentiator
from lagrangian.derivation.lagrange import derive


def chain(n: int, *, relative: bool = False, branch: bool = False, moving: bool = False):
    """An n-link planar pendulum (absolute angles, or relative ones), with a second arm hung
    from the first bob (branch) or a support that moves with t (moving)."""
    b = lagrangian.SystemBuilder(f"{n}-link chain")
    g = b.parameter("g", 9.81)
    t = sp.Symbol("t")
    x, y = (sp.sin(t), sp.S.Zero) if moving else (sp.S.Zero, sp.S.Zero)
    angle = sp.S.Zero
    first = None
    for i in range(1, n + 1):
        theta = b.coordinate(f"theta{i}")
        m, length = b.parameter(f"m{i}", 1.0 + 0.1 * i), b.parameter(f"l{i}", 1.0 + 0.2 * i)
        angle = angle + theta if relative else theta
        x, y = x + length * sp.sin(angle), y - length * sp.cos(angle)
        b.add_particle(f"bob{i}", m, (x, y))
        first = first or (x, y)
    if branch:
        phi = b.coordinate("phi")
        arm = b.parameter("a", 0.7)
        b.add_particle("side", b.parameter("ms", 0.5),
                       (first[0] + arm * sp.cos(phi), first[1] + arm * sp.sin(phi)))
    b.set_gravity(g, (0, -1))
    return b.build().model


def independent(model, state):
    """M and f from L = sum 1/2 m v.v - V by sympy's diff on the whole L (no structure)."""
    q, q_dot, t = model.q, model.q_dot, model.time
    T = V = sp.S.Zero
    for p in model.particles:
        v = [sum((sp.diff(r, qi) * vi for qi, vi in zip(q, q_dot, strict=True)), sp.diff(r, t))
             for r in p.position]
        T += p.mass * sum(c**2 for c in v) / 2
        V -= p.mass * model.gravity.magnitude * sum(
            d * r for d, r in zip(model.gravity.direction, p.position, strict=True))
    L = T - V
    M = sp.Matrix(len(q), len(q), lambda i, j: sp.diff(L, q_dot[i], q_dot[j]))
    f = sp.Matrix([sp.diff(L, qi) - sum(sp.diff(L, vi, qj) * wj for qj, wj in zip(q, q_dot,
                                                                                strict=True))
                   - sp.diff(L, vi, t) for qi, vi in zip(q, q_dot, strict=True)])
    return M.xreplace(state), f.xreplace(state)


def values(model, seed=1):
    rng = random.Random(seed)
    state = {p.symbol: p.value for p in model.parameters}
    state.update({s: rng.uniform(-2, 2) for s in (*model.q, *model.q_dot)})
    state[model.time] = 0.3
    return state


def segments(model):
    return particle_chains(model.particles, model.q, model.q_dot, model.time, Differentiator())


@pytest.mark.parametrize("kind", [{}, {"branch": True}, {"relative": True},
                                  {"moving": True}])
def test_a_chain_gives_the_equations_of_an_independent_derivation(kind):
    model = chain(5, **kind)
    eom = derive(model)
    state = values(model)
    M, f = independent(model, state)
    assert [float(x) for x in eom.mass_matrix.xreplace(state)] == pytest.approx(
        [float(x) for x in M], rel=1e-12)
    assert [float(x) for x in eom.forcing.xreplace(state)] == pytest.approx(
        [float(x) for x in f], rel=1e-10, abs=1e-10)


@pytest.mark.parametrize("kind", [{}, {"branch": True}, {"relative": True}])
def test_the_segments_write_what_the_particles_write(kind, monkeypatch):
    model = chain(8, **kind)
    through_chain = derive(model, check=False)
    monkeypatch.setattr(inertia, "particle_chains", lambda *args: [])
    one_by_one = derive(model, check=False)
    assert through_chain.mass_matrix == one_by_one.mass_matrix
    assert through_chain.forcing == one_by_one.forcing


def test_which_particles_take_the_chain():
    absolute = segments(chain(4, branch=True))
    parents = {s.particle.name: s.parent and s.parent.particle.name for s in absolute}
    assert parents == {"bob1": None, "bob2": "bob1", "bob3": "bob2", "bob4": "bob3",
                       "side": "bob1"}
    beyond = {s.particle.name: len(s.masses) for s in absolute}
    assert beyond == {"bob1": 5, "bob2": 3, "bob3": 2, "bob4": 1, "side": 1}
    # relative angles: theta1 is in every segment, so only the first bob is a segment and the
    # others go particle by particle (nothing to gain: no chain is returned)
    assert segments(chain(4, relative=True)) == []
    assert segments(chain(4, moving=True)) == []  # the support moves with t
