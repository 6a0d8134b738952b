"""Errors a user can meet, each naming where the problem is and what is wrong."""

from __future__ import annotations

import difflib
from collections.abc import Iterable


def closest_name(name: str, known: Iterable[str]) -> str | None:
    """The known name closest to ``name`` (difflib, ignoring case), or None when none is close.
    A name that differs only in case ('l' for 'L') is the closest of all."""
    name, known = str(name), [str(k) for k in known]  # a key of any type is named by its text
    same_but_case = [k for k in known if k.lower() == name.lower()]
    if same_but_case:
        return same_but_case[0]
    lowered: dict[str, str] = {}
    for k in known:
        lowered.setdefault(k.lower(), k)
    close = difflib.get_close_matches(name.lower(), lowered, n=1)
    return lowered[close[0]] if close else None


def misspelled(label: str | None, names: Iterable[str], known: Iterable[str]) -> str:
    """"V uses L1, which the model does not declare; did you mean l1?" when some of ``names``
    are close to ``known`` ones (closest_name), else ""."""
    known = list(known)
    close = {name: closest_name(name, known) for name in sorted(names)}
    if not any(close.values()):
        return ""
    means = ", ".join(c for c in close.values() if c)
    return f"{label} uses {', '.join(close)}, which the model does not declare; did you mean {means}?"


def did_you_mean(name: str, known: Iterable[str]) -> str:
    """"; did you mean 'x'?" naming the known name closest to ``name`` (closest_name), or ""
    when none is close."""
    close = closest_name(name, known)
    return f"; did you mean '{close}'?" if close else ""


def did_you_mean_or_list(name: str, known: Iterable[str], most: int = 24) -> str:
    """The hint of did_you_mean, or when no name is close, the valid names themselves
    ("; expected one of: a, b, c"), so an error never leaves a user guessing."""
    known = list(known)
    hint = did_you_mean(name, known)
    if hint or not known:
        return hint
    shown = ", ".join(known[:most]) + (", ..." if len(known) > most else "")
    return f"; expected one of: {shown}"


# control characters as escapes (a newline as \n), so every message stays one line and no
# user text reaches a terminal as a command: C0, DEL and C1 (0x9b is a terminal's CSI), the
# line and paragraph separators (str.splitlines breaks there) and the bidirectional overrides
_ONE_LINE = {code: f"\\u{code:04x}" if code > 255 else repr(chr(code))[1:-1]
             for code in (*range(32), *range(127, 160), 0x2028, 0x2029,
                          *range(0x202A, 0x202F), *range(0x2066, 0x206A))}


def one_line(text: str) -> str:
    """``text`` with its control characters as escapes: one line, safe for a terminal."""
    return text.translate(_ONE_LINE)


class LagrangianError(Exception):
    """Base class for every error the library raises on bad input (CLI exit status 2)."""


class ModelError(LagrangianError):
    """A model (file or builder) is invalid: names the source, the field and the problem."""

    def __init__(self, message: str, *, field: str | None = None, source: str | None = None):
        self.message = message
        self.field = field
        self.source = source
        super().__init__(self.__str__())

    def __str__(self) -> str:
        where = ": ".join(part for part in (self.source, self.field) if part)
        text = f"{where}: {self.message}" if where else self.message
        return one_line(text)  # a TOML key or value may hold a newline


class InputError(ModelError):
    """A bad argument (an option, a keyword, an output path), as opposed to a bad model file.

    Names the argument in ``field`` (``--t-end``, ``samples``). It is a ModelError too, so code
    that caught ModelError for bad arguments before keeps working."""

    def __init__(self, message: str, *, field: str | None = None):
        super().__init__(message, field=field)


class MissingExtraError(InputError):
    """An optional part of the library whose packages are not installed (the study stack of
    [sweep], pyarrow of [parquet], ...): names the extra that installs them, in one line.

    ``extra`` is its name and ``module`` the module that could not be imported."""

    def __init__(self, what: str, extra: str, module: str, reason: str = ""):
        self.extra = extra
        self.module = module
        why = f"{module} cannot be imported: {reason}" if reason else f"{module} is not installed"
        super().__init__(f'{what} needs the optional extra [{extra}]: pip install '
                         f'"lagrangian[{extra}]" ({why})')


def require_extra(extra: str, modules: Iterable[str], what: str) -> None:
    """Import each of ``modules`` (the packages of the optional extra ``extra``), or raise a
    MissingExtraError naming the extra for ``what`` the user asked for ("a parameter study")."""
    import importlib

    for module in modules:
        try:
            importlib.import_module(module)
        except ImportError as exc:
            # a module absent (the usual case: named, even when it is a dependency of one of
            # ``modules``) or present but broken (a shared library of its own missing): either
            # way installing the extra is the fix, and the reason is kept
            if isinstance(exc, ModuleNotFoundError):
                raise MissingExtraError(what, extra, exc.name or module) from None
            reason = " ".join(str(exc).split())[:160]
            raise MissingExtraError(what, extra, module, reason) from None


class DerivationError(LagrangianError):
    """The model is well formed but its equations cannot be formed (singular mass matrix, ...)."""


def lock_hint(joints) -> str:
    """The message for URDF joints that move no mass, naming the fix (lock)."""
    listed = ", ".join(f"'{j}'" for j in joints)
    flags = " ".join(f"--lock {j}=0" for j in joints)
    locks = ", ".join(f"'{j}': 0.0" for j in joints)
    many = len(joints) > 1
    return (f"singular mass matrix: URDF joint{'s' if many else ''} {listed} move"
            f"{'' if many else 's'} no mass (every link below carries none), so no acceleration "
            f"is defined for {'them' if many else 'it'}; freeze {'them' if many else 'it'} at a "
            f"value: {flags} (Python: load(path, lock={{{locks}}}))")


class ModelWarning(UserWarning):
    """A model was read with something left out that cannot change its results (a URDF link
    fixed to the root with an inertia that is not physical); one line, printed by the CLI."""


class BackendWarning(RuntimeWarning):
    """A compiler is there but the generated C failed to build: numpy runs instead (the same
    numbers, slower); one line, printed by the CLI."""


class DynamicsWarning(UserWarning):
    """Some states of a batch have no dynamics (an input not finite, or for forward dynamics a
    mass matrix that is not positive definite): their output rows are NaN, the others exact.
    Issued once per call; ``count`` and ``total`` say how many states of how many."""

    def __init__(self, message: str, count: int = 0, total: int = 0):
        super().__init__(message)
        self.count, self.total = count, total
