"""The machine a benchmark runs on, printed first by every script here so that figures from
different machines are never compared blind: the processor, the instruction sets it has, those
the build uses everywhere (baseline x86-64 for the wheels) and the scalar and ensemble kernels
chosen at run time, the cores and their load, and the Python."""

from __future__ import annotations

import os
import platform

import thermojitter as tj


def load() -> str:
    """The load average over 1, 5 and 15 minutes, for a line printed again at a run's end."""
    return " ".join(f"{x:.2f}" for x in os.getloadavg()) if hasattr(os, "getloadavg") else "n/a"


def describe() -> str:
    """Two lines: the CPU and instruction sets (from the engine), then cores, load and Python."""
    return (
        f"{tj._core.cpu_info()['summary']}\n"
        f"{os.cpu_count()} cores, load average {load()}, Python {platform.python_version()} "
        f"on {platform.system()} {platform.machine()}"
    )


if __name__ == "__main__":
    print(describe())
