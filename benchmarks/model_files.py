"""Model files (TOML) for the derive benchmarks, written as a user would write them.

``n_link_pendulum_on_cart(n)`` is sympy.physics.mechanics.models.n_link_pendulum_on_cart: a cart
(particle m0 at (q0, 0)), n links measured from the upward vertical (point masses m_i at the
link ends, P_i = P_{i-1} + l_{i-1} (-sin q_i, cos q_i)), gravity -g y on every mass and a
horizontal force F on the cart. ``n_link_pendulum(n)`` is the plain chain of benchmarks/n_link.py
(absolute angles from the downward vertical). ``mass_spring_damper_chain(n)``: n masses in a line,
each joined to the one before (the first to the wall) by a spring and a damper.
"""

from __future__ import annotations


def n_link_pendulum_on_cart(n: int) -> str:
    lines = [f'name = "{n}-link pendulum on a cart (sympy n_link_pendulum_on_cart)"', "",
             "[coordinates]", 'q0 = { unit = "m", initial = 0.0, rate = 0.0 }']
    lines += [f'q{i} = {{ unit = "rad", initial = {0.1 * i:.1f}, rate = 0.0 }}'
              for i in range(1, n + 1)]
    lines += ["", "[parameters]", 'g = { value = 9.81, unit = "m/s^2" }',
              'F = { value = 0.0, unit = "N" }']
    lines += [f'm{i} = {{ value = 1.0, unit = "kg" }}' for i in range(n + 1)]
    lines += [f'l{i} = {{ value = 1.0, unit = "m" }}' for i in range(n)]
    lines += ["", "[gravity]", 'g = "g"', "direction = [0, -1]", ""]
    x, y = "q0", "0"
    lines += ["[[particles]]", 'name = "cart"', 'mass = "m0"', f'position = ["{x}", {y}]', ""]
    for i in range(1, n + 1):
        x = f"{x} - l{i - 1}*sin(q{i})"
        y = f"l{i - 1}*cos(q{i})" if y == "0" else f"{y} + l{i - 1}*cos(q{i})"
        lines += ["[[particles]]", f'name = "P{i}"', f'mass = "m{i}"',
                  f'position = ["{x}", "{y}"]', ""]
    lines += ["[[loads]]", 'name = "F"', 'point = "cart"', 'force = ["F", 0]', ""]
    return "\n".join(lines)


def n_link_pendulum(n: int) -> str:
    lines = [f'name = "{n}-link pendulum"', "", "[coordinates]"]
    lines += [f'theta{i} = {{ unit = "rad", initial = {0.1 * i:.1f}, rate = 0.0 }}'
              for i in range(1, n + 1)]
    lines += ["", "[parameters]", 'g = { value = 9.81, unit = "m/s^2" }']
    lines += [f'm{i} = {{ value = 1.0, unit = "kg" }}' for i in range(1, n + 1)]
    lines += [f'l{i} = {{ value = 1.0, unit = "m" }}' for i in range(1, n + 1)]
    lines += ["", "[gravity]", 'g = "g"', "direction = [0, -1]", ""]
    x = y = ""
    for i in range(1, n + 1):
        x = f"{x} + l{i}*sin(theta{i})" if x else f"l{i}*sin(theta{i})"
        y = f"{y} - l{i}*cos(theta{i})" if y else f"-l{i}*cos(theta{i})"
        lines += ["[[particles]]", f'name = "bob{i}"', f'mass = "m{i}"',
                  f'position = ["{x}", "{y}"]', ""]
    return "\n".join(lines)


def mass_spring_damper_chain(n: int) -> str:
    lines = [f'name = "{n} masses, springs and dampers in a line"', "", "[coordinates]"]
    lines += [f'x{i} = {{ unit = "m", initial = {0.1 * i:.1f}, rate = 0.0 }}'
              for i in range(1, n + 1)]
    lines += ["", "[parameters]"]
    for i in range(1, n + 1):
        lines += [f'm{i} = {{ value = 1.0, unit = "kg" }}', f'k{i} = {{ value = 10.0, unit = "N/m" }}',
                  f'c{i} = {{ value = 0.5, unit = "N*s/m" }}']
    lines.append("")
    for i in range(1, n + 1):
        previous = f"x{i - 1}" if i > 1 else "0"
        stretch = f"x{i} - {previous}" if i > 1 else f"x{i}"
        rate = f"x{i}_dot - x{i - 1}_dot" if i > 1 else f"x{i}_dot"
        lines += ["[[particles]]", f'name = "mass{i}"', f'mass = "m{i}"',
                  f'position = ["x{i}", 0]', "",
                  "[[springs]]", f'name = "spring{i}"', f'stiffness = "k{i}"',
                  f'length = "{stretch}"', "",
                  "[[dampers]]", f'name = "damper{i}"', f'coefficient = "c{i}"',
                  f'rate = "{rate}"', ""]
    return "\n".join(lines)


def spatial_chain(n: int) -> str:
    """The chain of benchmarks/bench_spatial_chain.py as a model file: n rigid bodies (1 kg,
    inertia (0.1, 0.1, 0.02) kg m^2 about the centre, 0.5 m below the joint) on revolute joints
    about x, y, x, ... each 1 m below the last, gravity -g z."""
    lines = [f'name = "{n}-body spatial chain"', "", "[coordinates]"]
    lines += [f'q{i} = {{ unit = "rad", initial = {0.1 if i < 2 else 0.0}, rate = 0.0 }}'
              for i in range(n)]
    lines += ["", "[parameters]", 'g = { value = 9.81, unit = "m/s^2" }']
    lines += [f'm{i} = {{ value = 1.0, unit = "kg" }}' for i in range(n)]
    lines += ["", "[gravity]", 'g = "g"', "direction = [0, 0, -1]", ""]
    for i in range(n):
        at = ', at = [0, 0, -1]' if i else ""
        lines += ["[[bodies]]", f'name = "link{i}"', f'mass = "m{i}"',
                  "inertia = [0.1, 0.1, 0.02]", "center = [0, 0, -0.5]"]
        if i:
            lines.append(f'parent = "link{i - 1}"')
        lines += [f'joint = {{ type = "revolute", axis = "{"xy"[i % 2]}", angle = "q{i}"{at} }}',
                  ""]
    return "\n".join(lines)


def spatial_chain_urdf(n: int) -> str:
    """The same chain as a URDF (for Pinocchio): link i's frame at its joint."""
    parts = ['<robot name="chain">', '<link name="base"/>']
    for i in range(n):
        parts.append(f'<link name="link{i}"><inertial><origin xyz="0 0 -0.5"/><mass value="1"/>'
                     '<inertia ixx="0.1" iyy="0.1" izz="0.02" ixy="0" ixz="0" iyz="0"/>'
                     '</inertial></link>')
        parent = "base" if i == 0 else f"link{i - 1}"
        z = 0 if i == 0 else -1
        axis = "1 0 0" if i % 2 == 0 else "0 1 0"
        parts.append(f'<joint name="q{i}" type="revolute"><parent link="{parent}"/>'
                     f'<child link="link{i}"/><origin xyz="0 0 {z}"/><axis xyz="{axis}"/>'
                     '<limit lower="-10" upper="10" effort="100" velocity="100"/></joint>')
    parts.append("</robot>")
    return "\n".join(parts)
