"""The long run of the fuzz harness (tests/fuzzing.py): N generated hostile calls of the public API
and the scenario parser, known-invalid arguments of every public function (which must be refused
naming them: "accepted_invalid" and "wrong_name" are failures), and damaged scenario files and
long-run checkpoints, each in a worker process under a watchdog (20 s of the worker's CPU time,
or 6x that of wall time); prints the count of each outcome, the share of refusals that name the
parameter, and every failure.

    python benches/fuzz.py --n 10000
"""

from __future__ import annotations

import argparse
import collections
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

import machine  # noqa: E402  (benches/machine.py)
from fuzzing import FAILURES, OUTCOMES, Example, Runner, examples  # noqa: E402
from hypothesis import HealthCheck, given, seed, settings  # noqa: E402


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=10_000, help="number of generated calls")
    parser.add_argument("--limit", type=float, default=20.0, help="CPU time per call, s")
    parser.add_argument(
        "--wall-factor", type=float, default=6.0, help="wall time per call, in units of --limit"
    )
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--show",
        action="append",
        default=[],
        metavar="OUTCOME",
        help="also print the examples of this outcome (e.g. runtime_error); repeatable",
    )
    args = parser.parse_args()

    counts: collections.Counter[str] = collections.Counter()
    invalid: collections.Counter[str] = collections.Counter()  # the known-invalid calls alone
    by_target: dict[str, collections.Counter[str]] = collections.defaultdict(collections.Counter)
    failures: list[tuple[Example, str, str]] = []
    unnamed: list[tuple[Example, str]] = []
    shown: list[tuple[Example, str, str]] = []
    slowest: tuple[float, float, Example | None] = (0.0, 0.0, None)  # CPU s, wall s
    runner = Runner(limit=args.limit, wall_factor=args.wall_factor)
    started = time.perf_counter()

    @settings(
        max_examples=args.n,
        deadline=None,
        database=None,
        derandomize=False,
        suppress_health_check=list(HealthCheck),
    )
    @given(example=examples())
    def one(example: Example) -> None:
        nonlocal slowest
        outcome, detail = runner.run(example)
        if runner.last_cpu > slowest[0]:
            slowest = (runner.last_cpu, runner.last_wall, example)
        counts[outcome] += 1
        by_target[example.target][outcome] += 1
        if example.invalid:
            invalid["total"] += 1
            invalid[outcome] += 1
        if outcome in FAILURES:
            failures.append((example, outcome, detail))
        elif outcome == "refused_unnamed":
            unnamed.append((example, detail))
        elif outcome in args.show:
            shown.append((example, outcome, detail))
        done = sum(counts.values())
        if done % 1000 == 0:
            print(f"  {done} calls, {time.perf_counter() - started:.0f} s", file=sys.stderr)

    seed(args.seed)(one)()
    runner.close()
    total = sum(counts.values())
    refusals = counts["refused_named"] + counts["refused_unnamed"]
    print(machine.describe())
    print(f"{total} generated calls in {time.perf_counter() - started:.0f} s")
    for outcome in OUTCOMES:
        print(f"  {outcome:16s} {counts[outcome]:6d}")
    if refusals:
        print(f"refusals naming the parameter: {100.0 * counts['refused_named'] / refusals:.2f} %")
    print(
        f"known-invalid calls: {invalid['total']} (refused naming the argument: "
        f"{invalid['refused_named']}, accepted: {invalid['accepted_invalid']}, "
        f"refused naming another: {invalid['wrong_name']})"
    )
    print(f"limits per call: {runner.limit:g} s CPU, {runner.wall_limit:g} s wall")
    print(f"slowest call: {slowest[0]:.2f} s CPU, {slowest[1]:.2f} s wall ({slowest[2]})")
    print("per entry point (ok / refused / runtime error):")
    for target in sorted(by_target):
        c = by_target[target]
        print(
            f"  {target:24s} {c['ok']:5d} {c['refused_named'] + c['refused_unnamed']:5d} "
            f"{c['runtime_error']:5d}"
        )
    for example, outcome, detail in failures[:50]:
        print(f"FAILURE {outcome}: {example}: {detail}")
    for example, detail in unnamed[:50]:
        print(f"UNNAMED: {example}: {detail}")
    for example, outcome, detail in shown[:200]:
        print(f"{outcome.upper()}: {example}: {detail}")
    return 1 if failures else 0


if __name__ == "__main__":
    raise SystemExit(main())
