"""A small library of materials for laminate layers (room-temperature values).

Each material's values and their source live once, in the engine; this module exposes them.
``Material.layer(thickness)`` makes a :class:`thermojitter.Layer`. The materials and the source of
every value:
"""

from __future__ import annotations

from dataclasses import dataclass

from thermojitter import _core
from thermojitter.errors import ParameterError, wrong_type
from thermojitter.laminate import Layer


@dataclass(frozen=True)
class Material:
    """A material of the library: the properties of a layer but its thickness (SI), and
    ``source``, where every value comes from."""

    key: str
    name: str
    conductivity: float
    density: float
    specific_heat: float
    youngs_modulus: float
    expansion_coeff: float
    source: str

    def layer(self, thickness: float, name: str | None = None) -> Layer:
        """A layer of this material, ``thickness`` m thick (named after the material by
        default)."""
        # The layer's other fields, by the engine's one list of them, are the material's.
        values = {f: getattr(self, f) for f in _core.LAYER_FIELDS if f != "thickness"}
        return Layer(thickness=thickness, name=self.key if name is None else name, **values)


LIBRARY: dict[str, Material] = {m["key"]: Material(**m) for m in _core.materials()}
"""Every material by key."""

ALUMINIUM_6061 = LIBRARY["aluminium_6061"]
TITANIUM_6AL4V = LIBRARY["titanium_6al4v"]
CFRP_M55J_QI = LIBRARY["cfrp_m55j_qi"]
ALUMINIUM_HONEYCOMB = LIBRARY["aluminium_honeycomb"]
KAPTON = LIBRARY["kapton"]


def get(key: str) -> Material:
    """A material by key (a ``ParameterError`` naming ``key`` and listing the keys if unknown)."""
    if not isinstance(key, str):
        raise wrong_type("key", key, "a string")
    if key not in LIBRARY:
        raise ParameterError("key", key, f"not in the library ({', '.join(LIBRARY)})")
    return LIBRARY[key]


__doc__ = (__doc__ or "") + "".join(
    f"\n- ``{m.key.upper()}``, {m.name}: {m.source}\n" for m in LIBRARY.values()
)
