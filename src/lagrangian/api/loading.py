"""lagrangian.load: a model file (TOML), a robot (URDF, MJCF), a built-in example or an
installed example-robot-data robot by name, as a System."""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path

from ..errors import InputError
from .system import System


def load(path_or_example: str | Path, *, lock: Mapping[str, float] | None = None,
         gravity: Sequence[float] | None = None, payload: Mapping[str, object] | None = None,
         floating_base: bool = False) -> System:
    """Load a model file (TOML), a robot (URDF: ``lock`` freezes joints by name, rad or m, or
    a text with its unit, "30deg", checked against the joint's kind and limit; ``payload``
    {link: mass, or (mass, (x, y, z))} fixes point masses (kg, m in the link's frame) to links,
    as an edited URDF would; ``floating_base`` frees its root link, nq = n + 7, nv = n + 6:
    dynamics and kinematics only), a MuJoCo robot (MJCF, .xml: hinge, slide, ball and free
    joints in MuJoCo's qpos and qvel layout, docs/bridges.md; ``floating_base`` makes its one
    free joint the free flyer instead; ``lock`` and ``payload`` as for URDF), a built-in
    example by name (see ``examples()``), or an installed example-robot-data robot by its
    short name ("panda", "ur5": ``example_robots()``; a built-in example of the same name comes
    first); ``gravity`` (g_x, g_y, g_z) in m/s^2 turns the model's gravity
    (System.with_gravity)."""
    system = _load(path_or_example, lock, payload, floating_base)
    return system if gravity is None else system.with_gravity(gravity)


def _load(path_or_example: str | Path, lock, payload, floating_base) -> System:
    from ..model.examples import example_path
    from ..model.reader import read_model

    path = Path(path_or_example)
    if path.suffix.lower() in (".xml", ".mjcf"):  # MuJoCo's MJCF, read as the URDF it is
        from ..model.mjcf import read_mjcf

        return System(read_mjcf(path, lock, payload, floating_base))
    # a built-in model file by name is no URDF (example_urdf gives None): no URDF reader loaded
    if path.exists() or not _built_in_model_file(str(path_or_example)):
        from ..model.urdf import example_urdf, read_urdf

        urdf = path if path.suffix.lower() == ".urdf" else (
            None if path.exists() else example_urdf(str(path_or_example)))
        if urdf is not None:
            model = read_urdf(urdf, lock, payload, floating_base)
            return System(model if urdf is path else replace(model, source=f"example:{path}"))
    for name, given, what in (("payload", payload, "links to carry a payload"),
                              ("lock", lock, "joints to lock"),
                              ("floating_base", floating_base, "a base to float")):
        if given:
            raise InputError(f"only a URDF model has {what}", field=name)
    if path.exists() or path.suffix == ".toml" or len(path.parts) > 1:
        return System(read_model(path))
    model = read_model(example_path(str(path_or_example)))
    return System(replace(model, source=f"example:{path_or_example}"))


def _built_in_model_file(name: str) -> bool:
    """Whether ``name`` is a built-in example's model file (TOML) with no built-in URDF of the
    same name (that one would come first)."""
    from importlib import resources

    if not re.fullmatch(r"\w+", name):
        return False
    folder = resources.files("lagrangian.model.examples")
    return (folder / f"{name}.toml").is_file() and not (folder / f"{name}.urdf").is_file()
