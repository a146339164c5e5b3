"""Layups through the thickness: layers of different materials and the laminate they make.

The engine does every computation (lamination theory, the N-node conduction model); this module
validates, converts and presents. Layers are listed from the Sun-facing (front) side to the back.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, fields
from functools import cached_property
from typing import Any

from thermojitter import _core
from thermojitter import errors as checks
from thermojitter.persist import field_type


@field_type
@dataclass(frozen=True)
class Layer:
    """One layer of a laminate, isotropic in its plane; every value SI.

    ``youngs_modulus`` may be 0 (a honeycomb core carries no bending stress) and
    ``expansion_coeff`` may be negative (carbon fibre). A bad value raises ``ValueError`` naming
    the layer and the field, e.g. ``layer 'core': density``.
    """

    thickness: float
    """h, m."""
    conductivity: float
    """k through the thickness, W/(m K)."""
    density: float
    """ρ, kg/m³."""
    specific_heat: float
    """c, J/(kg K)."""
    youngs_modulus: float
    """E in the plane, Pa (>= 0)."""
    expansion_coeff: float
    """a in the plane, 1/K."""
    name: str = "layer"
    """A name for messages and tables."""

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):
            raise checks.wrong_type("name", self.name, "a string")
        for f in fields(self):
            if f.name != "name":
                label = f"layer '{self.name}': {f.name}"
                object.__setattr__(self, f.name, checks.real(label, getattr(self, f.name)))
        _core.validate_layer(self.as_dict())

    def as_dict(self) -> dict[str, Any]:
        return {f.name: getattr(self, f.name) for f in fields(self)}


@field_type
@dataclass(frozen=True)
class Laminate:
    """A stack of layers (front first) with its surface properties.

    ``reference_temperature`` (K) is the stress-free temperature: a layup whose expansion is not
    symmetric about its neutral axis (a bimetal) bends under a uniform change from it.
    Derived properties (classical lamination theory) come from the engine.
    """

    layers: tuple[Layer, ...]
    emissivity_front: float
    """ε of the front face, in (0, 1]."""
    emissivity_back: float
    """ε of the back face, in (0, 1]."""
    absorptivity: float
    """α of the front face, in (0, 1]."""
    reference_temperature: float = _core.REFERENCE_TEMPERATURE
    """T_ref, K."""

    def __post_init__(self) -> None:
        layers = self.layers
        if isinstance(layers, Layer) or not isinstance(layers, Iterable):
            raise checks.wrong_type(
                "layers",
                layers,
                "a sequence of thermojitter.Layer",
                "layers must be a sequence of thermojitter.Layer",
            )
        layers = tuple(layers)
        for i, layer in enumerate(layers):
            if not isinstance(layer, Layer):
                raise checks.wrong_type(f"layers[{i}]", layer, "a thermojitter.Layer")
        object.__setattr__(self, "layers", layers)
        for name in (
            "emissivity_front",
            "emissivity_back",
            "absorptivity",
            "reference_temperature",
        ):
            object.__setattr__(self, name, checks.real(name, getattr(self, name)))
        _core.validate_laminate(self.as_dict())

    def as_dict(self) -> dict[str, Any]:
        return {
            "layers": [layer.as_dict() for layer in self.layers],
            "emissivity_front": self.emissivity_front,
            "emissivity_back": self.emissivity_back,
            "absorptivity": self.absorptivity,
            "reference_temperature": self.reference_temperature,
        }

    @cached_property
    def _properties(self) -> dict[str, float]:
        return dict(_core.laminate_properties(self.as_dict()))

    @property
    def thickness(self) -> float:
        """d, total thickness, m."""
        return self._properties["thickness"]

    @property
    def mass_per_area(self) -> float:
        """Σ ρ h, kg/m²."""
        return self._properties["mass_per_area"]

    @property
    def heat_capacity(self) -> float:
        """Σ ρ c h, J/(m² K)."""
        return self._properties["heat_capacity"]

    @property
    def thermal_resistance(self) -> float:
        """Σ h/k face to face, m² K/W."""
        return self._properties["thermal_resistance"]

    @property
    def neutral_axis(self) -> float:
        """Depth of the neutral axis below the front face (modulus-weighted centroid), m."""
        return self._properties["neutral_axis"]

    @property
    def bending_stiffness(self) -> float:
        """D about the neutral axis per unit width, N m."""
        return self._properties["bending_stiffness"]
