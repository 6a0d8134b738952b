"""The n-link planar pendulum (point masses on massless rods, absolute angles), built three ways:
with lagrangian's SystemBuilder, and with sympy.physics.mechanics for LagrangesMethod/KanesMethod."""

from __future__ import annotations

import sympy as sp

import lagrangian


def build_lagrangian(n: int) -> lagrangian.System:
    b = lagrangian.SystemBuilder(f"{n}-link pendulum")
    g = b.parameter("g", 9.81)
    x, y = sp.S.Zero, sp.S.Zero
    for i in range(1, n + 1):
        theta = b.coordinate(f"theta{i}", unit="rad", initial=0.1 * i)
        mass, length = b.parameter(f"m{i}", 1.0), b.parameter(f"l{i}", 1.0)
        x, y = x + length * sp.sin(theta), y - length * sp.cos(theta)
        b.add_particle(f"bob{i}", mass, (x, y))
    b.set_gravity(g, (0, -1))
    return b.build()


def sympy_particles(n: int):
    """(q, u, particles, loads, frame) for sympy.physics.mechanics, same model and symbols."""
    import sympy.physics.mechanics as me

    frame = me.ReferenceFrame("N")
    origin = me.Point("O")
    origin.set_vel(frame, 0)
    g = sp.Symbol("g")
    q = me.dynamicsymbols(f"theta1:{n + 1}")
    u = me.dynamicsymbols(f"theta1:{n + 1}_dot")
    particles, loads, point = [], [], origin
    for i in range(n):
        mass, length = sp.symbols(f"m{i + 1} l{i + 1}")
        nxt = point.locatenew(f"P{i + 1}", length * sp.sin(q[i]) * frame.x
                              - length * sp.cos(q[i]) * frame.y)
        nxt.set_vel(frame, nxt.pos_from(origin).dt(frame))
        particle = me.Particle(f"bob{i + 1}", nxt, mass)
        particle.potential_energy = 0
        particles.append(particle)
        loads.append((nxt, -mass * g * frame.y))
        point = nxt
    return q, u, particles, loads, frame


def sympy_lagranges_method(n: int):
    """Mass matrix and forcing by sympy.physics.mechanics.LagrangesMethod."""
    import sympy.physics.mechanics as me

    q, _, particles, loads, frame = sympy_particles(n)
    L = me.Lagrangian(frame, *particles)
    method = me.LagrangesMethod(L, q, forcelist=loads, frame=frame)
    method.form_lagranges_equations()
    return method.mass_matrix, method.forcing


def sympy_kanes_method(n: int):
    """Mass matrix and forcing by sympy.physics.mechanics.KanesMethod."""
    import sympy.physics.mechanics as me

    q, u, particles, loads, frame = sympy_particles(n)
    # Re-express point velocities through u so Kane's partial velocities are defined.
    qd = [qi.diff(me.dynamicsymbols._t) for qi in q]
    for particle in particles:
        point = particle.point
        point.set_vel(frame, point.vel(frame).subs(dict(zip(qd, u, strict=True))))
    kdes = [ui - qdi for ui, qdi in zip(u, qd, strict=True)]
    method = me.KanesMethod(frame, q_ind=q, u_ind=u, kd_eqs=kdes)
    method.kanes_equations(particles, loads)
    return method.mass_matrix, method.forcing


def ours(n: int):
    eom = build_lagrangian(n).equations_of_motion()
    return eom.mass_matrix, eom.forcing
