"""Damaged, edited and foreign checkpoints of long runs and Monte Carlo are refused naming the
file (or the run is recomputed), never merged and never returned; and a full disk loses no
computed result and leaves no partial file, for simulate_orbits, monte_carlo and the command."""

from __future__ import annotations

import errno
import json
import os
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

import thermojitter as tj
from thermojitter import checkpoint
from thermojitter.checkpoint import CheckpointError
from thermojitter.cli import main as cli_main

# A low orbit and loose tolerances keep these runs short.
LOW = tj.Orbit(radius=7.0e6, period=5828.5)
PANEL = tj.Panel.paper()
FAST: dict[str, Any] = {"rtol": 1e-6, "atol": 1e-8, "progress": False}
VARY = {"damping": ("uniform", 1.0, 4.0)}
MC: dict[str, Any] = {"vary": VARY, "n": 8, "chunk_size": 4, "progress": False, **FAST}


def orbits(n: int, path: Path | None = None, **kw: Any) -> tj.OrbitSummaries:
    return tj.simulate_orbits(PANEL, LOW, n, checkpoint=path, **FAST, **kw)


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> tuple[tj.OrbitSummaries, bytes]:
    """A 3-orbit run without checkpoint, and the bytes of the checkpoint the same run writes."""
    path = tmp_path_factory.mktemp("ref") / "run.json"
    orbits(3, path)
    return orbits(3), path.read_bytes()


def same(a: tj.OrbitSummaries, b: tj.OrbitSummaries) -> None:
    pd.testing.assert_frame_equal(a.to_pandas(), b.to_pandas())
    assert np.array_equal(a.y_end, b.y_end)


def refused_naming(path: Path, call: Any, *words: str) -> None:
    with pytest.raises(CheckpointError) as info:
        call()
    assert str(path) in str(info.value)
    assert info.value.parameter == "checkpoint"
    for word in words:
        assert word in str(info.value)


# --- long runs --------------------------------------------------------------------------------


def test_intact_checkpoint_answers_the_same_request(tmp_path: Path, reference: Any) -> None:
    path = tmp_path / "run.json"
    path.write_bytes(reference[1])
    same(orbits(3, path), reference[0])


def test_truncated_checkpoint_is_refused(tmp_path: Path, reference: Any) -> None:
    path = tmp_path / "run.json"
    path.write_bytes(reference[1][: len(reference[1]) // 2])
    refused_naming(path, lambda: orbits(3, path), "damaged")


def test_bit_flipped_checkpoint_is_refused(tmp_path: Path, reference: Any) -> None:
    data = bytearray(reference[1])
    # Flip one bit of a digit of a saved summary value (still valid JSON).
    where = data.index(b'"amplitude": [') + len(b'"amplitude": [') + 3
    data[where] ^= 0x01
    path = tmp_path / "run.json"
    path.write_bytes(bytes(data))
    json.loads(path.read_text())  # still parses
    refused_naming(path, lambda: orbits(3, path), "checksum")


@pytest.mark.parametrize("edit", ["summary value", "saved state", "next_index"])
def test_edited_checkpoint_is_refused(tmp_path: Path, reference: Any, edit: str) -> None:
    record = json.loads(reference[1])
    content = record["content"]
    if edit == "summary value":
        content["columns"]["amplitude"][1] *= 2.0
    elif edit == "saved state":
        content["y"][2] = 0.1
    else:
        content["next_index"] = 2
    path = tmp_path / "run.json"
    path.write_text(json.dumps(record))
    refused_naming(path, lambda: orbits(3, path), "checksum")


def test_another_request_is_refused_naming_what_differs(tmp_path: Path, reference: Any) -> None:
    path = tmp_path / "run.json"
    path.write_bytes(reference[1])
    refused_naming(
        path,
        lambda: tj.simulate_orbits(PANEL.replace(damping=2.0), LOW, 3, checkpoint=path, **FAST),
        "panel.damping: 3.0 → 2.0",
    )


def test_fewer_orbits_than_saved_is_refused(tmp_path: Path, reference: Any) -> None:
    path = tmp_path / "run.json"
    path.write_bytes(reference[1])
    refused_naming(path, lambda: orbits(2, path), "n_orbits = 3")


def test_more_orbits_than_saved_extends_to_the_same_result(tmp_path: Path, reference: Any) -> None:
    path = tmp_path / "run.json"
    path.write_bytes(reference[1])
    extended = orbits(5, path)
    same(extended, orbits(5))


def test_checkpoint_holds_the_whole_request() -> None:
    record = json.loads(json.dumps({"x": 1}))
    assert checkpoint.digest(record) == checkpoint.digest({"x": 1})
    assert checkpoint.digest({"x": 1.0}) != checkpoint.digest({"x": 1.0000000000000002})


# --- Monte Carlo ------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def mc_reference(tmp_path_factory: pytest.TempPathFactory) -> tuple[pd.DataFrame, Path]:
    folder = tmp_path_factory.mktemp("mc") / "ckpt"
    tj.monte_carlo(PANEL, LOW, seed=1, checkpoint=folder, **MC)
    return tj.monte_carlo(PANEL, LOW, seed=1, **MC), folder


def copy_of(folder: Path, tmp_path: Path) -> Path:
    target = tmp_path / "ckpt"
    shutil.copytree(folder, target)
    return target


def mc(seed: int, folder: Path) -> pd.DataFrame:
    return tj.monte_carlo(PANEL, LOW, seed=seed, checkpoint=folder, **MC)


def test_intact_chunks_resume_to_the_same_frame(tmp_path: Path, mc_reference: Any) -> None:
    folder = copy_of(mc_reference[1], tmp_path)
    pd.testing.assert_frame_equal(mc(1, folder), mc_reference[0])


def test_missing_manifest_with_the_same_request_resumes(tmp_path: Path, mc_reference: Any) -> None:
    folder = copy_of(mc_reference[1], tmp_path)
    (folder / "manifest.json").unlink()
    pd.testing.assert_frame_equal(mc(1, folder), mc_reference[0])


def test_missing_manifest_does_not_mix_another_seed(tmp_path: Path, mc_reference: Any) -> None:
    folder = copy_of(mc_reference[1], tmp_path)
    (folder / "manifest.json").unlink()
    refused_naming(folder / "chunk-00000.parquet", lambda: mc(2, folder), "another request")


def test_foreign_chunk_is_refused(tmp_path: Path, mc_reference: Any) -> None:
    other = tmp_path / "other"
    mc(2, other)
    folder = copy_of(mc_reference[1], tmp_path)
    shutil.copy(other / "chunk-00001.parquet", folder / "chunk-00001.parquet")
    refused_naming(folder / "chunk-00001.parquet", lambda: mc(1, folder), "another request")


def test_edited_chunk_is_refused(tmp_path: Path, mc_reference: Any) -> None:
    import pyarrow as pa
    import pyarrow.parquet as pq

    folder = copy_of(mc_reference[1], tmp_path)
    path = folder / "chunk-00000.parquet"
    table = pq.read_table(path)
    column = table.column("exit_peak").to_numpy().copy()
    column[0] *= 0.5
    edited = table.set_column(
        table.schema.get_field_index("exit_peak"), "exit_peak", pa.array(column)
    )
    pq.write_table(edited.replace_schema_metadata(table.schema.metadata), path)
    refused_naming(path, lambda: mc(1, folder), "checksum")


@pytest.mark.parametrize("damage", ["truncated", "bit-flipped"])
def test_damaged_chunk_is_refused(tmp_path: Path, mc_reference: Any, damage: str) -> None:
    folder = copy_of(mc_reference[1], tmp_path)
    path = folder / "chunk-00001.parquet"
    data = bytearray(path.read_bytes())
    if damage == "truncated":
        data = data[: len(data) // 2]
    else:
        data[len(data) // 3] ^= 0x10
    path.write_bytes(bytes(data))
    refused_naming(path, lambda: mc(1, folder))


def test_damaged_manifest_is_refused(tmp_path: Path, mc_reference: Any) -> None:
    folder = copy_of(mc_reference[1], tmp_path)
    manifest = folder / "manifest.json"
    record = json.loads(manifest.read_text())
    record["content"]["chunk_size"] = 2
    manifest.write_text(json.dumps(record))
    refused_naming(manifest, lambda: mc(1, folder), "checksum")


def test_other_n_is_refused(tmp_path: Path, mc_reference: Any) -> None:
    folder = copy_of(mc_reference[1], tmp_path)
    refused_naming(
        folder / "manifest.json",
        lambda: tj.monte_carlo(PANEL, LOW, seed=1, checkpoint=folder, **{**MC, "n": 12}),
        "n: 8 → 12",
    )


# --- a full disk ------------------------------------------------------------------------------


@pytest.fixture
def full_disk(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every atomic write fails as on a full disk, after its temporary file was created."""

    def no_space(*args: Any, **kwargs: Any) -> None:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(checkpoint.os, "fsync", no_space)


def leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.rglob("*") if p.is_file())


def test_full_disk_keeps_every_orbit(tmp_path: Path, reference: Any, full_disk: None) -> None:
    path = tmp_path / "run.json"
    with pytest.warns(RuntimeWarning, match="could not be written"):
        runs = orbits(3, path)
    same(runs, reference[0])
    assert leftovers(tmp_path) == []


def test_full_disk_keeps_every_sample(tmp_path: Path, mc_reference: Any, full_disk: None) -> None:
    folder = tmp_path / "ckpt"
    with pytest.warns(RuntimeWarning, match="could not be written"):
        frame = mc(1, folder)
    pd.testing.assert_frame_equal(frame, mc_reference[0])
    assert leftovers(tmp_path) == []


def test_full_disk_in_the_command_names_the_file_and_leaves_nothing_partial(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    scenario = tmp_path / "s.toml"
    scenario.write_text("[simulation]\nt_end = 60.0\n[output]\nplots = false\n")
    out = tmp_path / "out"
    real_fsync = checkpoint.os.fsync

    def fail_on_run_json(fd: int) -> None:
        # run.json is written after the time series: only its write fails.
        if ".run.json." in os.readlink(f"/proc/self/fd/{fd}"):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        real_fsync(fd)

    monkeypatch.setattr(checkpoint.os, "fsync", fail_on_run_json)
    code = cli_main(["run", str(scenario), "--out", str(out), "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2
    assert "run.json" in err and "No space left on device" in err
    # The time series computed before the failure is complete; nothing partial is left.
    assert leftovers(out) == ["timeseries.csv"]
    frame = pd.read_csv(out / "timeseries.csv")
    assert frame["t [s]"].iloc[-1] == 60.0


def test_report_writes_name_the_file_and_leave_nothing_partial(
    tmp_path: Path, full_disk: None
) -> None:
    # The paper command's summary.json and report.md, and the beam comparison's files, go
    # through the same atomic write: a failed one names its file and leaves no partial file.
    from thermojitter import paper

    target = tmp_path / "summary.json"
    with pytest.raises(OSError) as info:
        paper._write_json(target, {"theta_steady_deg": 4.89})
    assert info.value.filename == str(target)
    with pytest.raises(OSError) as info:
        checkpoint.write_bytes_atomic(tmp_path / "report.md", b"# report\n")
    assert info.value.filename == str(tmp_path / "report.md")
    assert leftovers(tmp_path) == []


def test_command_refuses_a_non_empty_out_unless_overwrite(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scenario = tmp_path / "s.toml"
    scenario.write_text("[simulation]\nt_end = 20.0\n[output]\nplots = false\n")
    out = tmp_path / "out"
    out.mkdir()
    (out / "earlier.csv").write_text("kept\n")
    assert cli_main(["run", str(scenario), "--out", str(out), "--no-progress"]) == 2
    assert "--overwrite" in capsys.readouterr().err
    assert leftovers(out) == ["earlier.csv"]
    assert cli_main(["run", str(scenario), "--out", str(out), "--no-progress", "--overwrite"]) == 0
    assert (out / "earlier.csv").read_text() == "kept\n"
    assert (out / "timeseries.csv").exists()


@pytest.mark.parametrize("mask", [0o022, 0o077, 0o002])
def test_written_files_honour_the_umask(tmp_path: Path, mask: int) -> None:
    """Output files get the permissions of any new file (0o666 less the umask), not the
    owner-only 0o600 of a temporary file."""
    old = os.umask(mask)
    try:
        checkpoint.write_bytes_atomic(tmp_path / "plain.bin", b"x")
        tj.steady_state(tj.Panel.paper()).save(tmp_path / "eq.nc")
        scenario = tmp_path / "s.toml"
        scenario.write_text("[simulation]\nt_end = 20.0\n")
        out = tmp_path / "out"
        assert cli_main(["run", str(scenario), "--out", str(out), "--no-progress"]) == 0
    finally:
        os.umask(old)
    written = [tmp_path / "plain.bin", tmp_path / "eq.nc", *sorted(out.iterdir())]
    assert len(written) > 4
    for path in written:
        assert path.stat().st_mode & 0o777 == 0o666 & ~mask, path.name
