"""The chunk store of a resumable study: ``DIR/chunk-NNNNN.parquet`` files beside
``DIR/manifest.json``, each chunk written atomically with its request's fingerprint and a
checksum of its content."""

from __future__ import annotations

import hashlib
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from thermojitter import checkpoint as checkpoints
from thermojitter.montecarlo.metrics import (
    METRICS,
)

FORMAT_VERSION = 1
"""The version of the chunk store's settings (its manifest and fingerprint)."""


def chunk_path(directory: Path, k: int) -> Path:
    return directory / f"chunk-{k:05d}.parquet"


_CHUNK_REQUEST = b"thermojitter.request"
_CHUNK_CHECKSUM = b"thermojitter.checksum"


def _chunk_digest(columns: dict[str, Any]) -> str:
    """SHA-256 over a chunk's columns (names, values to the bit, error strings)."""
    h = hashlib.sha256()
    for name in sorted(columns):
        h.update(name.encode() + b"\0")
        value = columns[name]
        if name == "error":
            h.update(checkpoints.canonical(list(value)))
        else:
            h.update(np.ascontiguousarray(np.asarray(value, dtype=float)).tobytes())
    return h.hexdigest()


def write_chunk(directory: Path, k: int, start: int, metrics: dict[str, Any], request: str) -> bool:
    """Writes chunk ``k`` atomically, with the request's fingerprint and a checksum of its
    content in the Parquet metadata. On failure (a full disk, say) warns and returns False: the
    chunk stays in memory and in the result, and no partial file is left."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    n = len(metrics["error"])
    columns: dict[str, Any] = {"sample": np.arange(start, start + n, dtype=np.int64)}
    for m in METRICS:
        columns[m] = metrics[m]
    meta = {_CHUNK_REQUEST: request.encode(), _CHUNK_CHECKSUM: _chunk_digest(columns).encode()}
    columns["error"] = pa.array(metrics["error"], type=pa.string())
    table = pa.table(columns).replace_schema_metadata(meta)
    path = chunk_path(directory, k)
    try:
        checkpoints.write_atomic(path, lambda fh: pq.write_table(table, fh))
    except OSError as exc:
        warnings.warn(
            f"checkpoint chunk {path} could not be written ({exc.strerror or exc}); its samples "
            "are kept in memory and returned",
            RuntimeWarning,
            stacklevel=2,
        )
        return False
    return True


def read_chunk(
    directory: Path, k: int, start: int, stop: int, request: str
) -> dict[str, Any] | None:
    """Chunk ``k`` if it is intact and was written for ``request``; None if absent. A damaged,
    edited or foreign chunk is refused naming the file."""
    import pyarrow.parquet as pq

    path = chunk_path(directory, k)
    if not path.exists():
        return None
    try:
        table = pq.read_table(path)
        meta = table.schema.metadata or {}
        columns: dict[str, Any] = {"sample": table.column("sample").to_numpy()}
        for m in METRICS:
            if m == "error":
                columns[m] = table.column(m).to_pylist()
            else:
                columns[m] = table.column(m).to_numpy()
    except Exception:  # pyarrow raises several kinds on a damaged file
        raise checkpoints.CheckpointError(
            "checkpoint", path, "is damaged (not a readable chunk)"
        ) from None
    if meta.get(_CHUNK_REQUEST) != request.encode():
        raise checkpoints.CheckpointError(
            "checkpoint", path, "was written for another request (seed, n, design or settings)"
        )
    if meta.get(_CHUNK_CHECKSUM) != _chunk_digest(columns).encode():
        raise checkpoints.CheckpointError(
            "checkpoint", path, "is damaged or was edited (its checksum does not match)"
        )
    if not np.array_equal(columns["sample"], np.arange(start, stop)):
        raise checkpoints.CheckpointError(
            "checkpoint", path, f"does not hold samples {start}..{stop - 1}"
        )
    del columns["sample"]
    return columns


def open_checkpoint(directory: Path, settings: dict[str, Any], n: int, chunk_size: int) -> int:
    """Creates or checks the manifest; returns the chunk size the directory was started with.
    Without a manifest, chunks already in the folder are still checked one by one against the
    request's fingerprint when they are read."""
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise checkpoints.CheckpointError(
            "checkpoint", directory, f"cannot be created ({exc.strerror or exc})"
        ) from None
    manifest = directory / "manifest.json"
    saved = checkpoints.load(manifest, settings)
    if saved is not None:
        size = saved.get("chunk_size")
        if not isinstance(size, int) or size < 1:
            raise checkpoints.CheckpointError("checkpoint", manifest, "has no valid chunk_size")
        return size
    try:
        checkpoints.save(manifest, settings, {"n": n, "chunk_size": chunk_size})
    except OSError as exc:
        warnings.warn(
            f"checkpoint {manifest} could not be written ({exc.strerror or exc}); the run goes "
            "on and returns its result",
            RuntimeWarning,
            stacklevel=3,
        )
    return chunk_size
