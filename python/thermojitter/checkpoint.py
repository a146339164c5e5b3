"""Checkpoint files of long runs and Monte Carlo: written atomically, trusted only when intact.

A checkpoint holds the request it answers (every setting of the run: panel, orbit, solver,
``n_orbits`` or ``n`` and seed, chunking) and a SHA-256 checksum over that request and its content.
Reading one checks both: a truncated, bit-flipped or edited file, or one written for another
request, is refused with a :class:`CheckpointError` naming the file and what differs. It is
never merged into a run, nor returned.

Every file is written to a temporary name in the same folder, flushed to disk, given the
permissions the umask allows (as any new file), then renamed over the old one, so a killed or
failed writer leaves either the previous file or the new one, and no partial file: the temporary
file is removed when the write fails (a full disk, say).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any, BinaryIO

from thermojitter.errors import ParameterError

FORMAT = 2
"""Version of the checkpoint layout; a file of another version is refused."""


class CheckpointError(ParameterError):
    """A checkpoint that cannot be trusted: damaged, edited, or written for another request.
    ``parameter`` is ``"checkpoint"``, ``value`` the file, ``allowed`` the reason."""

    def __init__(
        self, parameter: str, value: Any, allowed: str | None = None, message: str | None = None
    ) -> None:
        if message is None:
            message = (
                f"checkpoint {value} {allowed}; remove it (or use another path) to start afresh"
            )
        super().__init__(parameter, value, allowed, message)


def canonical(value: Any) -> bytes:
    """The one JSON text of ``value`` that is hashed: sorted keys, no spaces, floats written
    to round-trip exactly (NaN and inf as JSON's extensions)."""
    return json.dumps(value, sort_keys=True, separators=(",", ":")).encode()


def digest(value: Any) -> str:
    """SHA-256 of :func:`canonical` ``value``."""
    return hashlib.sha256(canonical(value)).hexdigest()


def write_atomic(path: str | os.PathLike[str], write: Callable[[BinaryIO], object]) -> None:
    """Writes ``path`` through ``write(file)`` at a temporary name in the same folder, flushes
    it to disk and renames it over ``path``. On any failure the temporary file is removed and
    ``path`` is left as it was; the error is raised again (an ``OSError`` naming ``path``)."""
    target = Path(path)
    fd, name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    tmp = Path(name)
    try:
        with os.fdopen(fd, "wb") as fh:
            write(fh)
            fh.flush()
            os.fsync(fh.fileno())
        # mkstemp makes the file readable by its owner only: give it the permissions any new
        # file gets (0o666 less the umask), as open() would.
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, target)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            tmp.unlink()
        if isinstance(exc, OSError) and exc.filename is None:
            exc.filename = str(target)  # a failed fsync or write names no file otherwise
        raise
    _sync_folder(target.parent)


def _umask() -> int:
    """The process's umask (read from /proc where it can be, which changes nothing; else set
    and put back)."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def write_bytes_atomic(path: str | os.PathLike[str], data: bytes) -> None:
    """:func:`write_atomic` of a byte string."""
    write_atomic(path, lambda fh: fh.write(data))


def _sync_folder(folder: Path) -> None:
    """Makes the rename durable (where the platform can open a folder)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def save(path: str | os.PathLike[str], request: dict[str, Any], content: dict[str, Any]) -> None:
    """Writes a JSON checkpoint of ``content`` answering ``request``, atomically."""
    body = {"format": FORMAT, "request": request, "content": content}
    record = {**body, "checksum": digest(body)}
    write_bytes_atomic(path, json.dumps(record).encode())


def load(path: str | os.PathLike[str], request: dict[str, Any]) -> dict[str, Any] | None:
    """The content of the checkpoint at ``path`` if it is intact and answers ``request``;
    None if there is no file. Anything else raises :class:`CheckpointError`."""
    where = Path(path)
    try:
        raw = where.read_bytes()
    except FileNotFoundError:
        return None
    except OSError as exc:
        raise CheckpointError("checkpoint", where, f"cannot be read ({exc.strerror})") from None
    try:
        record = json.loads(raw)
    except (ValueError, UnicodeDecodeError):
        raise CheckpointError(
            "checkpoint", where, "is damaged (truncated or not valid JSON)"
        ) from None
    if not isinstance(record, dict) or not {"format", "request", "content", "checksum"} <= set(
        record
    ):
        raise CheckpointError("checkpoint", where, "is not a thermojitter checkpoint")
    if record["format"] != FORMAT:
        raise CheckpointError(
            "checkpoint", where, f"has format {record['format']!r}; this version reads {FORMAT}"
        )
    body = {k: record[k] for k in ("format", "request", "content")}
    if record["checksum"] != digest(body):
        raise CheckpointError(
            "checkpoint", where, "is damaged or was edited (its checksum does not match)"
        )
    check_request(where, record["request"], request)
    content = record["content"]
    if not isinstance(content, dict):
        raise CheckpointError("checkpoint", where, "is not a thermojitter checkpoint")
    return content


def check_request(where: Path, saved: Any, request: dict[str, Any]) -> None:
    """Refuses ``where`` unless ``saved`` is ``request``, naming the settings that differ."""
    if digest(saved) == digest(request):
        return
    old = flatten(saved) if isinstance(saved, dict) else {}
    new = flatten(request)
    changed = sorted(
        k for k in set(old) | set(new) if canonical(old.get(k)) != canonical(new.get(k))
    )
    shown = ", ".join(f"{k}: {_brief(old.get(k))} → {_brief(new.get(k))}" for k in changed[:4])
    if len(changed) > 4:
        shown += f" and {len(changed) - 4} more"
    raise CheckpointError(
        "checkpoint", where, f"was written for another request (differs in: {shown or 'format'})"
    )


def _brief(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 24 else text[:20] + "…"


def flatten(settings: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """Nested settings as one level of dotted keys, to name what differs."""
    flat: dict[str, Any] = {}
    for key, value in settings.items():
        if isinstance(value, dict):
            flat.update(flatten(value, f"{prefix}{key}."))
        else:
            flat[prefix + str(key)] = value
    return flat
