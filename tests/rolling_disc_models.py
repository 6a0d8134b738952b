"""The rolling disc of sympy.physics.mechanics, with its contact constraints written by hand:
the independent derivation the disc tests compare with (tests/derivation)."""

import sympy as sp
from sympy.physics.mechanics import (
    LagrangesMethod,
    Lagrangian,
    Point,
    ReferenceFrame,
    RigidBody,
    dynamicsymbols,
    inertia,
)

VALUES = {"m": 2.0, "r": 0.3, "g": 9.81}


def sympy_disc():
    """The disc in sympy.physics.mechanics with the contact constraints written by hand."""
    yaw, lean, spin, x, y = q = dynamicsymbols("yaw lean spin x y")
    m, r, g = (sp.Symbol(k) for k in VALUES)
    N = ReferenceFrame("N")
    A = N.orientnew("A", "Axis", [yaw, N.z])
    B = A.orientnew("B", "Axis", [lean, A.x])
    C = B.orientnew("C", "Axis", [spin, B.y])
    O = Point("O")
    O.set_vel(N, 0)
    G = O.locatenew("G", x * N.x + y * N.y + r * B.z)
    G.set_vel(N, G.pos_from(O).dt(N))
    contact = G.vel(N) + C.ang_vel_in(N).cross(-r * B.z)
    disc = RigidBody("disc", G, C, m, (inertia(C, m * r**2 / 4, m * r**2 / 2, m * r**2 / 4), G))
    disc.potential_energy = m * g * G.pos_from(O).dot(N.z)
    method = LagrangesMethod(Lagrangian(N, disc), q, frame=N,
                             nonhol_coneqs=[contact.dot(N.x), contact.dot(N.y)])
    method.form_lagranges_equations()
    return q, method
