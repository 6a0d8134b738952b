"""MJCF's joint equalities as mimic joints, and the joint losses folded onto the joint a mimic
follows.

<equality><joint joint1="a" joint2="b" polycoef="c0 c1 0 0 0"/> holds q_a = c0 + c1 q_b
(MuJoCo's qpos0 is 0 here: ref is refused), a URDF mimic joint (multiplier c1, offset c0), so
joint a is no coordinate of ours. MuJoCo holds the equality softly (solref, solimp) and we
exactly. On the constrained motion q_dot_a = c1 q_dot_b, so a mimic's armature I and damping d
act on b as c1^2 I and c1^2 d, its Coulomb friction f as |c1| f (the virtual work of each).
Everything else (weld, connect, tendon, flex equalities, a polynomial of higher degree, a joint
held at a constant) is refused in one line naming the element. Units SI (polycoef in rad or m,
whatever the compiler's angle).
"""

from __future__ import annotations

from ..errors import did_you_mean

# (master joint, offset c0, multiplier c1) of each mimic joint
Mimic = tuple[str, float, float]


def read_equalities(reader) -> dict[str, Mimic]:
    """The document's active joint equalities: joint1 -> (joint2, c0, c1)."""
    mimics: dict[str, Mimic] = {}
    for section in reader.root.iter("equality"):
        for k, element in enumerate(c for c in section if isinstance(c.tag, str)):
            name = element.get("name") or str(k)
            where = f"equality.{element.tag} '{name}'"
            if element.tag != "joint":
                raise reader.error(f"a <{element.tag}> equality is not supported (only <joint> "
                                   "equalities with a linear polycoef: our mimic joints)", where)
            attrs = dict(reader.defaults.get(element.get("class") or "main", {})
                         .get("equality", {}))
            attrs.update(element.attrib)
            if attrs.get("active", "true") == "false":  # not enforced: changes nothing
                continue
            first, second = attrs.get("joint1"), attrs.get("joint2")
            if not first:
                raise reader.error("a joint equality needs joint1", where)
            c0, c1, *higher = reader.numbers(attrs.get("polycoef", "0 1 0 0 0"), 5,
                                             f"{where}.polycoef")
            if not second or c1 == 0:
                raise reader.error(f"joint1 '{first}' is held at {c0:g}: not a mimic joint "
                                   "(lock it instead: load(..., lock={...}))", where)
            if any(higher):
                raise reader.error("a polycoef of degree above 1 is not supported (our mimic "
                                   "joints are linear: c0 + c1 q)", f"{where}.polycoef")
            if first == second:
                raise reader.error(f"joint1 and joint2 are both '{first}'", where)
            if first in mimics:
                raise reader.error(f"joint '{first}' is joint1 of two equalities", where)
            mimics[first] = (second, c0, c1)
    return mimics


def check_mimics(reader, mimics: dict[str, Mimic], joints, free) -> None:
    """Every equality's joints among the document's hinge and slide joints (``free``: the free
    joints' names), no cycle."""
    for first, (second, *_) in mimics.items():
        for name in (first, second):
            if name in free:
                raise reader.error(f"the free joint '{name}' cannot be in a joint equality",
                                   f"equality.joint '{first}'")
            if name not in joints:
                raise reader.error(f"no joint '{name}'{did_you_mean(name, joints)}",
                                   f"equality.joint '{first}'")
        master(reader, mimics, first)


def master(reader, mimics: dict[str, Mimic], name: str) -> tuple[str, float]:
    """The coordinate joint a joint follows through its chain of mimics, and the chain's
    multiplier (q_dot_name = k q_dot_master)."""
    k, seen = 1.0, {name}
    while name in mimics:
        name, _, c1 = mimics[name]
        k *= c1
        if name in seen:
            raise reader.error(f"a cycle of joint equalities through '{name}'",
                               f"equality.joint '{name}'")
        seen.add(name)
    return name, k


def folded_losses(reader, mimics: dict[str, Mimic],
                  losses: dict[str, tuple[float, float, float]]):
    """Per coordinate joint: (damping, friction, armature) with each mimic's added by its
    virtual work (module docstring)."""
    out = {name: list(values) for name, values in losses.items() if name not in mimics}
    for name, (damping, friction, armature) in losses.items():
        if name in mimics:
            top, k = master(reader, mimics, name)
            out[top][0] += k * k * damping
            out[top][1] += abs(k) * friction
            out[top][2] += k * k * armature
    return {name: tuple(values) for name, values in out.items()}


__all__ = ["Mimic", "check_mimics", "folded_losses", "master", "read_equalities"]
