"""Results recorded before the engine's models were put behind traits, to the bit.

The Rust side (rust/src/recorded.rs) pins the engine; this pins the whole path from the public
API: default start state, solver settings, the binding layer and the derived columns.
"""

import numpy as np
import pytest

import thermojitter as tj

# Every third of 13 evenly spaced samples over one orbit: t = 0, T/4, T/2, 3T/4, T.
RECORDED = {
    "paper": {
        "n_steps": 208180,
        "n_rhs": 1380150,
        "T_front": ["0x1.6e02d69c54a26p+8", "0x1.6e02d69c3ee7ap+8", "0x1.aecb736b559d6p+7",
                    "0x1.6e02d301f188bp+8", "0x1.6e02d731d93e1p+8"],
        "T_back": ["0x1.632e9060c9fe2p+8", "0x1.632e9060ca45ap+8", "0x1.b1438a20aae95p+7",
                   "0x1.632e8ede9bd75p+8", "0x1.632e904280fc5p+8"],
        "theta": ["0x1.5dd0550a39df9p-4", "0x1.5dd0721037535p-4", "-0x1.0bac9f692ec8ep-7",
                  "0x1.5aafe40fc1c40p-4", "0x1.5e8679118a966p-4"],
        "thermal_moment": ["0x1.7b059a23f474cp+8", "0x1.7b059a20f2260p+8",
                           "-0x1.59ac6b2aa5874p+5", "0x1.7b0550d4b7402p+8",
                           "0x1.7b05b2b910fd4p+8"],
    },
    "year": {
        "n_steps": 80488,
        "n_rhs": 617488,
        "T_front": ["0x1.6dcd46ced79fbp+8", "0x1.6dd09ade51af6p+8", "0x1.cad862a608a75p+7",
                    "0x1.6dd763100d5e3p+8", "0x1.6ddac79b87e45p+8"],
        "T_back": ["0x1.62fed2006ae06p+8", "0x1.6301c664ebc27p+8", "0x1.ce07d37627806p+7",
                   "0x1.6307d216ce9f7p+8", "0x1.630ad85458056p+8"],
        "theta": ["0x1.5d14645804c3dp-4", "0x1.5d209bd5f56fdp-4", "-0x1.9b98e6d934818p-7",
                  "0x1.5d378c2382237p-4", "0x1.5d43da587c2c2p-4"],
        "thermal_moment": ["0x1.7a39f838de27fp+8", "0x1.7a470c98ef64dp+8",
                           "-0x1.bdf1b1d0deb4cp+5", "0x1.7a60d21394144p+8",
                           "0x1.7a6db6bb8b7adp+8"],
    },
}  # fmt: skip

ORBITS = {
    "paper": tj.Orbit.geo_equinox,
    # 1 October: the autumn eclipse season, penumbra, Sun's distance and declination of the date.
    "year": lambda: tj.Orbit.geo_year("2026-10-01"),
}


@pytest.mark.parametrize("name", sorted(RECORDED))
def test_one_orbit_from_the_equilibrium_is_bit_identical(name: str) -> None:
    orbit = ORBITS[name]()
    t = np.linspace(0.0, orbit.period, 13)
    sol = tj.simulate(tj.Panel.paper(), orbit, (0.0, orbit.period), t_eval=t)
    want = RECORDED[name]
    assert (sol.n_steps, sol.n_rhs) == (want["n_steps"], want["n_rhs"])
    for column in ("T_front", "T_back", "theta", "thermal_moment"):
        got = [float(v).hex() for v in getattr(sol, column)[::3]]
        assert got == want[column], column
