"""The numeric sections of the report page (report/page.py): equilibria and their stability,
modes (numbers, shapes and each mode drawn moving), a simulation (plot and animation), the
units check and the check of a hand derivation. Each returns (body, status); a section that does
not apply returns one line saying why.
"""

from __future__ import annotations

from ..errors import LagrangianError
from ..kinds import FindingStatus
from .expected import expected_markup
from .html import Markup, element, image, join, note, number, paragraph, table
from .media import (
    MODE_CYCLE,
    MODES_ANIMATED,
    NOTHING_TO_DRAW,
    coordinate_mode_gif,
    data_uri,
    drawable,
    figure_png,
    mode_gif,
    simulation_gif,
)
from .outline import SHOWN


def _where(values: dict[str, float], units: dict[str, str]) -> str:
    return ", ".join(f"{name} = {number(v)} {units.get(name, '')}".rstrip()
                     for name, v in values.items())


def _units(c) -> dict[str, str]:
    return {co.name: co.unit or "" for co in c.model.coordinates}


def equilibria_section(c) -> tuple[Markup, str]:
    found = c.system.equilibria()
    units = _units(c)
    if not len(found) and not found.singular:
        return note("No equilibrium found: at none of the configurations searched do the forces "
                    "at rest balance."), "not applicable: none found"
    header = ["#", *found.coordinates, "stability"]
    if found.constraints:
        header[-1:-1] = [f"λ {name}" for name in found.constraints]
    rows = []
    for i, e in enumerate(found, 1):
        row = [str(i), *(f"{number(e.coordinates[n])} {units.get(n, '')}".rstrip()
                         for n in found.coordinates)]
        if found.constraints:
            row += [number(e.multipliers.get(n)) for n in found.constraints]
        row.append(element("span", "stable" if e.stable else "unstable",
                           class_="good" if e.stable else "bad"))
        rows.append(row)
    parts = [table(header, rows)]
    neutral = found[0].neutral if len(found) else ()
    if neutral:
        parts.append(note(f"Any value of {', '.join(neutral)} is also an equilibrium (the "
                          "equations at rest do not contain it); the initial value is shown."))
    if found.singular:
        parts.append(note("Also at rest where a rotation sequence is singular (gimbal lock): "
                          + "; ".join(_where(p, units) for p in found.singular)))
    return join(parts), SHOWN


def modes_section(c) -> tuple[Markup, str]:
    from ..output.modes import mode_shape_figure

    analysis = c.system.modes()
    if not len(analysis):
        return note("No modes: the linear model has no degree of freedom."), \
            "not applicable: no modes"
    units = _units(c)
    names = list(analysis.linear_model.user_coordinates)
    about = _where(analysis.equilibrium, units) or "the equilibrium"
    parts = [paragraph(f"About {about}: the system is "
                       f"{'stable' if analysis.stable else 'unstable'} there.")]
    header = ["mode", "ω (rad/s)", "f (Hz)", "ζ", "growth (1/s)", "kind",
              *(f"shape: {n}" for n in names)]
    rows = [[str(i), number(m.frequency), number(m.frequency_hz),
             # a real eigenvalue has no damping ratio (as `modes` prints it): "–"
             "–" if m.damping_ratio is None or m.frequency == 0 else number(m.damping_ratio, 4),
             number(m.growth_rate, 4), m.kind,
             *(number(m.shape.get(n), 4) for n in names)]
            for i, m in enumerate(analysis, 1)]
    parts.append(table(header, rows))
    parts.append(element("h3", "Mode shapes"))
    parts.append(element("figure", image(data_uri(figure_png(mode_shape_figure(analysis)),
                                                  "image/png"), "mode shapes, one panel each")))
    parts.append(element("h3", "Each mode, moving"))
    parts.append(_mode_animations(c, analysis))
    return join(parts), SHOWN


def _mode_animations(c, analysis) -> Markup:
    """A looping GIF of the mechanism in each of the lowest oscillating modes."""
    drawn = drawable(c.model)
    figures = []
    for i, mode in enumerate(analysis.modes[:MODES_ANIMATED], 1):
        if mode.frequency <= 0:
            figures.append(element("figure", note(f"Mode {i} is {mode.kind}: it does not "
                                                  "oscillate, so there is no motion to show.")))
            continue
        try:
            gif = mode_gif(c.model, analysis, mode, i, size=c.size, fps=c.fps) if drawn \
                else coordinate_mode_gif(analysis, mode, i, _units(c), size=c.size, fps=c.fps)
        except LagrangianError as exc:
            figures.append(note(f"Mode {i}: no animation ({exc})."))
            continue
        caption = (f"Mode {i}: {number(mode.frequency, 4)} rad/s, period "
                   f"{number(mode.period, 4)} s, played in {MODE_CYCLE:g} s; "
                   + ("amplitude exaggerated, " if drawn else "")
                   + "growth or decay left out.")
        figures.append(element("figure", image(data_uri(gif, "image/gif"),
                                               f"the mechanism moving in mode {i}",
                                               class_="animation"),
                               element("figcaption", caption)))
    if len(analysis) > MODES_ANIMATED:
        figures.append(note(f"The {len(analysis) - MODES_ANIMATED} higher modes are not drawn."))
    gallery = element("div", *figures, class_="gallery")
    if drawn:
        return gallery
    return join([note(f"{NOTHING_TO_DRAW} Each mode is shown as its coordinates moving, each "
                      "on its own track."), gallery])


REPORTED_IMPACTS = 10  # impacts listed on the page


def simulation_section(c, t_end: float) -> tuple[Markup, str]:
    from ..output.plots import time_history_figure

    simulation = c.system.simulate(t_end)
    parts = [paragraph(f"From the model's initial values to t = {number(simulation.t[-1])} s "
                       f"({simulation.method}, rtol {simulation.rtol:g}, atol {simulation.atol:g}): "
                       f"{simulation.message}.")]
    figure = time_history_figure(simulation, _units(c))
    parts.append(element("figure", image(data_uri(figure_png(figure), "image/png"),
                                         "the coordinates and the energy over time")))
    if simulation.impacts:  # a run through the model's impacts: the first ones, by number
        shown = simulation.impacts[:REPORTED_IMPACTS]
        parts.append(table(["t (s)", "impact", "impulse (N s)", "kinetic energy lost (J)"],
                           [(number(r.time), r.name, ", ".join(number(x) for x in r.impulse),
                             number(r.energy_lost)) for r in shown]))
        more = len(simulation.impacts) - len(shown)
        if more:
            parts.append(note(f"... and {more} more impacts (simulate --json lists them)."))
    if drawable(c.model):
        gif = simulation_gif(simulation, size=c.size, fps=c.fps)
        parts.append(element("figure", image(data_uri(gif, "image/gif"), "the simulated motion",
                                             class_="animation"),
                             element("figcaption", "The simulated motion, looping.")))
    else:
        parts.append(note(f"{NOTHING_TO_DRAW} The plot above shows its coordinates over time."))
    return join(parts), SHOWN


def units_section(c) -> tuple[Markup, str]:
    report = c.system.check_units()
    parts = []
    if report.consistent:
        parts.append(paragraph(element("span", "Consistent", class_="good"),
                               ": every term of T and V is in J, D in W and each Q in J per "
                               "unit of its coordinate."))
    else:
        parts.append(paragraph(element("span", f"{len(report.issues)} inconsistent term(s)",
                                       class_="bad")))
        parts.append(table(["item", "term", "what is wrong"],
                           [(i.item, i.term, i.message) for i in report.issues]))
    if report.unchecked:
        parts.append(note("Parameters without a unit are not judged: "
                          + ", ".join(report.unchecked)))
    return join(parts), SHOWN


def check_section(c, report) -> tuple[Markup, str]:
    if report is None:
        return note("No answer given: `lagrangian report MODEL --answer ANSWER.toml` (or "
                    "System.report(answer=...)) checks a hand derivation here."), \
            "not applicable: no answer"
    good, bad = (FindingStatus.CORRECT, FindingStatus.EQUIVALENT), FindingStatus.WRONG
    rows = [(f.item, element("span", f.status, class_="good" if f.status in good
                             else "bad" if f.status == bad else None),
             f.code or "", f.message, "" if f.expected is None or f.status == FindingStatus.CORRECT
             else expected_markup(c.write, c.model, f.expected)) for f in report.findings]
    verdict = element("span", report.verdict, class_="good" if report.passed else "bad")
    parts = [paragraph(f"{report.answer} against {report.model}: ", verdict)]
    if rows:
        parts.append(table(["item", "status", "code", "finding", "expected"], rows))
    else:
        parts.append(note("The answer has no items to check."))
    return join(parts), SHOWN
