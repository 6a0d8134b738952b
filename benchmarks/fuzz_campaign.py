"""Fuzzing campaign (issue 14): 10^5 generated and mutated inputs through the reader, derive
and the JSON output, with counts.

    python benchmarks/fuzz_campaign.py [--inputs 100000] [--minutes 20] [--json report.json]

Inputs are drawn at random (unlike the test suite's fixed CI budget, tests/fuzz): expressions,
numbers, unit strings and values with units, whole model files (from the grammar and mutated
built-in examples) and answer files read, and model files derived to JSON through the CLI.
Each must be accepted, or refused with the project's own one-line error; a refusal should take
under 1 s. Reports
inputs tried, accepted, refusals by kind, failures (tracebacks, time-outs) with their input,
the slowest refusal and the refusals over 1 s (each timed twice: a pause of the machine is not
a slow refusal).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "fuzz"))

from fuzz_inputs import (  # noqa: E402
    EXAMPLE_TEXTS,
    Tally,
    answer_files,
    derive_json,
    expressions,
    model_files,
    number_texts,
    quantities,
    read_answer_text,
    read_expression,
    read_model_text,
    run_input,
    unit_strings,
)
from hypothesis import HealthCheck, Phase, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from lagrangian.model.units import check_unit, parse_quantity, registry  # noqa: E402

# share of the inputs per target, and each input's time limit (a hang, not a slow refusal)
TARGETS = {
    "expression": (0.40, 10.0),
    "number": (0.05, 10.0),
    "unit": (0.05, 10.0),
    "quantity": (0.05, 10.0),
    "answer file (read)": (0.05, 20.0),
    "model file (read)": (0.30, 20.0),
    "model file (derive --format json)": (0.10, 60.0),
}
SLOW_REFUSAL = 1.0


class _Stop(Exception):
    pass


def campaign(inputs: int, minutes: float, progress: bool = True) -> dict:
    folder = Path(tempfile.mkdtemp(prefix="lagrangian-fuzz-"))
    # one-time set-up (pint's registry, sympy's caches: seconds on a busy machine) is not an
    # input's time
    registry()
    derive_json(EXAMPLE_TEXTS["double_pendulum"], folder)
    tallies = {target: Tally() for target in TARGETS}
    slow: list[tuple[float, str, str]] = []
    retimed: list[float] = []  # refusals over 1 s that took under 1 s when run again
    deadline = time.monotonic() + 60 * minutes
    started = time.monotonic()

    def runner(target: str, text: str):
        if target == "expression" or target == "number":
            return lambda: read_expression(text)
        if target == "unit":
            return lambda: check_unit(text, "unit", "fuzz.toml")
        if target == "quantity":
            return lambda: parse_quantity(text, "m", "--set x")
        if target == "model file (read)":
            return lambda: read_model_text(text)
        if target == "answer file (read)":
            return lambda: read_answer_text(text)
        return lambda: derive_json(text, folder)

    strategies = {
        "expression": expressions(), "number": number_texts(), "unit": unit_strings(),
        "quantity": quantities(), "model file (read)": model_files(),
        "answer file (read)": answer_files(),
        "model file (derive --format json)": model_files(),
    }
    # each target repeated by its weight: a uniform pick among 100 (hypothesis favours small
    # integers, so an integer draw would skew the shares)
    shares = [name for name, (weight, _) in TARGETS.items() for _ in range(round(100 * weight))]

    @settings(max_examples=inputs, phases=[Phase.generate], database=None, deadline=None,
              suppress_health_check=list(HealthCheck))
    @given(st.data())
    def one(data):
        if time.monotonic() > deadline:
            raise _Stop
        target = data.draw(st.sampled_from(shares))
        text = data.draw(strategies[target])
        outcome = run_input(runner(target, text), TARGETS[target][1])
        tallies[target].add(target, text, outcome)
        if not outcome.ok and progress:
            print(f"FAILURE {target}: {outcome.status} {outcome.kind} {outcome.message[:300]} "
                  f"on {text[:1000]!r}", file=sys.stderr, flush=True)
        if outcome.status == "refused" and outcome.seconds > SLOW_REFUSAL:
            # timed again at once: a pause of the machine (other work, garbage collection) is
            # not a slow refusal
            again = run_input(runner(target, text), TARGETS[target][1])
            if again.seconds > SLOW_REFUSAL:
                slow.append((min(outcome.seconds, again.seconds), f"{target}: {text[:200]}",
                             outcome.message[:200]))
            else:
                retimed.append(outcome.seconds)
        total = sum(t.tried for t in tallies.values())
        if progress and total % 1000 == 0:
            failures = sum(len(t.failures) for t in tallies.values())
            print(f"{total} inputs, {failures} failures, {time.monotonic() - started:.0f} s",
                  file=sys.stderr, flush=True)

    try:
        one()
    except KeyboardInterrupt:
        pass  # report what was tried
    except BaseException:  # noqa: BLE001
        # past the time limit hypothesis replays the stopping input and calls it flaky; the
        # counts are complete all the same
        if time.monotonic() <= deadline:
            raise
    return _report(tallies, slow, retimed, time.monotonic() - started)


def _report(tallies: dict[str, Tally], slow, retimed, seconds: float) -> dict:
    refusals: dict[str, int] = {}
    for tally in tallies.values():
        for kind, count in tally.refusals.items():
            refusals[kind] = refusals.get(kind, 0) + count
    slowest = max((t.slowest_refusal for t in tallies.values()), key=lambda s: s[0])
    slowest_accept = max((t.slowest_accept for t in tallies.values()), key=lambda s: s[0])
    return {
        "seconds": round(seconds, 1),
        "tried": sum(t.tried for t in tallies.values()),
        "accepted": sum(t.accepted for t in tallies.values()),
        "refused": sum(refusals.values()),
        "failures": sum(len(t.failures) for t in tallies.values()),
        "by_target": {name: {"tried": t.tried, "accepted": t.accepted,
                             "refused": sum(t.refusals.values()), "failures": len(t.failures)}
                      for name, t in tallies.items()},
        "refusals_by_kind": dict(sorted(refusals.items(), key=lambda kv: -kv[1])),
        "slowest_refusal": {"seconds": round(slowest[0], 3), "input": slowest[1],
                            "message": slowest[2]},
        "slowest_accept": {"seconds": round(slowest_accept[0], 3), "input": slowest_accept[1]},
        "refusals_over_1s": [{"seconds": round(s, 3), "input": i, "message": m}
                             for s, i, m in sorted(slow, reverse=True)[:20]],
        "refusals_over_1s_only_once": {"count": len(retimed),
                                       "max_seconds": round(max(retimed, default=0.0), 3)},
        "failure_examples": [{"target": target, "input": text[:2000], "what": what[:500]}
                             for tally in tallies.values()
                             for target, text, what in tally.failures[:10]],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--inputs", type=int, default=100_000)
    parser.add_argument("--minutes", type=float, default=60.0, help="stop after this long")
    parser.add_argument("--json", type=Path, help="write the report here too")
    args = parser.parse_args()
    report = campaign(args.inputs, args.minutes)
    text = json.dumps(report, indent=2, ensure_ascii=False)
    print(text)
    if args.json:
        args.json.write_text(text + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
