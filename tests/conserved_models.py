"""Model files for the conserved-quantity, Routh and Hamilton tests (closed forms known)."""

_SPHERICAL = '''
name = "Spherical pendulum"
[coordinates]
theta = { unit = "rad", initial = 0.6, rate = @THETA_DOT@ }
phi = { unit = "rad", initial = 0.0, rate = @PHI_DOT@ }
[parameters]
m = { value = 1.3, unit = "kg" }
l = { value = 0.8, unit = "m" }
g = { value = 9.81, unit = "m/s^2" }
[gravity]
g = "g"
direction = [0, 0, -1]
[[particles]]
name = "bob"
mass = "m"
position = ["l*sin(theta)*cos(phi)", "l*sin(theta)*sin(phi)", "-l*cos(theta)"]
'''


def spherical_pendulum(theta_dot: float = 0.0, phi_dot: float = 1.0) -> str:
    """A bob of 1.3 kg on a 0.8 m rod, from theta = 0.6 rad with these rates (rad/s)."""
    return _SPHERICAL.replace("@THETA_DOT@", repr(float(theta_dot))).replace(
        "@PHI_DOT@", repr(float(phi_dot)))


SPHERICAL_PENDULUM = spherical_pendulum()

KEPLER = '''
name = "Kepler problem"
[coordinates]
r = { unit = "m", initial = 1.0, rate = 0.1 }
phi = { unit = "rad", initial = 0.0, rate = 1.0 }
[parameters]
m = { value = 2.0, unit = "kg" }
k = { value = 3.0, unit = "N*m^2" }
[energy]
T = "1/2*m*(r_dot^2 + r^2*phi_dot^2)"
V = "-k/r"
'''

FREE_PAIR = '''
name = "Two masses joined by a spring"
[coordinates]
x1 = { unit = "m", initial = 0.0 }
x2 = { unit = "m", initial = 1.2 }
[parameters]
m1 = { value = 1.0, unit = "kg" }
m2 = { value = 3.0, unit = "kg" }
k = { value = 2.0, unit = "N/m" }
l0 = { value = 1.0, unit = "m" }
[energy]
T = "1/2*m1*x1_dot^2 + 1/2*m2*x2_dot^2"
V = "1/2*k*(x2 - x1 - l0)^2"
'''

CENTRAL_WELL = '''
name = "Particle in a central well"
[coordinates]
x = { unit = "m", initial = 1.0 }
y = { unit = "m", initial = 0.0, rate = 0.5 }
[parameters]
m = { value = 1.5, unit = "kg" }
k = { value = 2.0, unit = "N/m" }
[energy]
T = "1/2*m*(x_dot^2 + y_dot^2)"
V = "1/2*k*(x^2 + y^2)"
'''

# The pair with a damper on its stretch (no work along a translation) and a push on x1 (work).
DAMPED_PAIR = FREE_PAIR.replace('name = "Two masses joined by a spring"',
                                'name = "Damped pair"') + '''
[[dampers]]
name = "dashpot"
coefficient = "k"
rate = "x2_dot - x1_dot"
'''
PUSHED_PAIR = FREE_PAIR.replace('name = "Two masses joined by a spring"',
                                'name = "Pushed pair"') + '''
[generalized_forces]
x1 = "k"
'''
