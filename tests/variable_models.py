"""Models whose inertia changes with q or t, shared by the tests of the general Lagrange path,
the crosscheck's refusals and the time-by-value analysis."""

# A bead sliding on a spoke of a rotor: the rotor's inertia about its axis is I0 + m r^2.
ROTOR_WITH_BEAD = """
name = "Rotor with a bead on a spoke"
[coordinates]
phi = "rad"
r = "m"
[parameters]
I0 = 0.2
m = 0.5
M = 2.0
[[bodies]]
name = "rotor"
mass = "M"
inertia = "I0 + m*r^2"
position = [0, 0]
angle = "phi"
[[particles]]
name = "bead"
mass = "m"
position = ["r", 0]
"""

# A bead on a hoop spun at Omega about the vertical, in the inertial frame: t enters T only
# through sin^2(Omega t) + cos^2(Omega t).
BEAD_ON_SPINNING_HOOP = """
name = "Bead on a spinning hoop, inertial frame"
[coordinates]
theta = { unit = "rad", initial = 0.5, range = [-3.141592653589793, 3.141592653589793] }
[parameters]
m = 0.1
R = 0.5
g = 9.81
Omega = 6.0
[gravity]
g = "g"
direction = [0, 0, -1]
[[particles]]
name = "bead"
mass = "m"
position = ["R*sin(theta)*cos(Omega*t)", "R*sin(theta)*sin(Omega*t)", "-R*cos(theta)"]
"""
