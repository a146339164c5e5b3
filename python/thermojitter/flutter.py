"""Thermal flutter without integration: linear stability of the sunlit equilibrium."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from thermojitter import _core
from thermojitter.panel import Panel
from thermojitter.results import Equilibrium


@dataclass(frozen=True)
class FlutterResult:
    """Eigen-analysis of the coupled system linearised at the sunlit equilibrium.

    ``growth_rate`` (1/s) is the largest real part of the eigenvalues: positive means the
    oscillation grows (thermal flutter), e-folding in 1/growth_rate seconds. ``critical_damping``
    (N m s/rad) is the hinge damping c_d at which it crosses zero.
    """

    equilibrium: Equilibrium
    jacobian: NDArray[np.float64]
    eigenvalues: NDArray[np.complex128]
    growth_rate: float
    frequency_hz: float
    critical_damping: float
    model: str
    coupled: bool
    flux: float

    @property
    def stable(self) -> bool:
        return self.growth_rate < 0.0

    @property
    def e_folding_time(self) -> float:
        """1/|growth_rate|, s (time to grow, or decay, by a factor e)."""
        return math.inf if self.growth_rate == 0.0 else 1.0 / abs(self.growth_rate)


def flutter(
    panel: Panel,
    model: Literal["nonlinear", "linear"] = "nonlinear",
    *,
    coupled: bool = True,
    flux: float = 1.0,
) -> FlutterResult:
    """Linear stability of the sunlit equilibrium of ``panel``.

    ``flux`` scales the solar constant (the Sun–Earth distance changes it by about ±3.3 % over the
    year); the equilibrium, and with it the critical damping, depend on it.
    """
    if not isinstance(panel, Panel):
        raise TypeError(f"panel must be a thermojitter.Panel, not {type(panel).__name__}")
    raw = _core.flutter(panel.as_dict(), model, bool(coupled), float(flux))
    tf, tb, th = raw["equilibrium"]
    moment = float(_core.moment(panel.as_dict(), np.array([tf]), np.array([tb]))[0])
    return FlutterResult(
        equilibrium=Equilibrium(T_front=tf, T_back=tb, theta=th, thermal_moment=moment),
        jacobian=np.asarray(raw["jacobian"]),
        eigenvalues=np.array([complex(re, im) for re, im in raw["eigenvalues"]]),
        growth_rate=float(raw["growth_rate"]),
        frequency_hz=float(raw["frequency_hz"]),
        critical_damping=float(raw["critical_damping"]),
        model=model,
        coupled=bool(coupled),
        flux=float(flux),
    )
