"""Read a model file (TOML) into a :class:`Model`, naming file, table and key on every error."""

from __future__ import annotations

import errno
import functools
import math
import os
import re
import stat
import tomllib
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import BinaryIO

from ..errors import ModelError, did_you_mean, did_you_mean_or_list
from .builder import ModelBuilder
from .model import Model
from .units import check_unit, to_si

TOP_LEVEL = {
    "name", "description", "coordinates", "parameters", "definitions", "energy", "gravity",
    "particles", "bodies", "springs", "dampers", "loads", "generalized_forces", "constraints",
    "contacts", "steady", "control", "impacts",
}
COMPONENT_KEYS = {
    "particles": ({"name", "mass", "position"}, set()),
    "bodies": ({"name", "mass", "inertia"},
               {"position", "angle", "rotation", "origin", "center", "parent", "joint"}),
    "springs": ({"name", "stiffness"}, {"rest_length", "length", "between"}),
    "dampers": ({"name", "coefficient"}, {"rate", "between"}),
    "loads": ({"name"}, {"point", "force", "torque", "angle", "body", "moment", "axes"}),
    "constraints": ({"name"}, {"holonomic", "velocity"}),
    "contacts": ({"name", "body", "radius", "axle"}, {"normal"}),
    "impacts": ({"name", "guard", "point", "normal"},
                {"restitution", "tangential", "release", "relabel"}),
}
COORDINATE_KEYS = {"unit", "initial", "rate", "range"}  # a coordinate given as a table
PARAMETER_KEYS = {"value", "unit", "range", "integer"}  # a parameter given as a table
ENERGY_KEYS = {"T", "V", "D"}
GRAVITY_KEYS = ({"g"}, {"direction"})
STEADY_KEYS = ({"speed", "rates", "keep"}, {"about"})


def model_file_schema() -> dict[str, tuple[frozenset[str], frozenset[str]]]:
    """Every key the reader accepts: table -> (required keys, optional keys); "" is the file's
    top level. The table of docs/model-file.md is checked against it."""
    optional_top = TOP_LEVEL - {"coordinates"}
    schema = {"": (frozenset({"coordinates"}), frozenset(optional_top)),
              "coordinates.<name>": (frozenset(), frozenset(COORDINATE_KEYS)),
              "parameters.<name>": (frozenset(), frozenset(PARAMETER_KEYS)),
              "energy": (frozenset(), frozenset(ENERGY_KEYS)),
              "gravity": (frozenset(GRAVITY_KEYS[0]), frozenset(GRAVITY_KEYS[1])),
              "steady": (frozenset(STEADY_KEYS[0]), frozenset(STEADY_KEYS[1]))}
    for table, (required, optional) in COMPONENT_KEYS.items():
        schema[table] = (frozenset(required), frozenset(optional))
    return schema


# An input file (a model, an answer, a URDF) is text a person writes or a tool exports: the
# examples are under 10 kB and a robot's URDF (its meshes are other files) hundreds of kB at
# most, so 16 MiB leaves room for any generated file and still refuses a runaway one before it
# is read (a 3 GB answer file cost 3.2 GB of memory and 22 s before its first refusal).
MAX_TEXT_FILE_BYTES = 16 * 2**20

_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO"),
          (stat.S_ISCHR, "a device"), (stat.S_ISBLK, "a device"),
          (stat.S_ISSOCK, "a socket"), (stat.S_ISLNK, "a symbolic link"))


def file_kind(mode: int) -> str:
    """What a file that is not a regular one is ("a FIFO"), from its st_mode."""
    return next((name for test, name in _KINDS if test(mode)), "not a file")


def _size(n: int) -> str:
    """'3 GiB (3221225472 bytes)'."""
    for unit, scale in (("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if n >= scale:
            return f"{n / scale:.3g} {unit} ({n} bytes)"
    return f"{n} bytes"


def read_text_file(path: str | Path, *, follow_symlinks: bool = True) -> str:
    """The text of a user's input file; a missing, unreadable, non-regular (a FIFO, a device, a
    directory) or too large (MAX_TEXT_FILE_BYTES) file is a ModelError naming it, raised before
    anything is read. ``follow_symlinks=False`` refuses a symbolic link as well."""
    source = str(path)
    with _opened(path, follow_symlinks) as stream:
        try:
            data = stream.read(MAX_TEXT_FILE_BYTES + 1)  # a file still growing stops here
        except OSError as exc:
            raise ModelError(f"cannot read the file ({exc.strerror or exc})", source=source) \
                from None
    if len(data) > MAX_TEXT_FILE_BYTES:
        raise ModelError(f"the file grew past the limit of {_size(MAX_TEXT_FILE_BYTES)} for an "
                         "input file while it was read", source=source)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ModelError(f"cannot read the file ({exc})", source=source) from None
    return text.replace("\r\n", "\n").replace("\r", "\n")  # universal newlines, as read_text


def check_text_file(path: str | Path, *, follow_symlinks: bool = True) -> None:
    """Refuse ``path`` as read_text_file would before reading (missing, not a regular file, too
    large), reading nothing: lets a command refuse a bad input before its slow work."""
    _opened(path, follow_symlinks).close()


def _opened(path: str | Path, follow_symlinks: bool) -> BinaryIO:
    """``path`` open for reading, once it is known to be a regular file within the limit."""
    source = str(path)
    # O_NONBLOCK: opening a FIFO must not wait for a writer; O_BINARY: bytes as written (Windows)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0)
    if not follow_symlinks:
        flags |= getattr(os, "O_NOFOLLOW", 0)
    link = ModelError("not a regular file (a symbolic link): not read", source=source)
    try:
        if not follow_symlinks and Path(path).is_symlink():  # where O_NOFOLLOW is unknown
            raise link
        handle = os.open(path, flags)
    except FileNotFoundError:
        raise ModelError("no such file", source=source) from None
    except OSError as exc:
        if not follow_symlinks and exc.errno == errno.ELOOP:
            raise link from None
        raise ModelError(f"cannot read the file ({exc.strerror or exc})", source=source) \
            from None
    info = os.fstat(handle)  # the open file's, so nothing can be swapped in after the check
    fault = None
    if not stat.S_ISREG(info.st_mode):
        fault = f"not a regular file ({file_kind(info.st_mode)}): not read"
    elif info.st_size > MAX_TEXT_FILE_BYTES:
        fault = (f"the file is {_size(info.st_size)}, over the limit of "
                 f"{_size(MAX_TEXT_FILE_BYTES)} for an input file: not read")
    if fault:
        os.close(handle)
        raise ModelError(fault, source=source)
    return os.fdopen(handle, "rb")


def read_model(path: str | Path) -> Model:
    """Load a TOML model file."""
    return parse_model(read_text_file(path), source=str(path))


def parse_model(text: str, *, source: str = "<model>") -> Model:
    """Parse the text of a TOML model file."""
    return _parsed(text, source)


@functools.lru_cache(maxsize=32)
def _parsed(text: str, source: str) -> Model:
    # by content: a Model is immutable, and one text read twice (a notebook cell run again, a
    # second command in one process) is built once (the bicycle's rolling contacts take 1 s);
    # a refused text raises again, never cached
    return model_from_mapping(load_toml(text, source), source=source)


class _TinyNumber(ValueError):
    """A TOML float whose digits are not zero but whose value underflows to 0.0."""


def _toml_float(text: str) -> float:
    value = float(text)
    if abs(value) < 1e-300 and any(d in "123456789" for d in text.lower().partition("e")[0]):
        raise _TinyNumber(text)
    return value


def load_toml(text: str, source: str) -> dict:
    """The tables of a TOML document; a number too small for a float (1e-400) is refused,
    never read as 0."""
    try:
        return tomllib.loads(text, parse_float=_toml_float)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"invalid TOML: {exc}", source=source) from None
    except _TinyNumber as exc:
        raise ModelError(f"the number {exc} is too small (below 1e-300, it would be read as 0): "
                         f"write 0 or a larger number", field=_line_of(text, str(exc)),
                         source=source) from None
    except ValueError:  # an integer of more than 4300 digits
        raise ModelError("invalid TOML: a number has far too many digits", source=source) \
            from None


def _line_of(text: str, literal: str) -> str | None:
    """'line N (key)' of the first occurrence of a number literal, for the message."""
    for number, line in enumerate(text.splitlines(), 1):
        if re.search(rf"(?<![\w.]){re.escape(literal)}(?![\w.])", line):
            key = re.match(r"\s*([\w.\"'-]+)\s*=", line)
            return f"line {number}" + (f" ({key.group(1)})" if key else "")
    return None


def model_from_mapping(data: Mapping, *, source: str = "<model>") -> Model:
    """Build a Model from the already-parsed TOML tables."""
    check_known_keys(data, TOP_LEVEL, None, source)
    name = _string(data.get("name", ""), "name", source)
    description = _string(data.get("description", ""), "description", source)
    builder = ModelBuilder(name, description, source=source)

    coordinates = _table(data, "coordinates", source, required=True)
    for key, spec in coordinates.items():
        field = f"coordinates.{key}"
        if isinstance(spec, str):
            builder.coordinate(key, check_unit(spec, field, source), field=field)
        elif isinstance(spec, Mapping):
            check_known_keys(spec, COORDINATE_KEYS, field, source)
            unit = check_unit(_string(spec.get("unit", "m"), f"{field}.unit", source),
                              f"{field}.unit", source)
            builder.coordinate(
                key, unit, initial=spec.get("initial"), rate=spec.get("rate"),
                range=spec.get("range"), field=field,
            )
        else:
            raise ModelError("expected a unit string or a table {unit, initial, rate}",
                             field=field, source=source)

    for key, spec in _table(data, "parameters", source).items():
        field = f"parameters.{key}"
        if isinstance(spec, Mapping):
            check_known_keys(spec, PARAMETER_KEYS, field, source)
            unit = spec.get("unit")
            if unit is not None:
                unit = check_unit(_string(unit, f"{field}.unit", source), f"{field}.unit", source)
            value = spec.get("value")
            if value is not None and unit is not None:
                value = to_si(value, unit, f"{field}.value", source)
            bounds = spec.get("range")
            if bounds is not None and unit is not None and isinstance(bounds, list) \
                    and all(isinstance(b, int | float) and not isinstance(b, bool)
                            for b in bounds):
                bounds = [b if isinstance(b, float) and math.isinf(b)
                          else to_si(b, unit, f"{field}.range", source) for b in bounds]
            builder.parameter(key, value, unit, field=field, range=bounds,
                              integer=spec.get("integer", False))
        else:
            builder.parameter(key, spec, field=field)

    for key, text in _table(data, "definitions", source).items():
        builder.define(key, text, field=f"definitions.{key}")

    energy = _table(data, "energy", source)
    check_known_keys(energy, ENERGY_KEYS, "energy", source)
    adders: dict[str, Callable] = {
        "T": builder.add_kinetic_energy,
        "V": builder.add_potential_energy,
        "D": builder.add_dissipation,
    }
    for key, text in energy.items():
        adders[key](text, field=f"energy.{key}")

    if "gravity" in data:
        gravity = _table(data, "gravity", source)
        check_known_keys(gravity, GRAVITY_KEYS[0] | GRAVITY_KEYS[1], "gravity", source)
        if "g" not in gravity:
            raise ModelError("missing key 'g'", field="gravity", source=source)
        builder.set_gravity(gravity["g"], gravity.get("direction"))

    for index, item in _components(data, "particles", source):
        field = f"particles[{index}]"
        builder.add_particle(item["name"], item["mass"], item["position"], field=field)
    for index, item in tree_order(list(_components(data, "bodies", source)), source):
        field = f"bodies[{index}]"
        if is_spatial_body(item):
            if "angle" in item:
                raise ModelError("'angle' is for a planar body; a 3D body turns by 'rotation' "
                                 "or by its 'joint'", field=f"{field}.angle", source=source)
            builder.add_rigid_body(
                item["name"], item["mass"], item["inertia"], position=item.get("position"),
                rotation=item.get("rotation"), origin=item.get("origin"),
                center=item.get("center"), parent=item.get("parent"), joint=item.get("joint"),
                field=field)
            continue
        for key in ("position", "angle"):
            if key not in item:
                raise ModelError(f"missing key '{key}' (a planar body has 'position' and "
                                 "'angle'; a 3D body 'rotation' or 'joint')", field=field,
                                 source=source)
        builder.add_body(item["name"], item["mass"], item["inertia"], item["position"],
                         item["angle"], field=field)
    for index, item in _components(data, "springs", source):
        builder.add_spring(
            item["name"], item["stiffness"], item.get("rest_length", 0),
            length=item.get("length"), between=item.get("between"), field=f"springs[{index}]",
        )
    for index, item in _components(data, "dampers", source):
        builder.add_damper(
            item["name"], item["coefficient"], rate=item.get("rate"),
            between=item.get("between"), field=f"dampers[{index}]",
        )
    for index, item in _components(data, "loads", source):
        field = f"loads[{index}]"
        has_force = "point" in item or "force" in item
        has_torque = "torque" in item or "angle" in item
        has_moment = "moment" in item or "body" in item or "axes" in item
        if has_force + has_torque + has_moment != 1:
            raise ModelError("give either 'point' and 'force', 'torque' and 'angle', or "
                             "'body' and 'moment'", field=field, source=source)
        if has_moment:
            for key in ("body", "moment"):
                if key not in item:
                    raise ModelError(f"missing key '{key}'", field=field, source=source)
            builder.add_moment(item["name"], _string(item["body"], f"{field}.body", source),
                               item["moment"], axes=item.get("axes", "world"), field=field)
        elif has_force:
            for key in ("point", "force"):
                if key not in item:
                    raise ModelError(f"missing key '{key}'", field=field, source=source)
            builder.add_force(item["name"], item["point"], item["force"], field=field)
        else:
            for key in ("torque", "angle"):
                if key not in item:
                    raise ModelError(f"missing key '{key}'", field=field, source=source)
            builder.add_torque(item["name"], item["torque"], item["angle"], field=field)

    for key, text in _table(data, "generalized_forces", source).items():
        builder.add_generalized_force(key, text, field=f"generalized_forces.{key}")

    for index, item in _components(data, "contacts", source):
        field = f"contacts[{index}]"
        builder.add_rolling_contact(item["name"], _string(item["body"], f"{field}.body", source),
                                    item["radius"], item["axle"], normal=item.get("normal"),
                                    field=field)
    for index, item in _components(data, "constraints", source):
        builder.add_constraint(
            item["name"], holonomic=item.get("holonomic"), velocity=item.get("velocity"),
            field=f"constraints[{index}]",
        )
    for index, item in _components(data, "impacts", source):
        field = f"impacts[{index}]"
        builder.add_impact(
            item["name"], item["guard"], item["point"], item["normal"],
            restitution=item.get("restitution", 0),
            tangential=_string(item.get("tangential", "slip"), f"{field}.tangential", source),
            release=item.get("release"), relabel=item.get("relabel"), field=field)
    for key, law in _table(data, "control", source).items():
        field = f"control.{key}"
        builder.add_control_law(key, _string(law, field, source), field=field)
    steady = _table(data, "steady", source)
    if steady:
        check_known_keys(steady, STEADY_KEYS[0] | STEADY_KEYS[1], "steady", source)
        for key in sorted(STEADY_KEYS[0]):
            if key not in steady:
                raise ModelError(f"missing key '{key}'", field="steady", source=source)
        rates = steady["rates"]
        if not isinstance(rates, Mapping):
            raise ModelError("expected a table, e.g. rates = { x_dot = \"v\" }",
                             field="steady.rates", source=source)
        about = steady.get("about", {})
        if not isinstance(about, Mapping):
            raise ModelError("expected a table of coordinate values", field="steady.about",
                             source=source)
        keep = steady["keep"]
        if not isinstance(keep, list) or not all(isinstance(k, str) for k in keep):
            raise ModelError("expected a list of coordinate names, e.g. [\"phi\", \"delta\"]",
                             field="steady.keep", source=source)
        builder.set_steady_motion(_string(steady["speed"], "steady.speed", source), rates, keep,
                                  about)
    return builder.build_model()


SPATIAL_BODY_KEYS = ("rotation", "origin", "center", "parent", "joint")


def is_spatial_body(item: Mapping) -> bool:
    """A body in space (3D keys, or an inertia given as a list) rather than a planar one."""
    return any(key in item for key in SPATIAL_BODY_KEYS) or isinstance(item.get("inertia"), list)


def tree_order(items: list[tuple[int, Mapping]], source: str) -> list[tuple[int, Mapping]]:
    """Bodies with every parent before its children (file order otherwise); a missing parent
    or a cycle is named with the body's field."""
    names = {item["name"]: (index, item) for index, item in items}
    placed: set[str] = set()
    ordered: list[tuple[int, Mapping]] = []

    def place(index: int, item: Mapping) -> None:
        # Walk up to a placed body or the ground, then place the chain from the top down:
        # iterative, so a chain of thousands of bodies is no recursion-depth traceback.
        chain: list[tuple[int, Mapping]] = []
        on_chain: set[str] = set()
        while item["name"] not in placed:
            name = item["name"]
            chain.append((index, item))
            on_chain.add(name)
            parent = item.get("parent")
            if parent is None:
                break
            field = f"bodies[{index}].parent"
            _string(parent, field, source)
            if parent in on_chain:
                path = [entry["name"] for _, entry in chain]
                cycle = " -> ".join([*path[path.index(parent):], parent]) \
                    if parent != name else f"{name} -> {name}"
                raise ModelError(f"the bodies' parents form a cycle ({cycle}): a kinematic tree "
                                 "ends at the ground", field=field, source=source)
            if parent not in names:
                raise ModelError(f"no body named '{parent}'"
                                 f"{did_you_mean(parent, sorted(names))}", field=field,
                                 source=source)
            index, item = names[parent]
        for entry in reversed(chain):
            placed.add(entry[1]["name"])
            ordered.append(entry)

    for index, item in items:
        place(index, item)
    return ordered


def _table(data: Mapping, key: str, source: str, *, required: bool = False) -> Mapping:
    if key not in data:
        if required:
            raise ModelError(f"missing table [{key}]", field=key, source=source)
        return {}
    value = data[key]
    if not isinstance(value, Mapping):
        raise ModelError(f"expected a table [{key}]", field=key, source=source)
    return value


def _components(data: Mapping, key: str, source: str):
    items = data.get(key, [])
    if not isinstance(items, list):
        raise ModelError(f"expected an array of tables [[{key}]]", field=key, source=source)
    required, optional = COMPONENT_KEYS[key]
    for index, item in enumerate(items):
        field = f"{key}[{index}]"
        if not isinstance(item, Mapping):
            raise ModelError("expected a table", field=field, source=source)
        check_known_keys(item, required | optional, field, source)
        missing = sorted(required - set(item), key=lambda k: (k != "name", k))
        if missing:
            raise ModelError(f"missing key '{missing[0]}'", field=field, source=source)
        _string(item["name"], f"{field}.name", source)
        yield index, item


def check_known_keys(
    table: Mapping, allowed, field: str | None, source: str, what: str = "key"
) -> None:
    """Unknown keys are errors (never silently ignored), with the nearest valid one suggested."""
    for key in table:
        if key not in allowed:
            hint = did_you_mean_or_list(key, sorted(allowed))
            where = f"{field}.{key}" if field else key
            raise ModelError(f"unknown {what} '{key}'{hint}", field=where, source=source)


def _string(value: object, field: str, source: str) -> str:
    if not isinstance(value, str):
        raise ModelError(f"expected a string, got {value!r}", field=field, source=source)
    return value
