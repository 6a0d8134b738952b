"""`lagrangian derive MODEL`: energies, equations of motion, generalized forces, matrices."""

from __future__ import annotations

from enum import StrEnum
from typing import Annotated

import typer

from ..errors import InputError
from . import app
from .common import LOCK_HELP, SET_HELP, load_system, print_json, warn_if_unphysical


class Format(StrEnum):
    text = "text"
    latex = "latex"
    json = "json"


@app.command()
def derive(
    model: Annotated[str, typer.Argument(help="Model file (TOML) or built-in example name.")],
    format: Annotated[Format, typer.Option("--format", "-f", help="Output format.")] = Format.text,
    json_: Annotated[bool, typer.Option("--json", help="Print JSON (as --format json, the flag of every other command).")] = False,  # noqa: E501
    set_: Annotated[list[str], typer.Option("--set", help=SET_HELP)] = [],  # noqa: B006
    lock: Annotated[list[str], typer.Option("--lock", help=LOCK_HELP)] = [],  # noqa: B006
    steps: Annotated[bool, typer.Option("--steps", help="Show the working: dL/dq_dot, its d/dt, dL/dq, Q and each load's virtual work (a 'steps' key in JSON).")] = False,  # noqa: E501
    steps_full: Annotated[bool, typer.Option("--steps-full", help="--steps with every step printed, however large (a step over 1000 nodes is otherwise given by its size; the JSON is always complete).")] = False,  # noqa: E501
    standalone: Annotated[bool, typer.Option("--standalone", help="With --format latex: a complete document for pdflatex (title, amsmath), not a fragment.")] = False,  # noqa: E501
    expand: Annotated[bool, typer.Option("--expand", help="Write every expression out in full, however large (large equations, a deep chain of bodies, are otherwise written in named intermediate quantities listed first).")] = False,  # noqa: E501
    routh: Annotated[list[str], typer.Option("--routh", help="Reduce by Routh: each named cyclic coordinate's momentum becomes a constant p_NAME; prints the reduced Lagrangian L_R = L - p q_dot (the Routhian R = -L_R), its effective potential and its equations. Repeat, or join with commas.")] = [],  # noqa: B006,E501
    hamilton: Annotated[bool, typer.Option("--hamilton", help="Hamilton's equations: the momenta p = dL/dq_dot, H(q, p) and q_dot = dH/dp, p_dot = -dH/dq + Q.")] = False,  # noqa: E501
) -> None:
    """Derive the equations of motion by Lagrange's method."""
    from ..output.derivation import derivation_document, derivation_latex, derivation_text

    system = load_system(model, set_, lock)
    if routh or hamilton:
        if routh and hamilton:
            raise InputError("--routh and --hamilton are two derivations; give one",
                             field="--routh")
        if format is Format.latex or standalone:
            raise InputError("--routh and --hamilton print text or JSON", field="--format")
        _routh_or_hamilton(system, routh, hamilton, json_ or format is Format.json, expand)
        return
    eom = system.equations_of_motion()
    warn_if_unphysical(eom)
    if json_ and format is Format.latex:
        raise InputError("--json and --format latex ask for two formats; give one", field="--format")
    if standalone and (json_ or format is not Format.latex):
        raise InputError("--standalone writes a LaTeX document; give it with --format latex",
                         field="--standalone")
    working = eom.steps() if steps or steps_full else None
    if json_ or format is Format.json:
        document = derivation_document(eom, expand=expand)
        if working is not None:
            from ..output.steps import steps_document

            document["steps"] = steps_document(working)
            found = _conserved(system)
            if found is not None:
                from ..output.conserved import conserved_document

                # part of the working: derive's own keys stay as without --steps
                document["steps"]["conserved"] = conserved_document(found, eom.model)["conserved"]
        print_json(document)
    elif format is Format.latex:
        latex = derivation_latex(eom, standalone=standalone, expand=expand)
        if working is not None:
            from ..output.steps import steps_latex

            end = "\\end{document}"
            working_latex = steps_latex(working, full=steps_full)
            latex = (latex.replace(end, working_latex + end) if standalone and end in latex
                     else latex + working_latex)
        typer.echo(latex, nl=False)
    else:
        typer.echo(derivation_text(eom, expand=expand), nl=False)
        if working is not None:
            from ..output.steps import steps_text

            typer.echo("\n" + steps_text(working, full=steps_full), nl=False)
            found = _conserved(system)
            if found is not None:
                from ..output.conserved import conserved_lines

                typer.echo("\nConserved (lagrangian conserved MODEL):\n"
                           + "\n".join(conserved_lines(found, eom.model)))


def _conserved(system):
    """The conserved quantities for --steps: a small model's only (the search is cheap there)."""
    if system.runs_on_tree or len(system.coordinates) > 6:
        return None
    return system.conserved()


def _routh_or_hamilton(system, routh: list[str], hamilton: bool, json_: bool,
                       expand: bool) -> None:
    from ..output.conserved import (
        hamiltonian_document,
        hamiltonian_text,
        routhian_document,
        routhian_text,
    )
    from ..output.derivation import derivation_document, derivation_text

    if hamilton:
        found = system.hamiltonian()
        if json_:
            print_json(hamiltonian_document(found))
        else:
            typer.echo(hamiltonian_text(found), nl=False)
        return
    names = [n.strip() for item in routh for n in item.split(",") if n.strip()]
    reduced = system.routhian(*names)
    eom = reduced.equations_of_motion()
    if json_:
        document = derivation_document(eom, expand=expand)
        document["routhian"] = routhian_document(reduced.model)
        print_json(document)
    else:
        typer.echo(routhian_text(reduced.model) + "\n" + derivation_text(eom, expand=expand),
                   nl=False)
