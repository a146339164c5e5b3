"""Scenario files: one simulation described in TOML, checked key by key.

A scenario has these tables, each optional::

    [panel]        # any Panel field (SI); missing ones take the Table 1 values
    mass_per_length = 5.51

    [laminate]     # a layup: the panel is then Panel.from_laminate of it, and [panel] may
    emissivity_front = 0.8   # give only length, width, hinge_stiffness, damping,
    emissivity_back = 0.8    # solar_constant and moment_scale
    absorptivity = 0.9

    [[laminate.layers]]      # front first: a library material and its thickness, or the six
    material = "kapton"      # properties of Layer (a material's values may be overridden)
    thickness = 50e-6

    [boom]         # instead of [panel] and [laminate]: a thin-walled tube (thermojitter.Boom):
    length = 30.0  # length, radius and wall required; material = a library key; any Boom
    radius = 6.35e-3  # field (SI), and solar_inclination_deg in place of solar_inclination
    wall = 5.1e-5

    [orbit]        # preset = "geo_equinox" | "geo_year" | "leo" | "circular" | "sunlit"
    preset = "geo_equinox"   # and/or any Orbit field

    [attitude]     # kind = "sun_pointing" | "sun_tracking" (offset, rad) | "nadir" |
    kind = "sun_pointing"    # "inertial" (normal = [x, y, z])

    [simulation]   # t_start, t_end or orbits or years, model, coupled, method, rtol, atol, dt,
                   # dt_out, keep ("samples" | "orbits"), theta_limit_deg, on_limit,
                   # layers (nodes through the thickness: the N-node model)
    orbits = 1

    [output]       # format = "csv" | "parquet", plots = true
    format = "csv"

Every problem is a :class:`ScenarioError` naming the file, the key and the reason.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, fields
from datetime import date
from pathlib import Path
from typing import Any

from thermojitter import errors as checks
from thermojitter import materials
from thermojitter.attitude import Attitude
from thermojitter.boom import Boom
from thermojitter.errors import ParameterError
from thermojitter.laminate import Laminate, Layer
from thermojitter.longrun import DEFAULT_THETA_LIMIT
from thermojitter.orbit import EQUINOX_DAY, LEO_ALTITUDE, Orbit, day_of_year
from thermojitter.panel import LAYUP_FIELDS, Panel
from thermojitter.solver import ATOL, MAX_STEPS, RTOL, SolverSettings

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib


class ScenarioError(ValueError):
    """A scenario file that cannot be used: names the file, the key (dotted) and the reason."""

    def __init__(self, path: str | Path, key: str | None, reason: str) -> None:
        self.path = str(path)
        self.key = key
        self.reason = reason
        if key is None:
            message = f"{self.path}: {reason}"
        elif reason.startswith("= "):  # the engine's "name = value is invalid: ..." form
            message = f"{self.path}: {key} {reason}"
        else:
            message = f"{self.path}: {key}: {reason}"
        super().__init__(message)


ORBIT_PRESETS: dict[str, Callable[..., Orbit]] = {
    "geo_equinox": Orbit.geo_equinox,
    "geo_year": Orbit.geo_year,
    "leo": Orbit.leo,
    "circular": Orbit.circular,
    "sunlit": Orbit.sunlit,
}
SHADOWS = ("none", "cylindrical", "penumbra", "conical")
MODELS = ("nonlinear", "linear")
METHODS = ("rk45", "rk4", "hybrid")
FORMATS = ("csv", "parquet")
KEEP = ("samples", "orbits")
ON_LIMIT = ("stop", "flag")


@dataclass(frozen=True)
class SimulationSettings:
    """Time span (s) and solver options of one run."""

    t_start: float = 0.0
    t_end: float | None = None
    orbits: float | None = None
    model: str = "nonlinear"
    coupled: bool = True
    method: str | None = None
    """"rk45", "rk4" or "hybrid" (keep = "orbits" only); None: the API's default, "hybrid" with
    keep = "orbits" (as :func:`thermojitter.simulate_orbits`) and "rk45" for a time series (as
    :func:`thermojitter.simulate`)."""
    rtol: float = RTOL
    atol: float = ATOL
    dt: float | None = None
    dt_out: float = 0.5
    years: float | None = None
    """Alternative to t_end and orbits: the span in Julian years (365.25 days)."""
    keep: str = "samples"
    """"samples": the time series every dt_out; "orbits": one summary row per orbit (for runs
    of months and years; resumable from a checkpoint in the output folder)."""
    theta_limit_deg: float = math.degrees(DEFAULT_THETA_LIMIT)
    """With keep = "orbits": |θ| beyond which the hinge model is not trusted, deg."""
    on_limit: str = "stop"
    """With keep = "orbits": "stop" at the first crossing of theta_limit_deg, or "flag" it."""
    layers: int | None = None
    """Nodes through the thickness of the N-node model (one homogeneous layer for a [panel]);
    None: the two-layer model."""
    max_steps: int = MAX_STEPS
    """The run's step budget (every orbit together with keep = "orbits")."""

    def __post_init__(self) -> None:
        if self.method is None:
            object.__setattr__(self, "method", "hybrid" if self.keep == "orbits" else "rk45")

    @property
    def solver(self) -> SolverSettings:
        """The integrator settings of ``method`` (rk45 for the hybrid propagator's fallback),
        ``rtol``, ``atol`` and ``dt``, checked by the engine when a run asks for them."""
        method = "rk45" if self.method == "hybrid" else self.method
        return SolverSettings(
            method,  # type: ignore[arg-type]
            self.rtol,
            self.atol,
            self.dt,
            max_steps=self.max_steps,
        )

    def span(self, orbit: Orbit) -> tuple[float, float]:
        """(t0, t1) in s: t_end if given, else t_start + orbits · period (one orbit by default)."""
        if self.t_end is not None:
            return self.t_start, self.t_end
        return self.t_start, self.t_start + self.n_orbits(orbit) * orbit.period

    def n_orbits(self, orbit: Orbit) -> float:
        """The span in orbits (one by default)."""
        if self.t_end is not None:
            return (self.t_end - self.t_start) / orbit.period
        if self.years is not None:
            return self.years * 365.25 * 86400.0 / orbit.period
        return 1.0 if self.orbits is None else self.orbits


@dataclass(frozen=True)
class OutputSettings:
    format: str = "csv"
    plots: bool = True


@dataclass(frozen=True)
class Scenario:
    panel: Panel | Boom = field(default_factory=Panel.paper)
    """The panel, or the boom of a scenario with a [boom] table."""
    orbit: Orbit = field(default_factory=Orbit.geo_equinox)
    attitude: Attitude = field(default_factory=Attitude.sun_pointing)
    simulation: SimulationSettings = field(default_factory=SimulationSettings)
    output: OutputSettings = field(default_factory=OutputSettings)
    source: str = "<built-in>"
    extra: dict[str, dict[str, Any]] = field(default_factory=dict)
    """Tables a command adds to the format (e.g. [flutter]), checked by that command."""


def _real(path: Path, key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ScenarioError(path, key, f"must be a number, not {_toml_type(value)} {value!r}")
    try:
        number = checks.real(key, value)
    except ParameterError as exc:  # an integer too large for a float
        raise ScenarioError(path, key, str(exc.allowed)) from None
    if not math.isfinite(number):
        raise ScenarioError(path, key, f"must be finite, not {value!r}")
    return number


def _positive(path: Path, key: str, value: Any) -> float:
    number = _real(path, key, value)
    if number <= 0.0:
        raise ScenarioError(path, key, f"must be > 0, not {value!r}")
    return number


def _choice(path: Path, key: str, value: Any, allowed: tuple[str, ...]) -> str:
    if not isinstance(value, str):
        raise ScenarioError(path, key, f"must be a string, not {_toml_type(value)} {value!r}")
    if value not in allowed:
        options = ", ".join(repr(a) for a in allowed)
        raise ScenarioError(path, key, f"must be one of {options}, not {value!r}")
    return value


def _boolean(path: Path, key: str, value: Any) -> bool:
    if not isinstance(value, bool):
        raise ScenarioError(path, key, f"must be true or false, not {_toml_type(value)} {value!r}")
    return value


def _toml_type(value: Any) -> str:
    names = {bool: "a boolean", int: "an integer", float: "a float", str: "a string"}
    for kind, name in names.items():
        if type(value) is kind:
            return name
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return "an array"
    return "a " + type(value).__name__


def _reject_unknown(path: Path, section: str, table: dict[str, Any], known: set[str]) -> None:
    for key in table:
        if key not in known:
            hint = ", ".join(sorted(known))
            raise ScenarioError(path, f"{section}.{key}", f"unknown key (allowed: {hint})")


def _table(path: Path, data: dict[str, Any], name: str) -> dict[str, Any]:
    value = data.get(name, {})
    if not isinstance(value, dict):
        raise ScenarioError(path, name, f"must be a table [{name}], not {_toml_type(value)}")
    return value


def _validated(path: Path, section: str, build: Any, base: Any, values: dict[str, float]) -> Any:
    """Builds the object one key at a time (so a bad value is named), then all together."""
    for key, value in values.items():
        try:
            build(**{**base, key: value})
        except (ValueError, TypeError) as exc:
            raise _engine_error(path, section, exc, key) from None
    try:
        return build(**{**base, **values})
    except (ValueError, TypeError) as exc:
        raise _engine_error(path, section, exc, None) from None


def _engine_error(path: Path, section: str, exc: Exception, key: str | None) -> ScenarioError:
    """The scenario key of an error from the API: the parameter a ParameterError names, else the
    key being checked."""
    if isinstance(exc, ParameterError):
        reason = f"= {exc.value!r} is invalid"
        if exc.allowed:
            reason += f": {exc.allowed}"
        return ScenarioError(path, f"{section}.{exc.parameter}", reason)
    return ScenarioError(path, f"{section}.{key}" if key else section, str(exc))


def _panel(path: Path, table: dict[str, Any]) -> Panel:
    known = set(Panel.field_names())
    _reject_unknown(path, "panel", table, known)
    values = {key: _real(path, f"panel.{key}", value) for key, value in table.items()}
    return _validated(path, "panel", Panel, {}, values)  # type: ignore[no-any-return]


BOOM_KEYS = (*Boom.field_names(), "material", "solar_inclination_deg")
"""Keys of [boom]: the Boom's fields, its library material, and the inclination in degrees."""


def _boom(path: Path, table: dict[str, Any]) -> Boom:
    _reject_unknown(path, "boom", table, set(BOOM_KEYS))
    values: dict[str, Any] = {}
    for key, value in table.items():
        if key == "material":
            if not isinstance(value, str) or value not in materials.LIBRARY:
                keys = ", ".join(materials.LIBRARY)
                raise ScenarioError(path, "boom.material", f"must be one of {keys}")
            values[key] = value
        elif key == "solar_inclination_deg":
            if "solar_inclination" in table:
                raise ScenarioError(
                    path, "boom.solar_inclination_deg", "give solar_inclination or _deg, not both"
                )
            values["solar_inclination"] = math.radians(_real(path, f"boom.{key}", value))
        else:
            values[key] = _real(path, f"boom.{key}", value)
    required = {}
    for key in ("length", "radius", "wall"):
        if key not in values:
            raise ScenarioError(path, f"boom.{key}", "is required")
        required[key] = values.pop(key)
    return _validated(path, "boom", Boom, required, values)  # type: ignore[no-any-return]


LAYER_KEYS = ("material", "name", *(f.name for f in fields(Layer) if f.name != "name"))
"""Keys of a [[laminate.layers]] entry: a library material and/or the properties of a Layer."""
LAMINATE_KEYS = tuple(f.name for f in fields(Laminate) if f.name != "layers")
"""Keys of [laminate] besides its layers."""
LAMINATE_PANEL_KEYS = tuple(
    k for k in Panel.field_names() if k not in LAYUP_FIELDS and k not in LAMINATE_KEYS
) + ("width",)
"""The [panel] keys a scenario with a [laminate] may give (Panel.from_laminate's arguments)."""


def _layer(path: Path, index: int, entry: Any) -> Layer:
    """One [[laminate.layers]] entry; errors name laminate.layers[i].key and the layer."""
    where = f"laminate.layers[{index}]"
    if not isinstance(entry, dict):
        raise ScenarioError(path, where, f"must be a table, not {_toml_type(entry)}")
    named = entry.get("name", entry.get("material"))
    label = where + (f" ('{named}')" if isinstance(named, str) else "")
    for key in entry:
        if key not in LAYER_KEYS:
            raise ScenarioError(
                path, f"{label}.{key}", f"unknown key (allowed: {', '.join(LAYER_KEYS)})"
            )
    values: dict[str, Any] = {}
    if "material" in entry:
        key = entry["material"]
        if not isinstance(key, str) or key not in materials.LIBRARY:
            raise ScenarioError(
                path,
                f"{label}.material",
                f"must be one of {', '.join(repr(k) for k in materials.LIBRARY)}, not {key!r}",
            )
        # The material's properties, named after it; the entry's own keys override them.
        values = materials.LIBRARY[key].layer(1.0).as_dict()
        del values["thickness"]
    if "name" in entry:
        if not isinstance(entry["name"], str):
            raise ScenarioError(path, f"{label}.name", f"must be a string, not {entry['name']!r}")
        values["name"] = entry["name"]
    for key, value in entry.items():
        if key not in ("material", "name"):
            values[key] = _real(path, f"{label}.{key}", value)
    missing = [f.name for f in fields(Layer) if f.name != "name" and f.name not in values]
    if missing:
        raise ScenarioError(
            path,
            f"{label}.{missing[0]}",
            "is required (give material = a library key, or every property of the layer)",
        )
    # The engine checks the layer and names the property it refuses.
    try:
        return Layer(**values)
    except ParameterError as exc:
        # "layer 'core': density = -50 is invalid: ..." → "= -50 is invalid: ..." under the key
        # of the property the engine names.
        field_name = exc.parameter.rsplit(": ", 1)[-1]
        reason = str(exc).split(f"{field_name} ", 1)[-1]
        raise ScenarioError(path, f"{label}.{field_name}", reason) from None
    except (ValueError, TypeError) as exc:
        raise ScenarioError(path, label, str(exc)) from None


def _laminate(path: Path, table: dict[str, Any]) -> Laminate:
    """[laminate] with its [[laminate.layers]] (front first)."""
    _reject_unknown(path, "laminate", table, {"layers", *LAMINATE_KEYS})
    entries = table.get("layers")
    if not isinstance(entries, list) or not entries:
        raise ScenarioError(
            path, "laminate.layers", "at least one [[laminate.layers]] table is required"
        )
    layers = tuple(_layer(path, i, entry) for i, entry in enumerate(entries))
    missing = [k for k in ("emissivity_front", "emissivity_back", "absorptivity") if k not in table]
    if missing:
        raise ScenarioError(path, f"laminate.{missing[0]}", "is required")
    values = {k: _real(path, f"laminate.{k}", v) for k, v in table.items() if k != "layers"}
    try:
        return Laminate(layers, **values)
    except ParameterError as exc:
        # The engine names the surface property or "layers" (the stack as a whole).
        key = f"laminate.{exc.parameter}"
        reason = str(exc).split(f"{exc.parameter} ", 1)[-1]
        raise ScenarioError(path, key, reason) from None
    except (ValueError, TypeError) as exc:
        raise ScenarioError(path, "laminate", str(exc)) from None


def _laminate_panel(path: Path, panel: dict[str, Any], laminate: Laminate) -> Panel:
    """Panel.from_laminate of the layup with the [panel] keys it takes."""
    for key in panel:
        if key not in LAMINATE_PANEL_KEYS:
            raise ScenarioError(
                path,
                f"panel.{key}",
                "follows from [laminate] (give it there, or remove [laminate]); with a "
                f"[laminate], [panel] takes {', '.join(LAMINATE_PANEL_KEYS)}",
            )
    values = {key: _real(path, f"panel.{key}", value) for key, value in panel.items()}
    return _validated(  # type: ignore[no-any-return]
        path, "panel", lambda **kw: Panel.from_laminate(laminate, **kw), {}, values
    )


def _orbit(path: Path, table: dict[str, Any]) -> Orbit:
    """[orbit]: a preset (with its own arguments: start_date for geo_year, altitude for leo)
    and/or any Orbit field."""
    known = {f.name for f in fields(Orbit)} | {"preset", "start_date", "altitude"}
    _reject_unknown(path, "orbit", table, known)
    base: dict[str, Any] = {}
    preset = None
    if "preset" in table:
        preset = _choice(path, "orbit.preset", table["preset"], tuple(ORBIT_PRESETS))
    if "start_date" in table and preset not in ("geo_year", "circular"):
        raise ScenarioError(path, "orbit.start_date", "goes with preset = 'geo_year' or 'circular'")
    if "altitude" in table and preset not in ("leo", "circular"):
        raise ScenarioError(path, "orbit.altitude", "goes with preset = 'leo' or 'circular'")
    if preset == "circular":
        # Orbit.circular's own defaults (the March equinox, J2, a conical shadow, the Earth's
        # mean albedo and infrared); its other fields below override them.
        altitude = _positive(path, "orbit.altitude", table.get("altitude", LEO_ALTITUDE))
        start = table.get("start_date", EQUINOX_DAY)
        if not isinstance(start, (str, int, float, date)) or isinstance(start, bool):
            raise ScenarioError(path, "orbit.start_date", "must be a date (2026-03-20) or a day")
        try:
            epoch = day_of_year(start, "start_date")
        except (ValueError, TypeError) as exc:
            raise ScenarioError(path, "orbit.start_date", str(exc)) from None
        try:
            base = Orbit.circular(altitude, epoch=epoch).as_dict()
        except (ValueError, TypeError) as exc:
            raise _engine_error(path, "orbit", exc, "altitude") from None
    elif preset == "geo_year":
        start = table.get("start_date", "2026-01-01")
        if not isinstance(start, (str, int, date)) or isinstance(start, bool):
            raise ScenarioError(path, "orbit.start_date", "must be a date (2026-03-20) or a day")
        try:
            base = Orbit.geo_year(start).as_dict()
        except (ValueError, TypeError) as exc:
            raise ScenarioError(path, "orbit.start_date", str(exc)) from None
    elif preset == "leo":
        altitude = _positive(path, "orbit.altitude", table.get("altitude", LEO_ALTITUDE))
        base = Orbit.leo(altitude).as_dict()
    elif preset is not None:
        base = ORBIT_PRESETS[preset]().as_dict()
    values: dict[str, Any] = {}
    for key, value in table.items():
        if key in ("preset", "start_date", "altitude"):
            continue
        if key == "shadow":
            values[key] = _choice(path, "orbit.shadow", value, SHADOWS)
        elif key in ("season", "eccentric_sun", "j2"):
            values[key] = _boolean(path, f"orbit.{key}", value)
        else:
            values[key] = _real(path, f"orbit.{key}", value)
    return _validated(path, "orbit", Orbit, base, values)  # type: ignore[no-any-return]


ATTITUDE_KEYS = ("kind", "offset", "normal")
"""The keys of a scenario's [attitude] table."""


def _attitude(path: Path, table: dict[str, Any]) -> Attitude:
    """[attitude]: kind (default Sun-pointing), with offset (rad) for Sun tracking and normal
    (three numbers) for an inertial attitude."""
    _reject_unknown(path, "attitude", table, set(ATTITUDE_KEYS))
    kinds = ("sun_pointing", "sun_tracking", "nadir", "inertial")
    kind = _choice(path, "attitude.kind", table.get("kind", "sun_pointing"), kinds)
    values: dict[str, Any] = {"kind": kind}
    if "offset" in table:
        if kind != "sun_tracking":
            raise ScenarioError(path, "attitude.offset", "goes with kind = 'sun_tracking'")
        values["offset"] = _real(path, "attitude.offset", table["offset"])
    if "normal" in table:
        if kind != "inertial":
            raise ScenarioError(path, "attitude.normal", "goes with kind = 'inertial'")
        normal = table["normal"]
        if not isinstance(normal, list) or len(normal) != 3:
            raise ScenarioError(path, "attitude.normal", "must be three numbers [x, y, z]")
        values["normal"] = tuple(
            _real(path, f"attitude.normal[{i}]", v) for i, v in enumerate(normal)
        )
    return _validated(path, "attitude", Attitude, values, {})  # type: ignore[no-any-return]


def _simulation(path: Path, table: dict[str, Any]) -> SimulationSettings:
    known = {f.name for f in fields(SimulationSettings)}
    _reject_unknown(path, "simulation", table, known)
    s = "simulation."
    out: dict[str, Any] = {}
    for key, value in table.items():
        if key in ("model",):
            out[key] = _choice(path, s + key, value, MODELS)
        elif key == "method":
            out[key] = _choice(path, s + key, value, METHODS)
        elif key == "coupled":
            out[key] = _boolean(path, s + key, value)
        elif key == "keep":
            out[key] = _choice(path, s + key, value, KEEP)
        elif key == "on_limit":
            out[key] = _choice(path, s + key, value, ON_LIMIT)
        elif key in ("t_start", "t_end"):
            out[key] = _real(path, s + key, value)
        elif key == "max_steps":
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise ScenarioError(path, s + key, f"must be an integer >= 1, not {value!r}")
            out[key] = value
        elif key == "layers":
            if isinstance(value, bool) or not isinstance(value, int) or value < 2:
                raise ScenarioError(
                    path,
                    s + key,
                    f"must be an integer >= 2 (nodes through the thickness), not {value!r}",
                )
            out[key] = value
        else:
            out[key] = _positive(path, s + key, value)
    given = [k for k in ("t_end", "orbits", "years") if k in out]
    if len(given) > 1:
        raise ScenarioError(path, s + given[1], "give either t_end, orbits or years, not several")
    settings = SimulationSettings(**out)
    if settings.t_end is not None and settings.t_end <= settings.t_start:
        raise ScenarioError(
            path, s + "t_end", f"must be after t_start = {settings.t_start}, not {settings.t_end}"
        )
    if settings.method == "hybrid" and settings.keep != "orbits":
        raise ScenarioError(
            path,
            s + "method",
            "'hybrid' keeps one summary per orbit: it needs keep = 'orbits'",
        )
    if settings.method == "rk4" and settings.dt is None:
        raise ScenarioError(path, s + "dt", "is required with method = 'rk4' (the fixed step, s)")
    return settings


def _output(path: Path, table: dict[str, Any]) -> OutputSettings:
    _reject_unknown(path, "output", table, {"format", "plots"})
    fmt = _choice(path, "output.format", table.get("format", "csv"), FORMATS)
    plots = _boolean(path, "output.plots", table.get("plots", True))
    return OutputSettings(format=fmt, plots=plots)


def parse_scenario(
    data: dict[str, Any], path: str | Path = "<scenario>", extra_sections: Sequence[str] = ()
) -> Scenario:
    """A scenario from parsed TOML data; ``path`` is used in error messages only.

    ``extra_sections`` names further tables the caller accepts; they are returned unchecked in
    ``Scenario.extra`` (absent ones as empty tables)."""
    where = Path(path)
    sections = {
        "panel",
        "laminate",
        "boom",
        "orbit",
        "attitude",
        "simulation",
        "output",
        *extra_sections,
    }
    for key in data:
        if key not in sections:
            raise ScenarioError(
                where, key, f"unknown table (allowed: {', '.join(sorted(sections))})"
            )
    panel: Panel | Boom
    if "boom" in data:
        for other in ("panel", "laminate"):
            if other in data:
                raise ScenarioError(
                    where, other, "a scenario with [boom] has no [panel] or [laminate]"
                )
        panel = _boom(where, _table(where, data, "boom"))
    elif "laminate" in data:
        layup = _laminate(where, _table(where, data, "laminate"))
        panel = _laminate_panel(where, _table(where, data, "panel"), layup)
    else:
        panel = _panel(where, _table(where, data, "panel"))
    return Scenario(
        panel=panel,
        orbit=_orbit(where, _table(where, data, "orbit")),
        attitude=_attitude(where, _table(where, data, "attitude")),
        simulation=_simulation(where, _table(where, data, "simulation")),
        output=_output(where, _table(where, data, "output")),
        source=str(path),
        extra={name: _table(where, data, name) for name in extra_sections},
    )


def load_scenario(path: str | Path, extra_sections: Sequence[str] = ()) -> Scenario:
    """Reads and checks a TOML scenario file; raises :class:`ScenarioError` on any problem."""
    where = Path(path)
    try:
        raw = where.read_bytes()
    except FileNotFoundError:
        raise ScenarioError(where, None, "no such file") from None
    except IsADirectoryError:
        raise ScenarioError(where, None, "is a directory, not a scenario file") from None
    except OSError as exc:
        raise ScenarioError(where, None, f"cannot be read ({exc.strerror})") from None
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except UnicodeDecodeError:
        raise ScenarioError(where, None, "is not UTF-8 text") from None
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(where, None, f"invalid TOML: {exc}") from None
    return parse_scenario(data, where, extra_sections)
