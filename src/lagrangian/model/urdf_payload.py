"""Payloads on a robot read from URDF: a point mass m (kg) fixed to a link at a point (x, y, z)
of the link's frame (m), as if the file had one more link on a fixed joint carrying that mass
(so the result equals that of the edited URDF, everything else unchanged).

``{"tool0": 2.5}`` puts 2.5 kg at the link's origin; ``{"tool0": (2.5, (0, 0, 0.1))}`` 10 cm
along its z axis. The robot's tree changes; its dynamics run on the compact kernel
(dynamics/engine/compact_kernel.py), which takes the tree's numbers at run time: no rebuild.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from ..errors import InputError

PREFIX = "lagrangian_payload_"


def payload_values(payloads: Mapping[str, object], field: str = "payload"
                   ) -> dict[str, tuple[float, tuple[float, float, float]]]:
    """Each link's (mass in kg, point in the link's frame in m), checked: a mass that is a
    positive finite number, a point of three finite numbers."""
    if not isinstance(payloads, Mapping):
        raise InputError("a payload is {link: mass} or {link: (mass, (x, y, z))}", field=field)
    out = {}
    for link, value in payloads.items():
        where = f"{field}.{link}"
        if isinstance(value, tuple | list):
            if len(value) != 2:
                raise InputError("expected a mass, or (mass, (x, y, z))", field=where)
            mass, point = value
        else:
            mass, point = value, (0.0, 0.0, 0.0)
        try:
            mass = float(mass)
            point = tuple(float(x) for x in point)  # type: ignore[union-attr]
        except (TypeError, ValueError):
            raise InputError(f"{value!r} is not a mass (kg) with a point (x, y, z) in m",
                             field=where) from None
        if not (math.isfinite(mass) and mass > 0):
            raise InputError(f"the mass {mass!r} kg must be positive and finite", field=where)
        if len(point) != 3 or not all(math.isfinite(x) for x in point):
            raise InputError("the point is three finite numbers x, y, z (m)", field=where)
        out[str(link)] = (mass, point)
    return out


def add_payloads(root, payloads: Mapping[str, tuple[float, tuple[float, float, float]]],
                 source: str) -> None:
    """Add to the parsed URDF (an lxml <robot>) one link per payload on a fixed joint."""
    from lxml import etree

    from ..errors import did_you_mean

    links = [link.get("name") for link in root.findall("link")]
    for i, (link, (mass, point)) in enumerate(payloads.items()):
        if link not in links:
            raise InputError(f"no link '{link}' in {source}{did_you_mean(link, links)}",
                             field=f"payload.{link}")
        name = f"{PREFIX}{i}"
        body = etree.SubElement(root, "link", name=name)
        inertial = etree.SubElement(body, "inertial")
        etree.SubElement(inertial, "origin", xyz=" ".join(repr(x) for x in point), rpy="0 0 0")
        etree.SubElement(inertial, "mass", value=repr(mass))
        etree.SubElement(inertial, "inertia", ixx="0", ixy="0", ixz="0", iyy="0", iyz="0",
                         izz="0")
        joint = etree.SubElement(root, "joint", name=name, type="fixed")
        etree.SubElement(joint, "parent", link=link)
        etree.SubElement(joint, "child", link=name)
        etree.SubElement(joint, "origin", xyz="0 0 0", rpy="0 0 0")


__all__ = ["add_payloads", "payload_values"]
