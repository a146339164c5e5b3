"""Whether the engine's speed depends on where its call lands on the stack.

The same call, ``tj.simulate`` of the paper's orbit over one orbit, timed three ways in one run:

- through the public path from the main thread (the engine's worker thread runs it);
- in place from a thread of this script, under each of several stacks of C frames (builtins
  that call back into Python: ``map``, ``filter``, ``sorted``, ``itertools.starmap``), which
  move the engine's frames by different amounts;
- the spread of the in-place timings, and the public path's ratio to their median.

A build whose step loop is sensitive to its frame's place in a cache line shows it here as a
spread of several per cent between depths, or as a public-path ratio above that of a build known
to be insensitive. The public path's ratio is above 1 even then: its results, made in the
worker thread, are freed in the main thread, and the allocator then hands the next call memory
it must fault in again (~3700 pages a call here, where a call in place faults ~70). Thread CPU
time of each call (the process's for the public path, whose main thread only waits), median of
``--repeat``.

    python benches/stack_layout.py [--repeat 7]
"""

from __future__ import annotations

import argparse
import functools
import itertools
import statistics
import threading
import time
from collections.abc import Callable

import machine  # benches/machine.py

import thermojitter as tj

WRAPPERS: dict[str, Callable[[Callable[[], object]], object]] = {
    "map": lambda g: list(map(lambda _: g(), [0])),
    "filter": lambda g: list(filter(lambda _: g() is not None, [0])),
    "sorted": lambda g: sorted([0], key=lambda _: id(g())),
    "starmap": lambda g: list(itertools.starmap(lambda: g(), [()])),
}


def stacks() -> list[tuple[str, ...]]:
    """No wrapper, each wrapper alone, and the pairs of wrappers."""
    names = list(WRAPPERS)
    return [(), *((n,) for n in names), *itertools.combinations_with_replacement(names, 2)]


def median_ms(call: Callable[[], object], repeat: int, clock: Callable[[], float]) -> float:
    call()
    times = []
    for _ in range(repeat):
        start = clock()
        call()
        times.append(clock() - start)
    return 1e3 * statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    print(machine.describe())

    panel, orbit = tj.Panel.paper(), tj.Orbit.geo_equinox()

    def run() -> object:
        return tj.simulate(panel, orbit, (0.0, orbit.period))

    # The main thread waits while the worker runs: the process's CPU time is the worker's.
    public = median_ms(run, args.repeat, time.process_time)
    in_place: dict[str, float] = {}

    def in_thread() -> None:
        for stack in stacks():
            call: Callable[[], object] = run
            for name in stack:
                call = functools.partial(WRAPPERS[name], call)
            in_place["+".join(stack) or "none"] = median_ms(call, args.repeat, time.thread_time)

    worker = threading.Thread(target=in_thread)
    worker.start()
    worker.join()

    values = list(in_place.values())
    middle = statistics.median(values)
    print(f"\ntj.simulate of the paper's orbit, one orbit, median of {args.repeat} (thread CPU)")
    print(f"  public path (engine worker thread)   {public:7.1f} ms   {public / middle:5.2f} x")
    print(f"  in place, median of {len(values):2d} stacks        {middle:7.1f} ms   1.00 x")
    print(
        f"  in place, fastest .. slowest          {min(values):7.1f} .. {max(values):.1f} ms"
        f"   spread {(max(values) - min(values)) / middle:.1%}"
    )
    for name, value in in_place.items():
        print(f"    {name:18s} {value:7.1f} ms")
    print(f"\nload average at the end: {machine.load()}")


if __name__ == "__main__":
    main()
