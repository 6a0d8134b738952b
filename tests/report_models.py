"""Models for the report tests: one whose every piece of text is hostile markup."""

HOSTILE_NAME = '<script>alert("name")</script></math><img src=x onerror=alert(1)> cost $\\frac$'
HOSTILE_MODEL = f"""# </code></pre><script>alert("file")</script>
name = '{HOSTILE_NAME}'
description = "</p><script>alert('description')</script>"

[coordinates]
theta = {{ unit = "rad", initial = 0.3, rate = 0.0 }}

[parameters]
m = {{ value = 1.0, unit = "kg" }}
L = {{ value = 0.5, unit = "m" }}
g = {{ value = 9.81, unit = "m/s^2" }}

[gravity]
g = "g"
direction = [0, -1]

[[particles]]
name = "bob</math>"
mass = "m"
position = ["L*sin(theta)", "-L*cos(theta)"]

[[loads]]
name = "<script>push</script>"
point = "bob</math>"
force = ["m*g/10", 0]
"""
