"""Measurements on sampled records: spectra, the dominant frequency, zero crossings, the drift
removed, the oscillation amplitude. Used by the paper reproduction, the beam comparison and the
figures; plain NumPy, no physics."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from thermojitter.errors import ParameterError

Array = NDArray[np.float64]

DEFAULT_F_MIN = 0.02
"""Lowest frequency (Hz) searched for the jitter peak: above the orbital and thermal drift."""


def window(t: Array, y: Array, t0: float, t1: float) -> tuple[Array, Array]:
    """The samples of (t, y) with t0 <= t <= t1."""
    mask = (t >= t0) & (t <= t1)
    return t[mask], y[mask]


def detrend(t: Array, y: Array, span: float = 60.0) -> Array:
    """y minus its moving average over ``span`` s (removes the slow thermal drift)."""
    dt = float(np.median(np.diff(t)))
    n = max(3, int(round(span / dt)) | 1)
    kernel = np.ones(n) / n
    padded = np.pad(y, n // 2, mode="edge")
    return y - np.convolve(padded, kernel, mode="valid")


def spectrum(t: ArrayLike, x: ArrayLike, *, pad: int = 1) -> tuple[Array, Array]:
    """One-sided amplitude spectrum of a uniformly sampled signal (mean removed, Hann window):
    frequencies (Hz) and amplitudes (same unit as x). ``pad`` > 1 zero-pads to the power of two
    at or above pad·n samples (a finer frequency grid, the same peaks)."""
    ts = np.asarray(t, dtype=float)
    xs = np.asarray(x, dtype=float)
    if ts.size < 8 or ts.size != xs.size:
        raise ParameterError(
            "t", t, message=f"t holds {ts.size} samples: need 8 or more, as many as x"
        )
    steps = np.diff(ts)
    if not np.allclose(steps, steps[0], rtol=1e-6, atol=0.0):
        raise ParameterError("t", t, message="t must be uniformly spaced for the FFT")
    if isinstance(pad, bool) or not isinstance(pad, int) or pad < 1:
        raise ParameterError("pad", pad, "must be an integer >= 1")
    size = xs.size if pad == 1 else 1 << math.ceil(math.log2(pad * xs.size))
    taper = np.hanning(xs.size)
    amp = np.abs(np.fft.rfft((xs - xs.mean()) * taper, size)) * 2.0 / taper.sum()
    return np.fft.rfftfreq(size, steps[0]), amp


def power_spectral_density(t: ArrayLike, x: ArrayLike) -> tuple[Array, Array]:
    """One-sided power spectral density of a uniformly sampled signal (mean removed, Hann
    window): frequencies (Hz) and densities (x's unit squared per Hz). It is :func:`spectrum`'s
    amplitude A rescaled, PSD = A² (Σw)² / (2 f_s Σw²) for the window w and sampling rate f_s,
    so that the densities summed over the bins (times the bin width) give x's variance."""
    f, amp = spectrum(t, x)
    taper = np.hanning(np.asarray(x, dtype=float).size)
    rate = float(f[1]) * taper.size
    return f, amp**2 * taper.sum() ** 2 / (2.0 * rate * np.sum(taper**2))


def dominant_frequency(
    t: ArrayLike, x: ArrayLike, f_min: float = DEFAULT_F_MIN, *, pad: int = 1
) -> float:
    """The frequency (Hz) of the largest spectral peak above ``f_min``, refined by a parabola
    through the log amplitudes of the peak bin and its neighbours (see :func:`spectrum` for
    ``pad``)."""
    f, a = spectrum(t, x, pad=pad)
    idx = np.nonzero(f >= f_min)[0]
    if idx.size < 3:
        raise ParameterError("f_min", f_min, "leaves fewer than 3 frequency bins")
    k = int(idx[np.argmax(a[idx])])
    if 0 < k < a.size - 1:
        y0, y1, y2 = np.log(a[k - 1 : k + 2] + 1e-300)
        denom = y0 - 2.0 * y1 + y2
        shift = 0.5 * (y0 - y2) / denom if denom != 0 else 0.0
        return float(f[k] + shift * (f[1] - f[0]))
    return float(f[k])


def zero_crossing_frequency(t: Array, y: Array) -> float:
    """Frequency (Hz) from the mean spacing of the (interpolated) upward zero crossings."""
    up = np.nonzero((y[:-1] < 0.0) & (y[1:] >= 0.0))[0]
    if len(up) < 2:
        return float("nan")
    crossings = t[up] - y[up] * (t[up + 1] - t[up]) / (y[up + 1] - y[up])
    return float((len(crossings) - 1) / (crossings[-1] - crossings[0]))


def oscillation_amplitude(t: Array, y: Array, bin_s: float) -> tuple[Array, Array]:
    """Half the peak-to-peak of y in consecutive bins of ``bin_s`` s: (bin centres, amplitudes)."""
    edges = np.arange(t[0], t[-1], bin_s)
    centres, amps = [], []
    for a in edges:
        seg = y[(t >= a) & (t < a + bin_s)]
        if len(seg) > 1:
            centres.append(a + 0.5 * bin_s)
            amps.append(0.5 * float(np.ptp(seg)))
    return np.array(centres), np.array(amps)
