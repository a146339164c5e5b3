"""Results that persist: every result saved to one self-describing file, and loaded back.

A run's result (:class:`thermojitter.Solution`, :class:`thermojitter.OrbitSummaries`,
:class:`thermojitter.DistributedSolution`, the flutter results…) is written as NetCDF-4 (HDF5,
through xarray and h5netcdf): its arrays as variables, everything else — the scalars, the run's
settings, its inputs (``result.panel`` with its layup, ``result.orbit``) — as JSON in the global
attribute ``thermojitter_fields``, beside ``thermojitter_kind`` (the class),
``thermojitter_version`` (the package's version) and ``thermojitter_format``. Floats are written
so that they read back to the bit. A study's frame (:func:`thermojitter.monte_carlo`,
:func:`thermojitter.sweep`) is a table and goes to Parquet, with its ``attrs`` and the same marks
in the file's metadata.

    sol.save("run.nc")            # any result; tj.save(frame, "mc.parquet") for a frame
    again = tj.load("run.nc")     # the same type, arrays equal to the bit
    sol.to_xarray()               # the Dataset the file holds

Files are written atomically (a temporary name in the same folder, renamed when whole), with the
permissions the umask allows.
"""

from __future__ import annotations

import dataclasses
import json
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any, ClassVar, TypeVar

import numpy as np

from thermojitter import errors as checks
from thermojitter.checkpoint import write_atomic
from thermojitter.errors import ParameterError

FORMAT = 1
"""Version of the file layout; a file of a later version is refused."""

KIND = "thermojitter_kind"
VERSION = "thermojitter_version"
FORMAT_KEY = "thermojitter_format"
FIELDS = "thermojitter_fields"
FRAME_KIND = "DataFrame"
"""The kind of a study's frame (a pandas DataFrame, written as Parquet)."""

_NETCDF_MAGIC = b"\x89HDF\r\n\x1a\n"
_PARQUET_MAGIC = b"PAR1"
_PARQUET_KEY = b"thermojitter"


class ResultFileError(ParameterError):
    """A file :func:`thermojitter.load` cannot read as the result asked for: not a thermojitter
    result, of a kind this version does not know, of a later format, or of another kind than
    the one asked. ``parameter`` is ``"path"``, ``value`` the file, ``allowed`` the reason."""

    def __init__(
        self, parameter: str, value: Any, allowed: str | None = None, message: str | None = None
    ) -> None:
        if message is None:
            message = f"{value} {allowed}"
        super().__init__(parameter, value, allowed, message)


class _Damaged(Exception):
    """A file's fields that :func:`decode` cannot read (reported as a ResultFileError)."""


_KINDS: dict[str, type[Persistent]] = {}


class Persistent:
    """What every result class shares: :meth:`to_xarray`, :meth:`save` and :meth:`load`.

    ``xarray_dims`` names the dimensions of an array field (of each array of a field holding a
    dict of arrays) where the class's own view (``_dataset``) does not already hold it."""

    xarray_dims: ClassVar[dict[str, tuple[str, ...]]] = {}

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if not cls.__name__.startswith("_"):
            _KINDS[cls.__name__] = cls

    def _dataset(self) -> Any:
        """The class's own view as an xarray Dataset (the arrays with named dimensions);
        :meth:`to_xarray` completes it with every field."""
        return _xarray().Dataset()

    def to_xarray(self) -> Any:
        """An xarray Dataset holding the whole result: its arrays over named dimensions, its
        other fields, settings and inputs (``panel``, ``orbit``) as JSON in the attribute
        ``thermojitter_fields``, and the package's version; the content of :meth:`save`'s file.
        Needs xarray."""
        return dataset(self)

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Writes the result to ``path`` (NetCDF-4; :func:`thermojitter.load` reads it back as
        the same type, every array equal to the bit). Needs xarray and h5netcdf
        (``pip install 'thermojitter[dataframes]'``). Returns the path."""
        return save(self, path)

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Any:
        """The result saved at ``path``, refused (:class:`ResultFileError`) unless it is of
        this class."""
        return load(path, kind=cls)


def _xarray() -> Any:
    try:
        import xarray as xr
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError(
            "saved results need xarray and h5netcdf: pip install 'thermojitter[dataframes]'"
        ) from exc
    return xr


# ------------------------------------------------------------------------------ JSON fields


_FIELD_TYPES: dict[str, type] = {}
"""The classes a result's JSON fields may hold, by name (nothing else is made on load)."""

_T = TypeVar("_T", bound=type)


def field_type(cls: _T) -> _T:
    """Class decorator: instances of ``cls`` may be held in a result's fields (written as JSON,
    made again on load). Each class registers itself where it is defined, so ``persist`` imports
    none of them."""
    _FIELD_TYPES[cls.__name__] = cls
    return cls


def _types() -> dict[str, type]:
    """The classes a result's JSON fields may hold, by name (those marked :func:`field_type`)."""
    return _FIELD_TYPES


def encode(value: Any) -> Any:
    """``value`` as JSON-able data that :func:`decode` turns back into an equal value of the
    same type (tuples, complex numbers, arrays and the known classes tagged)."""
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value)
    if isinstance(value, (complex, np.complexfloating)):
        return {"__complex__": [value.real, value.imag]}
    if isinstance(value, np.ndarray):
        flat = value.ravel()
        items = [encode(v) for v in flat.tolist()]
        return {"__ndarray__": items, "dtype": value.dtype.str, "shape": list(value.shape)}
    if isinstance(value, tuple) and hasattr(value, "_asdict"):  # a named tuple
        return {"__type__": type(value).__name__, "fields": encode(dict(value._asdict()))}
    if isinstance(value, tuple):
        return {"__tuple__": [encode(v) for v in value]}
    if isinstance(value, list):
        return [encode(v) for v in value]
    if isinstance(value, dict):
        if not all(isinstance(k, str) for k in value):
            return {"__items__": [[encode(k), encode(v)] for k, v in value.items()]}
        return {"__dict__": {k: encode(v) for k, v in value.items()}}
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        if type(value).__name__ not in _types():
            raise checks.InternalError(f"a result holds a {type(value).__name__}, not savable")
        record = {
            "__type__": type(value).__name__,
            "fields": encode(
                {f.name: getattr(value, f.name) for f in dataclasses.fields(value) if f.init}
            ),
        }
        layup = getattr(value, "layup", None) if type(value).__name__ == "Panel" else None
        if layup is not None:
            record["layup"] = encode(layup)
        return record
    raise checks.InternalError(f"a result holds a {type(value).__name__}, not savable")


def decode(data: Any) -> Any:
    """The value :func:`encode` wrote."""
    if isinstance(data, list):
        return [decode(v) for v in data]
    if not isinstance(data, dict):
        return data
    if "__complex__" in data:
        re, im = data["__complex__"]
        return complex(re, im)
    if "__ndarray__" in data:
        values = [decode(v) for v in data["__ndarray__"]]
        return np.array(values, dtype=np.dtype(data["dtype"])).reshape(data["shape"])
    if "__tuple__" in data:
        return tuple(decode(v) for v in data["__tuple__"])
    if "__items__" in data:
        return {decode(k): decode(v) for k, v in data["__items__"]}
    if "__dict__" in data:
        return {k: decode(v) for k, v in data["__dict__"].items()}
    if "__type__" in data:
        cls = _types().get(data["__type__"])
        if cls is None:
            raise _Damaged(f"an unknown type {data['__type__']!r}")
        made = cls(**decode(data["fields"]))
        if "layup" in data:
            # The panel of a laminate carries the layup it was made from (Panel.from_laminate).
            object.__setattr__(made, "_layup", decode(data["layup"]))
        return made
    raise _Damaged("an untagged mapping")


# --------------------------------------------------------------------------- the Dataset


def _is_array(value: Any) -> bool:
    # Booleans go to the JSON fields: NetCDF has no boolean type.
    return isinstance(value, np.ndarray) and value.ndim >= 1 and value.dtype.kind in "iufc"


def _same(variable: Any, array: np.ndarray) -> bool:
    """``variable`` holds ``array`` to the bit (dtype, shape and bytes)."""
    values = np.asarray(variable.values)
    return (
        values.dtype == array.dtype
        and values.shape == array.shape
        and values.tobytes() == np.ascontiguousarray(array).tobytes()
    )


def _free_name(ds: Any, name: str) -> str:
    while name in ds.variables or name in ds.dims or name in (FIELDS, KIND):
        name += "_"
    return name


def _put(ds: Any, name: str, array: np.ndarray, dims: tuple[str, ...] | None) -> str:
    """The name of a variable of ``ds`` holding ``array``: one of the view's, else a new one."""
    if name in ds.variables and _same(ds.variables[name], array):
        return name
    for other, variable in ds.variables.items():
        if _same(variable, array):
            return str(other)
    name = _free_name(ds, name)
    if dims is None or len(dims) != array.ndim:
        dims = tuple(f"{name}_dim{axis}" for axis in range(array.ndim))
    ds[name] = (dims, array)
    return name


def _store(ds: Any, name: str, value: Any, dims: tuple[str, ...] | None) -> Any:
    """The JSON record of one field, its arrays put in ``ds``."""
    if _is_array(value) and value.dtype.kind == "c":
        re = _put(ds, f"{name}_real", np.ascontiguousarray(value.real), dims)
        im = _put(ds, f"{name}_imag", np.ascontiguousarray(value.imag), dims)
        return {"__complex_array__": [re, im]}
    if _is_array(value):
        return {"__array__": _put(ds, name, value, dims)}
    if isinstance(value, dict) and value and all(_is_array(v) for v in value.values()):
        names = {str(k): _store(ds, str(k), v, dims)["__array__"] for k, v in value.items()}
        return {"__arrays__": names}
    return encode(value)


def dataset(result: Persistent) -> Any:
    """``result`` as the Dataset its file holds: the class's view completed with every field."""
    from thermojitter import __version__

    ds = result._dataset().copy()
    record = {}
    for f in dataclasses.fields(result):  # type: ignore[arg-type]
        if f.init:
            value = getattr(result, f.name)
            record[f.name] = _store(ds, f.name, value, type(result).xarray_dims.get(f.name))
    for f in dataclasses.fields(result):  # type: ignore[arg-type]
        # The scalars also as plain attributes, for readers without thermojitter.
        value = getattr(result, f.name)
        if isinstance(value, (bool, np.bool_)):
            ds.attrs.setdefault(f.name, int(value))
        elif isinstance(value, (int, float, str, np.integer, np.floating)):
            ds.attrs.setdefault(f.name, value)
    ds.attrs.update(
        {
            KIND: type(result).__name__,
            VERSION: __version__,
            FORMAT_KEY: FORMAT,
            FIELDS: json.dumps(record),
        }
    )
    return ds


def _restore(ds: Any, data: Any) -> Any:
    def array(name: str) -> np.ndarray:
        return np.array(ds.variables[name].values)

    if isinstance(data, dict) and "__array__" in data:
        return array(data["__array__"])
    if isinstance(data, dict) and "__complex_array__" in data:
        re, im = data["__complex_array__"]
        return array(re) + 1j * array(im)
    if isinstance(data, dict) and "__arrays__" in data:
        return {k: array(v) for k, v in data["__arrays__"].items()}
    return decode(data)


def from_xarray(ds: Any, kind: type | None = None, where: Any = "dataset") -> Any:
    """The result a Dataset of :meth:`Persistent.to_xarray` holds (``kind``: the class it must
    be); ``where`` names it in errors."""
    name = ds.attrs.get(KIND)
    if name is None or FIELDS not in ds.attrs:
        raise ResultFileError("path", where, "is not a saved thermojitter result (no kind)")
    _check_format(where, ds.attrs.get(FORMAT_KEY), ds.attrs.get(VERSION))
    cls = _KINDS.get(str(name))
    if cls is None:
        raise ResultFileError(
            "path",
            where,
            f"holds a result of kind {name!r}, which this version of thermojitter does not know "
            f"(it reads {', '.join(sorted(_KINDS))} and study frames)",
        )
    _check_kind(where, str(name), kind)
    try:
        record = json.loads(ds.attrs[FIELDS])
        values = {field: _restore(ds, data) for field, data in record.items()}
        return cls(**values)
    except (KeyError, TypeError, ValueError, _Damaged) as exc:
        raise ResultFileError("path", where, f"is damaged ({exc})") from None


def _check_format(where: Any, fmt: Any, version: Any) -> None:
    try:
        number = int(fmt)
    except (TypeError, ValueError):
        raise ResultFileError("path", where, "is not a saved thermojitter result") from None
    if number > FORMAT:
        raise ResultFileError(
            "path",
            where,
            f"was written in file format {number} (thermojitter {version}); this version reads "
            f"format {FORMAT} and before: upgrade thermojitter",
        )


def _check_kind(where: Any, name: str, kind: type | None) -> None:
    if kind is not None and name != kind.__name__:
        raise ResultFileError("path", where, f"holds a {name}, not the {kind.__name__} asked for")


# --------------------------------------------------------------------------------- files


def _is_frame(value: Any) -> bool:
    try:
        import pandas as pd
    except ImportError:  # pragma: no cover
        return False
    return isinstance(value, pd.DataFrame)


def save(result: Any, path: str | os.PathLike[str]) -> Path:
    """Writes ``result`` to ``path``, atomically: a result as NetCDF-4 (see
    :meth:`Persistent.to_xarray`), a study's frame (a pandas DataFrame of
    :func:`thermojitter.monte_carlo` or :func:`thermojitter.sweep`) as Parquet with its ``attrs``.
    Returns the path."""
    target = checks.path("path", path)
    if _is_frame(result):
        _save_frame(result, target)
        return target
    if not isinstance(result, Persistent):
        raise checks.wrong_type(
            "result", result, "a thermojitter result or a study's frame (a pandas DataFrame)"
        )
    ds = result.to_xarray()
    _xarray()
    try:
        import h5netcdf  # noqa: F401
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError(
            "saved results need h5netcdf: pip install 'thermojitter[dataframes]'"
        ) from exc
    # No fill value: every number, NaN included, is written and read back as it is.
    encoding = {name: {"_FillValue": None} for name in ds.variables}
    data = ds.to_netcdf(engine="h5netcdf", encoding=encoding)
    write_atomic(target, lambda fh: fh.write(bytes(data)))
    return target


def _save_frame(frame: Any, target: Path) -> None:
    import pyarrow as pa
    import pyarrow.parquet as pq

    from thermojitter import __version__

    objects = [str(c) for c in frame.columns if frame[c].dtype == object]
    marks = {KIND: FRAME_KIND, VERSION: __version__, FORMAT_KEY: FORMAT, "objects": objects}
    try:
        attrs = json.dumps(frame.attrs)
    except (TypeError, ValueError) as exc:
        raise ParameterError(
            "result", "frame.attrs", message=f"the frame's attrs must be JSON data ({exc})"
        ) from None
    table = pa.Table.from_pandas(frame)
    metadata = dict(table.schema.metadata or {})
    metadata[b"PANDAS_ATTRS"] = attrs.encode()  # pandas.read_parquet restores attrs from it
    metadata[_PARQUET_KEY] = json.dumps(marks).encode()
    table = table.replace_schema_metadata(metadata)
    write_atomic(target, lambda fh: pq.write_table(table, fh))


def _load_frame(where: Path, kind: type | None) -> Any:
    import pyarrow.parquet as pq

    try:
        table = pq.read_table(where)
    except (OSError, ValueError) as exc:
        raise ResultFileError("path", where, f"cannot be read as Parquet ({exc})") from None
    metadata = table.schema.metadata or {}
    if _PARQUET_KEY not in metadata:
        raise ResultFileError("path", where, "is a Parquet file, not a saved thermojitter frame")
    marks = json.loads(metadata[_PARQUET_KEY])
    _check_format(where, marks.get(FORMAT_KEY), marks.get(VERSION))
    if kind is not None:
        raise ResultFileError(
            "path", where, f"holds a study's frame, not the {kind.__name__} asked for"
        )
    frame = table.to_pandas()
    for column in marks.get("objects", []):
        values = frame[column]
        frame[column] = values.astype(object).where(values.notna(), None)
    frame.attrs = json.loads(metadata.get(b"PANDAS_ATTRS", b"{}"))
    return frame


def _opened(where: Path, read: Callable[[], Any]) -> Any:
    try:
        return read()
    except FileNotFoundError:
        raise ResultFileError("path", where, "does not exist") from None
    except OSError as exc:
        raise ResultFileError("path", where, f"cannot be read ({exc.strerror or exc})") from None


def load(path: str | os.PathLike[str], kind: type | None = None) -> Any:
    """The result saved at ``path`` by :func:`save` (or ``result.save``), of the type it was
    saved as: every array equal to the bit, its settings and inputs (``panel``, ``orbit``) equal.
    ``kind``: the class it must be (e.g. ``tj.Solution``), else refused. A file that is not a
    saved result, of a kind or format this version does not know, raises
    :class:`ResultFileError`."""
    where = checks.path("path", path)
    if kind is not None and not (isinstance(kind, type) and issubclass(kind, Persistent)):
        raise checks.wrong_type("kind", kind, "a thermojitter result class, e.g. tj.Solution")

    def head() -> bytes:
        with open(where, "rb") as fh:
            return fh.read(8)

    magic = _opened(where, head)
    if magic.startswith(_PARQUET_MAGIC):
        return _opened(where, lambda: _load_frame(where, kind))
    if magic != _NETCDF_MAGIC:
        raise ResultFileError(
            "path", where, "is not a saved thermojitter result (neither NetCDF-4 nor Parquet)"
        )
    xr = _xarray()

    def read() -> Any:
        # The numbers as written: no CF decoding (a variable in s is not made a timedelta).
        with xr.open_dataset(where, engine="h5netcdf", decode_cf=False) as ds:
            return ds.load()

    return from_xarray(_opened(where, read), kind, where)
