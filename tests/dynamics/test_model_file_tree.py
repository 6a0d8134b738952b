"""A model file's rigid bodies on revolute and prismatic joints as a kinematic tree
(model/tree.body_tree): the recursive algorithms agree with Lagrange's equations derived term by
term (two derivations) at random states, for random spatial chains and branching trees of 3 to 6
bodies, a planar chain, prismatic joints, a joint angle k q + c, an actuator parameter and no
gravity; a model holding anything else has no tree; a chain too deep to derive is refused by
derive in one line before the work, while its dynamics go down the tree."""

from __future__ import annotations

import time

import numpy as np
import pytest

import lagrangian
from lagrangian.compile import compiled
from lagrangian.compile.functions import numeric
from lagrangian.derivation.lagrange import derive
from lagrangian.dynamics.recursive import TREE_PATH_BODIES, TreeDynamics, applicable_tree
from lagrangian.errors import ModelError
from lagrangian.model.builder import ModelBuilder
from lagrangian.model.rotations import MAX_CHAIN_ROTATIONS

needs_c = pytest.mark.skipif(not compiled.available(), reason="no C compiler / Python headers")


def random_tree(seed: int, n: int, *, branching: bool = True, prismatic: bool = True,
                gravity: bool = True, actuator: bool = False) -> ModelBuilder:
    """n bodies, each on a random revolute (or prismatic) joint of a random earlier body."""
    rng = np.random.default_rng(seed)
    b = ModelBuilder(f"tree {seed}")
    if gravity:
        b.parameter("g", 9.81)
        b.set_gravity("g", tuple(round(float(x), 3) for x in rng.normal(size=3)))
    for i in range(n):
        slides = prismatic and rng.random() < 0.25
        b.coordinate(f"q{i}", "m" if slides else "rad")
        b.parameter(f"m{i}", float(rng.uniform(0.5, 2.0)))
        b.parameter(f"a{i}", float(rng.uniform(0.2, 1.0)))
        axis = [round(float(x), 3) for x in rng.normal(size=3)]
        at = [0, 0, f"-a{i}"] if i else [0.1, 0, 0]
        if slides:
            joint = {"type": "prismatic", "axis": axis, "distance": f"q{i}", "at": at}
        else:
            joint = {"type": "revolute", "axis": axis if i % 3 else "xy"[i % 2],
                     "angle": f"q{i}" if i != 2 else f"2*q{i} + 0.3", "at": at}
        parent = None if i == 0 else f"link{rng.integers(0, i) if branching else i - 1}"
        off = [round(float(x), 4) for x in 0.005 * rng.normal(size=3)]
        inertia = [[0.1, off[0], off[1]], [off[0], 0.12, off[2]], [off[1], off[2], 0.08]]
        b.add_rigid_body(f"link{i}", f"m{i}", inertia, parent=parent, joint=joint,
                         center=[round(float(x), 3) for x in rng.normal(scale=0.3, size=3)])
    if actuator:
        b.parameter("tau", 0.7)
        b.add_generalized_force("q1", "tau")
    return b


def assert_agree(model, tree_dynamics, states: int = 6, seed: int = 0):
    """M and the bias of the tree equal those of the derived equations, and T + V."""
    symbolic = numeric(derive(model), backend="numpy")
    rng = np.random.default_rng(seed)
    n = len(model.coordinates)
    q, v = rng.uniform(-2, 2, (states, n)), rng.uniform(-2, 2, (states, n))
    scale = 1 + np.abs(symbolic.mass_matrix(q, v)).max()
    assert np.allclose(tree_dynamics.mass_matrix(q), symbolic.mass_matrix(q, v),
                       rtol=1e-10, atol=1e-10 * scale)
    assert np.allclose(tree_dynamics.bias_forces(q, v), -symbolic.forcing(q, v),
                       rtol=1e-10, atol=1e-10 * scale)
    energy = tree_dynamics.kinetic_energy(q, v) + tree_dynamics.potential_energy(q)
    assert np.allclose(energy, symbolic.energy(q, v), rtol=1e-10, atol=1e-10 * scale)


@pytest.mark.parametrize("seed, n", [(1, 3), (2, 4), (3, 5),
                                     pytest.param(4, 6, marks=pytest.mark.slow)])
def test_a_random_tree_of_bodies_on_joints_agrees_with_lagrange(seed, n):
    model = random_tree(seed, n).build_model()
    tree = applicable_tree(model)
    assert tree is not None and len(tree.joints) == n
    assert_agree(model, TreeDynamics(model, tree, kernel="numpy"), seed=seed)


def test_the_spatial_chain_with_an_actuator_and_without_gravity_agrees():
    for builder in (random_tree(7, 3, branching=False, actuator=True),
                    random_tree(8, 3, gravity=False)):
        model = builder.build_model()
        assert_agree(model, TreeDynamics(model, applicable_tree(model), kernel="numpy"))


def test_a_planar_chain_on_z_axes_agrees_and_has_the_textbook_mass_matrix():
    """A double pendulum of rods (m, l, I_G = m l^2 / 12) turning about z in the x-y plane."""
    b = ModelBuilder("planar chain")
    b.parameter("g", 9.81)
    b.set_gravity("g", (0, -1, 0))
    m, length = 1.3, 0.8
    for i in range(2):
        b.coordinate(f"q{i}", "rad")
        joint = {"type": "revolute", "axis": "z", "angle": f"q{i}"}
        if i:
            joint["at"] = [0, -length, 0]
        b.add_rigid_body(f"rod{i}", m, [m * length**2 / 12, 1e-3, m * length**2 / 12],
                         parent=f"rod{i - 1}" if i else None, joint=joint,
                         center=[0, -length / 2, 0])
    model = b.build_model()
    dynamics = TreeDynamics(model, applicable_tree(model), kernel="numpy")
    assert_agree(model, dynamics)
    # two rods hanging straight: M = m l^2 [[1/3 + 1/12 + 9/4, 1/12 + 1/4 + 1/2], [., 1/3]]
    expected = m * length**2 * np.array([[8 / 3, 5 / 6], [5 / 6, 1 / 3]])
    # a 1e-3 kg m^2 about the rods' own x axis does not enter a motion about z
    assert np.allclose(dynamics.mass_matrix(np.zeros(2)), expected, rtol=1e-12)


@needs_c
def test_the_compiled_tree_agrees_with_lagrange():
    model = random_tree(11, 4, actuator=True).build_model()
    assert_agree(model, TreeDynamics(model, applicable_tree(model), kernel="unrolled"))


def test_a_model_holding_anything_else_has_no_tree():
    edits = [
        lambda b: b.add_potential_energy("q0**2"),
        lambda b: b.add_particle("p", 1.0, ("q0", 0, 0)),
        lambda b: b.add_generalized_force("q0", "q1"),  # not a parameter
        lambda b: b.add_moment("spin", "link1", (0, 0, 1)),
    ]
    for edit in edits:
        b = random_tree(3, 3)
        edit(b)
        assert applicable_tree(b.build_model()) is None
    # a body on a spherical joint, or a mass that changes with q
    b = random_tree(3, 2)
    b.coordinate("phi", "rad")
    b.add_rigid_body("ball", 1.0, [0.1, 0.1, 0.1], parent="link1",
                     joint={"type": "spherical", "rotation": [["z", "phi"]]})
    assert applicable_tree(b.build_model()) is None
    b = ModelBuilder("growing")
    b.coordinate("q", "rad")
    b.add_rigid_body("bar", "1 + q**2", [0.1, 0.1, 0.1],
                     joint={"type": "revolute", "axis": "z", "angle": "q"})
    assert applicable_tree(b.build_model()) is None
    # a parameter without a value: no numbers for the tree
    b = ModelBuilder("symbolic")
    b.coordinate("q", "rad")
    b.parameter("m")
    b.add_rigid_body("bar", "m", [0.1, 0.1, 0.1],
                     joint={"type": "revolute", "axis": "z", "angle": "q"})
    assert applicable_tree(b.build_model()) is None


def test_the_tree_follows_the_parameter_values():
    model = random_tree(2, 4).build_model()
    heavier = applicable_tree(model, {"m0": 5.0})
    assert heavier.joints[0].mass == 5.0
    assert applicable_tree(model).joints[0].mass != 5.0
    assert_agree(model.with_parameter_values({"m0": 5.0}),
                 TreeDynamics(model, heavier, {"m0": 5.0}, kernel="numpy"))


def chain(n: int) -> ModelBuilder:
    b = ModelBuilder(f"{n}-body chain")
    b.parameter("g", 9.81)
    b.set_gravity("g", (0, 0, -1))
    for i in range(n):
        b.coordinate(f"q{i}", "rad")
        joint = {"type": "revolute", "axis": "xy"[i % 2], "angle": f"q{i}"}
        if i:
            joint["at"] = [0, 0, -1]
        b.add_rigid_body(f"link{i}", 1.0, [0.1, 0.1, 0.02], parent=f"link{i - 1}" if i else None,
                         joint=joint, center=[0, 0, -0.5])
    return b


def test_a_chain_too_deep_to_derive_is_refused_before_the_work_and_its_dynamics_run():
    n = MAX_CHAIN_ROTATIONS + 6
    started = time.perf_counter()
    system = lagrangian.System(chain(n).build_model())
    with pytest.raises(ModelError, match=f"{MAX_CHAIN_ROTATIONS + 1} elementary rotations.*"
                       f"at most {MAX_CHAIN_ROTATIONS}") as error:
        system.equations_of_motion()
    assert f"link{MAX_CHAIN_ROTATIONS}" in str(error.value) and "\n" not in str(error.value)
    assert time.perf_counter() - started < 10
    # the numbers go down the tree: the chain hanging straight down is at rest
    dynamics = system.dynamics(backend="numpy")
    assert dynamics.kernel == "numpy"
    assert np.allclose(dynamics.gravity(np.zeros(n)), 0.0, atol=1e-12)
    # a body's weight m g at the top joint, turned a quarter about x: n m g (n/2 - ... ) by value
    q = np.zeros(n)
    q[0] = np.pi / 2
    torque = dynamics.gravity(q)[0]
    # every body lies along +y at its centre's distance: sum of (k + 1/2) m g
    assert torque == pytest.approx(sum(k + 0.5 for k in range(n)) * 9.81, rel=1e-12)


def test_a_small_model_file_tree_keeps_its_derived_equations():
    system = lagrangian.System(chain(TREE_PATH_BODIES - 1).build_model())
    assert system._recursive is None
    assert lagrangian.System(chain(TREE_PATH_BODIES).build_model()).dynamics(
        backend="numpy").backend == "recursive-numpy"


def test_a_tree_simulates_and_has_modes_without_deriving():
    """Energy kept over a run, the work of an actuator balanced, and the modes of the hanging
    chain equal to those of the derived equations (K from the tree's g by differences)."""
    n = TREE_PATH_BODIES
    system = lagrangian.System(chain(n).build_model())
    run = system.simulate(1.0, initial={"q0": 0.4, "q3": -0.3})
    assert run.status == "finished" and run.invariant == "energy"
    energy = run.energy
    assert np.abs(energy - energy[0]).max() < 1e-7 * np.abs(energy).max()
    modes = system.modes(about={f"q{i}": 0.0 for i in range(n)})
    assert "_equations" not in system.__dict__  # nothing derived
    from lagrangian.compile.at_rest import AtRestFunctions
    from lagrangian.dynamics.tree_at_rest import TreeAtRest

    q = np.random.default_rng(4).uniform(-1, 1, (3, n))
    tree, derived = (TreeAtRest(system.dynamics()).evaluate(q),
                     AtRestFunctions(system.equations_of_motion()).evaluate(q))
    for key in ("mass", "forcing", "stiffness", "damping"):
        assert np.allclose(tree[key], derived[key], rtol=1e-9, atol=1e-9), key
    frequencies = [m.frequency for m in modes.modes]
    assert np.all(np.diff(frequencies) >= 0) and frequencies[0] > 0


def test_an_actuator_on_a_tree_does_work_that_balances():
    b = chain(TREE_PATH_BODIES)
    b.parameter("tau", 2.0)
    b.add_generalized_force("q0", "tau")
    run = lagrangian.System(b.build_model()).simulate(1.0)
    assert run.invariant == "work_balance"
    h, work = run.invariant_values, run.work
    assert np.abs(h - h[0] - work).max() < 1e-6 * np.abs(work).max()


def test_a_chain_too_large_to_compile_that_is_no_bare_tree_is_refused_before_the_work():
    from lagrangian.compile.functions import MAX_COMPILED_ROTATIONS

    b = chain(MAX_COMPILED_ROTATIONS + 2)
    b.add_potential_energy("q0**2")  # an energy of its own: not a bare tree
    system = lagrangian.System(b.build_model())
    started = time.perf_counter()
    for call in (system.numeric, system.modes, lambda: system.simulate(1.0)):
        with pytest.raises(ModelError, match=f"{MAX_COMPILED_ROTATIONS + 1} elementary "
                           "rotations.*too large to compile") as error:
            call()
        assert f"link{MAX_COMPILED_ROTATIONS}" in str(error.value)
    assert time.perf_counter() - started < 10


def test_the_documented_chain_runs_and_shows_the_physics():
    import re
    from pathlib import Path

    import docs_blocks  # tests/docs_blocks.py

    text = docs_blocks.block("tree-model-file")
    code = re.findall(r"```python\n(.*?)```", text, re.S)[0]
    scope: dict = {}
    exec(compile(code, str(Path(docs_blocks.block_file("tree-model-file"))), "exec"), scope)
    n = scope["n"]
    assert scope["snake"].dynamics().backend == "recursive"
    expected = sum(k + 0.5 for k in range(n)) * 9.81
    assert scope["held"] == pytest.approx(expected, rel=1e-12)
    assert f"{expected:.1f} N m" in code
    energy = scope["run"].energy
    assert np.abs(energy - energy[0]).max() < 1e-9 * np.abs(energy).max()
    assert scope["lowest"] > 0


def chain_file(n: int) -> str:
    """The chain of ``chain(n)`` as a model file."""
    lines = [f'name = "{n}-body chain"', "", "[coordinates]"]
    lines += [f'q{i} = {{ unit = "rad", initial = {0.2 if i == 0 else 0.0} }}' for i in range(n)]
    lines += ["", "[parameters]", 'g = { value = 9.81, unit = "m/s^2" }', "",
              "[gravity]", 'g = "g"', "direction = [0, 0, -1]", ""]
    for i in range(n):
        at = ", at = [0, 0, -1]" if i else ""
        lines += ["[[bodies]]", f'name = "link{i}"', "mass = 1.0", "inertia = [0.1, 0.1, 0.02]",
                  "center = [0, 0, -0.5]", *([f'parent = "link{i - 1}"'] if i else []),
                  f'joint = {{ type = "revolute", axis = "{"xy"[i % 2]}", angle = "q{i}"{at} }}',
                  ""]
    return "\n".join(lines)


def test_the_command_line_runs_a_model_files_tree_and_refuses_a_chain_too_deep(cli, tmp_path):
    import json

    path = tmp_path / "chain.toml"
    path.write_text(chain_file(TREE_PATH_BODIES))
    result = cli("simulate", str(path), "--t-end", "1", "--json")
    assert result.code == 0, result.err
    document = json.loads(result.out)
    assert document["status"] == "finished" and document["energy_conserved"]
    assert document["relative_energy_drift"] < 1e-9
    result = cli("modes", str(path), "--json")
    assert result.code == 0, result.err
    assert all(mode["frequency"] > 0 for mode in json.loads(result.out)["modes"])
    deep = tmp_path / "deep.toml"
    deep.write_text(chain_file(MAX_CHAIN_ROTATIONS + 1))
    result = cli("simulate", str(deep), "--t-end", "0.2", "--json")  # nothing derived
    assert result.code == 0, result.err
    assert json.loads(result.out)["relative_energy_drift"] < 1e-9
    result = cli("derive", str(deep))
    assert result.code == 2
    (line,) = result.err.strip().splitlines()
    assert line.startswith("error: ") and f"at most {MAX_CHAIN_ROTATIONS}" in line
