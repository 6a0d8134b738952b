"""A model file the control tests share: a pendulum whose [control] law (each test's own)
tracks theta_ref = a sin t with gains Kp, Kd (SI units)."""

PENDULUM = """
name = "PD pendulum"
[coordinates]
theta = { unit = "rad", initial = 0.3 }
[parameters]
m = 1.0
L = 0.5
g = 9.81
Kp = 4.0
Kd = 2.0
a = 0.2
[definitions]
theta_ref = "a*sin(t)"
[energy]
T = "1/2*m*L^2*theta_dot^2"
V = "-m*g*L*cos(theta)"
"""
