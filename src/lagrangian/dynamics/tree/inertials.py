"""A link's inertial as runtime parameters of a robot's dynamics: ``<link>.mass`` (kg),
``<link>.com_x``, ``com_y``, ``com_z`` (the URDF's <inertial><origin xyz>, m, in the link's
frame) and ``<link>.ixx``, ``ixy``, ``ixz``, ``iyy``, ``iyz``, ``izz`` (its <inertia>, kg m^2,
about the centre of mass in the inertial frame's axes): the results are those of the URDF
edited so (model/tree.py with_link_inertials)."""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from ...errors import InputError, did_you_mean
from ...model.tree import INERTIAL_FIELDS, KinematicTree, with_link_inertials


def split_inertials(tree: KinematicTree | None, parameters: Mapping[str, object] | None,
                    field: str = "parameters"):
    """(the model's own parameters, the tree with the links' inertials set, or None where none
    is): every ``<link>.<field>`` name checked against the tree's links and INERTIAL_FIELDS."""
    if not parameters:
        return parameters, None
    own = {k: v for k, v in parameters.items() if "." not in str(k)}
    dotted = {str(k): v for k, v in parameters.items() if "." in str(k)}
    if not dotted:
        return parameters, None
    if tree is None or not tree.links:
        name = next(iter(dotted))
        raise InputError("a link's inertial is a parameter of a robot read from URDF only",
                         field=f"{field}.{name}")
    links = [link.name for link in tree.links]
    values = {}
    for name, value in dotted.items():
        link, _, what = name.rpartition(".")
        where = f"{field}.{name}"
        if link not in links:
            raise InputError(f"no link '{link}'{did_you_mean(link, links)}", field=where)
        if what not in INERTIAL_FIELDS:
            raise InputError(f"a link's inertial is one of {', '.join(INERTIAL_FIELDS)}, not "
                             f"'{what}'{did_you_mean(what, list(INERTIAL_FIELDS))}", field=where)
        try:
            number = float(value)  # type: ignore[arg-type]
        except (TypeError, ValueError):
            raise InputError(f"{value!r} is not a number (SI units)", field=where) from None
        if not math.isfinite(number) or (what == "mass" and number < 0):
            raise InputError(f"{number!r} is not a finite " + (
                "mass of 0 kg or more" if what == "mass" else "number"), field=where)
        values[(link, what)] = number
    edited = with_link_inertials(tree, values)
    for link in edited.links:
        tensor = np.array(link.inertia)
        if any(name == link.name for name, _ in values) and np.linalg.eigvalsh(tensor)[0] < (
                -1e-12 * max(1.0, float(np.abs(tensor).max()))):
            raise InputError("the inertia tensor is not positive semidefinite",
                             field=f"{field}.{link.name}")
    return own, edited


__all__ = ["split_inertials"]
