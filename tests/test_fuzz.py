"""The fuzz harness in CI: generated hostile calls of the public API and the scenario parser,
each in a worker process under a watchdog, give a finite result or a clear error naming the
parameter — never a crash, a hang, a panic or a silent NaN; and every known-invalid argument
(``fuzzing.SPECS``) is refused naming it. A short run (400 calls, about 10 s); benches/fuzz.py
runs 10,000 and prints the count of each outcome."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from fuzzing import FAILURES, INVALID, SPECS, Example, Runner, classify, examples
from hypothesis import HealthCheck, given, settings


@pytest.fixture(scope="module")
def runner() -> Iterator[Runner]:
    r = Runner(limit=20.0)
    yield r
    r.close()


@settings(
    max_examples=400,
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(example=examples())
def test_hostile_calls_are_refused_by_name_or_answered(runner: Runner, example: Example) -> None:
    outcome, detail = runner.run(example)
    assert outcome not in FAILURES, f"{example}: {outcome}: {detail}"
    assert outcome != "refused_unnamed", f"{example}: the refusal does not name it: {detail}"


@pytest.mark.parametrize("target", sorted(SPECS))
def test_every_known_invalid_argument_is_refused_naming_it(target: str) -> None:
    # Each invalid value of each argument, in this process: all are refused before any run.
    wrong = []
    for arg, kind in SPECS[target].items():
        for value in INVALID[kind]:
            outcome, detail = classify(Example(target, {arg: value}, invalid=True))
            if outcome != "refused_named":
                wrong.append(f"{arg}={value!r:.40}: {outcome}: {detail}")
    assert not wrong, "\n".join(wrong)
