"""Model files shared by the statics tests (analysis, CLI, check, docs)."""

# A massless slider-crank: crank r, rod l, a crank torque tau and a piston force P (the unknown),
# closed by two loop constraints. Closed form: P = tau / (r sin(theta) (1 + r cos(theta) /
# sqrt(l^2 - r^2 sin^2(theta)))).
SLIDER_CRANK = """
name = "Massless slider-crank: piston force against a crank torque"
[coordinates]
theta = { unit = "rad", initial = 0.7 }
phi = { unit = "rad", initial = 0.2 }
x = { unit = "m", initial = 0.37 }
[parameters]
r = { value = 0.1, unit = "m" }
l = { value = 0.3, unit = "m" }
tau = { value = 12.0, unit = "N*m" }
P = { unit = "N" }
[[loads]]
name = "crank_torque"
torque = "tau"
angle = "theta"
[[loads]]
name = "piston_force"
point = ["x", 0]
force = ["P", 0]
[[constraints]]
name = "loop_y"
holonomic = "r*sin(theta) - l*sin(phi)"
[[constraints]]
name = "loop_x"
holonomic = "x - r*cos(theta) - l*cos(phi)"
"""
