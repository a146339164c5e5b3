"""Monte Carlo on a real Dask cluster: a ``dask scheduler`` and two ``dask worker`` processes on
127.0.0.1, started here on free ports and always torn down. The frame must be the local one, bit
for bit, even when a worker is killed midway."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

import thermojitter as tj

pd = pytest.importorskip("pandas")
distributed = pytest.importorskip("distributed")

LOW = tj.Orbit(radius=7.0e6, period=5828.5)
VARY = {"damping": ("uniform", 1.0, 4.0), "emissivity_back": ("normal", 0.3, 0.03)}
COMMON: dict[str, Any] = {
    "vary": VARY, "n": 16, "seed": 5, "horizon": 4, "rtol": 1e-6, "atol": 1e-8,
    "progress": False,
}  # fmt: skip
START_TIMEOUT = 90.0


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def dask(*args: str) -> subprocess.Popen[bytes]:
    """``dask ARGS`` with this interpreter, in a process group of its own (torn down whole)."""
    return subprocess.Popen(
        [sys.executable, "-m", "dask", *args],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )


def stop(proc: subprocess.Popen[bytes]) -> None:
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(timeout=10)


class Cluster:
    def __init__(self) -> None:
        self.port = free_port()
        self.address = f"tcp://127.0.0.1:{self.port}"
        self.scheduler = dask(
            "scheduler", "--host", "127.0.0.1", "--port", str(self.port), "--no-dashboard"
        )
        self.workers: list[subprocess.Popen[bytes]] = []

    def start_workers(self, n: int) -> None:
        for i in range(n):
            self.workers.append(
                dask(
                    "worker",
                    self.address,
                    "--nthreads",
                    "1",
                    "--no-nanny",
                    "--no-dashboard",
                    "--name",
                    f"w{i}",
                    "--host",
                    "127.0.0.1",
                )  # fmt: skip
            )
        from distributed import Client

        with Client(self.address, timeout=START_TIMEOUT) as client:
            client.wait_for_workers(n, timeout=START_TIMEOUT)

    def close(self) -> None:
        for proc in [*self.workers, self.scheduler]:
            stop(proc)


@pytest.fixture()
def cluster() -> Iterator[Cluster]:
    c = Cluster()
    try:
        deadline = time.monotonic() + START_TIMEOUT
        while True:  # the scheduler listens
            try:
                socket.create_connection(("127.0.0.1", c.port), timeout=1.0).close()
                break
            except OSError:
                if c.scheduler.poll() is not None or time.monotonic() > deadline:
                    pytest.fail("the dask scheduler did not start")
                time.sleep(0.2)
        c.start_workers(2)
        yield c
    finally:
        c.close()


@pytest.fixture(scope="module")
def local_frame() -> Any:
    return tj.monte_carlo(tj.Panel.paper(), LOW, **COMMON)


def test_frame_on_a_cluster_is_the_local_one(cluster: Cluster, local_frame: Any) -> None:
    frame = tj.monte_carlo(tj.Panel.paper(), LOW, backend=cluster.address, chunk_size=3, **COMMON)
    pd.testing.assert_frame_equal(frame, local_frame, check_exact=True)


def test_a_worker_killed_midway_loses_no_sample(
    cluster: Cluster, local_frame: Any, tmp_path: Path
) -> None:
    ckpt = tmp_path / "ckpt"
    killed_after: list[int] = []

    def kill_a_worker_after_two_chunks() -> None:
        deadline = time.monotonic() + 300
        while time.monotonic() < deadline:
            done = len(list(ckpt.glob("chunk-*.parquet")))
            if done >= 2:
                cluster.workers[0].kill()  # SIGKILL, no nanny: the worker is gone
                killed_after.append(done)
                return
            time.sleep(0.01)

    killer = threading.Thread(target=kill_a_worker_after_two_chunks, daemon=True)
    killer.start()
    frame = tj.monte_carlo(
        tj.Panel.paper(), LOW, backend=cluster.address, chunk_size=1, checkpoint=ckpt, **COMMON
    )
    killer.join(timeout=10)
    assert killed_after and killed_after[0] < COMMON["n"], "the worker was not killed midway"
    assert cluster.workers[0].wait(timeout=10) != 0
    pd.testing.assert_frame_equal(frame, local_frame, check_exact=True)
