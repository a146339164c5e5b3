//! A segment's loads fitted once and read many times: slow time asks for the Earth's heat and
//! the Sun's at some twenty times a step, and a penumbra's full integration at every stage of
//! its hinge-resolved steps, each time through the orbit's geometry, the view factors and (in a
//! penumbra) the overlap of two discs. On each segment between the orbit's breakpoints the
//! loads are smooth but at the albedo's terminator and the view factors' edges of full view,
//! so a piecewise Chebyshev table ([`Table`]) holds them to [`LOAD_TOLERANCE`] of the Sun's flux
//! on every part its check keeps; the parts it refuses (those kinks) are evaluated exactly.

use crate::inputs::heating::Loads;
use crate::models::coupled::Coupled;
use crate::numerics::chebyshev::{Form, Table};
use crate::numerics::integrate::{OdeSystem, State};
use nalgebra::U4;

/// The largest error of a tabulated load, as a fraction of the Sun's flux at 1 au (the
/// front's sunlight factor, and the absorbed fluxes over the solar constant): the tolerance of
/// the penumbra's flux interpolant at long orbits. A flux off by 1e-10 of the Sun's moves the
/// temperatures by ~3e-8 K and θ₀ by ~2e-10 rad (Table 1), far below slow time's tolerance on
/// θ₀ (5e-8 rad) and the summaries' gate.
pub const LOAD_TOLERANCE: f64 = 1e-10;
/// The longest span of a part, s (in v the middle parts are π/2 times wider in t): a few
/// tenths of a low orbit's radian (its loads turn with the orbit's angle: a degree-10 series
/// holds cos over 0.7 rad to ~1e-16).
const PART_SPAN: f64 = 300.0;
/// The span, s, on which the loads' kinks are searched for one sign change each: where a face
/// barely reaches full view of the Earth, it leaves it again within a minute or two.
const KINK_SEARCH: f64 = 60.0;
/// Parts between two kinks at least: next to a face's edge of full view its view factor turns
/// within minutes.
const KINK_PARTS: usize = 2;
/// Parts of a penumbra's table, in the variable in which its contacts are smooth (as the
/// penumbra's flux interpolant of long orbits). Two hold a low orbit's penumbra of 8 to 15 s:
/// none of 800 parts refused at 540 km (28.5°, 200 orbits), 10 of 3600 on four other low orbits
/// (400 to 1400 km, 30° to 98°), which are then read exactly.
const PENUMBRA_PARTS: usize = 2;

/// The loads of one segment of an orbit: a table between each two of its kinks.
#[derive(Debug, Clone)]
pub(crate) struct LoadTable {
    /// The segment's start, its kinks and its end.
    cuts: Vec<f64>,
    tables: Vec<Table<3>>,
}

impl LoadTable {
    /// The loads of `system` over its current segment [a, b] (entered), or None when the system
    /// takes the front's sunlight alone (its flux is already cheap) or the segment is empty.
    pub(crate) fn fit(system: &Coupled, a: f64, b: f64) -> Option<Self> {
        let solar = system.solar_constant()?;
        if !system.has_face_loads() || b.partial_cmp(&a) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        let tol = [
            LOAD_TOLERANCE,
            LOAD_TOLERANCE * solar,
            LOAD_TOLERANCE * solar,
        ];
        let loads = |t: f64| {
            let l = system.loads_at(t);
            [l.sun, l.front, l.back]
        };
        let fewest = if system.illumination_varies() {
            PENUMBRA_PARTS
        } else {
            KINK_PARTS
        };
        let mut cuts = vec![a];
        cuts.extend(system.orbit().load_kinks(a, b, KINK_SEARCH));
        cuts.push(b);
        let tables = cuts
            .windows(2)
            .map(|w| {
                let parts = ((w[1] - w[0]) / PART_SPAN).ceil().max(fewest as f64) as usize;
                Table::fit_in(Form::Power, loads, w[0], w[1], parts, tol)
            })
            .collect();
        Some(LoadTable { cuts, tables })
    }

    /// The loads at t, None where the table leaves them to the exact loads.
    #[inline(always)]
    pub(crate) fn at(&self, t: f64) -> Option<Loads> {
        let n = self.tables.len();
        // The inner cuts at or before t, counted without branches (a handful: a binary
        // search's branches are a coin toss at every read).
        let k = self.cuts[1..n].iter().filter(|&&c| c <= t).count();
        self.tables[k]
            .at(t)
            .map(|[sun, front, back]| Loads { sun, front, back })
    }

    /// Parts of the table, and of those refused.
    #[cfg(test)]
    pub(crate) fn parts(&self) -> (usize, usize) {
        self.tables
            .iter()
            .fold((0, 0), |(p, r), tb| (p + tb.parts(), r + tb.refused()))
    }
}

/// The loads at t of a system whose segment was tabulated as `table`.
#[inline(always)]
pub(crate) fn loads_at(system: &Coupled, table: Option<&LoadTable>, t: f64) -> Loads {
    match table.and_then(|tb| tb.at(t)) {
        Some(loads) => loads,
        None => system.loads_at(t),
    }
}

/// The panel on its hinge with each segment's loads tabulated on entering it: the full
/// integration inside a slow-time run (penumbrae, orbits given back).
pub(crate) struct Tabulated<'a> {
    system: &'a mut Coupled,
    table: Option<LoadTable>,
}

impl<'a> Tabulated<'a> {
    pub(crate) fn new(system: &'a mut Coupled) -> Self {
        Tabulated {
            system,
            table: None,
        }
    }
}

impl OdeSystem<U4> for Tabulated<'_> {
    #[inline(always)]
    fn rhs(&self, t: f64, y: &State<U4>) -> State<U4> {
        match &self.table {
            Some(tb) => self
                .system
                .rhs_at_loads(loads_at(self.system, Some(tb), t), y),
            None => self.system.rhs(t, y),
        }
    }

    #[inline(always)]
    fn rhs_fused(&self, t: f64, y: &State<U4>) -> State<U4> {
        match &self.table {
            Some(tb) => self
                .system
                .rhs_at_loads_fused(loads_at(self.system, Some(tb), t), y),
            None => self.system.rhs_fused(t, y),
        }
    }

    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        self.system.breakpoints(t0, t1)
    }

    fn check_span(&self, t0: f64, t1: f64) -> crate::error::Result<()> {
        self.system.check_span(t0, t1)
    }

    fn enter_segment(&mut self, a: f64, b: f64) {
        self.system.enter_segment(a, b);
        self.table = LoadTable::fit(self.system, a, b);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inputs::orbit::{Orbit, Shadow};
    use crate::inputs::panel::Panel;
    use crate::models::coupled::Coupling;
    use crate::models::hinge::HingeModel;
    use crate::numerics::chebyshev::TIME_ROUNDINGS;

    /// On drawn heated orbits, every segment's table reads the exact loads to its tolerance
    /// (at 2000 times a segment, not the check's own points): [`LOAD_TOLERANCE`] of the Sun's
    /// flux, plus what the loads themselves are known to at times this large (their slope times
    /// [`TIME_ROUNDINGS`] roundings of t, the check's own allowance). A table keeps nearly all
    /// of its parts: the loads' kinks are found and cut at.
    #[test]
    fn a_segments_table_is_its_loads() {
        let mut draw = crate::numerics::testing::uniform_draws(41);
        let (mut parts, mut refused, mut worst) = (0, 0, 0.0_f64);
        for _ in 0..16 {
            let orbit = Orbit {
                shadow: if draw() < 0.5 {
                    Shadow::Penumbra
                } else {
                    Shadow::Cylindrical
                },
                inclination: 1.7 * draw(),
                raan: 6.0 * draw(),
                epoch_day: 365.0 * draw(),
                season: true,
                eccentric_sun: true,
                j2: true,
                albedo: 0.4 * draw(),
                earth_ir: 260.0 * draw(),
                ..Orbit::leo(300e3 + 1200e3 * draw())
            };
            let panel = Panel::paper();
            let solar = panel.solar_constant;
            let mut system =
                Coupled::new(panel, orbit, HingeModel::Linear, Coupling::ProjectedArea);
            let t0 = 3e7 * draw();
            let mut cuts = vec![t0];
            cuts.extend(system.breakpoints(t0, t0 + orbit.period));
            cuts.push(t0 + orbit.period);
            for w in cuts.windows(2) {
                let (a, b) = (w[0], w[1]);
                system.enter_segment(a, b);
                let table = LoadTable::fit(&system, a, b).expect("a heated orbit's segment");
                let (p, r) = table.parts();
                parts += p;
                refused += r;
                let n = 2000;
                let times: Vec<f64> = (0..=n).map(|i| a + (b - a) * i as f64 / n as f64).collect();
                let exact: Vec<[f64; 3]> = times
                    .iter()
                    .map(|&t| {
                        let l = system.loads_at(t);
                        [l.sun, l.front / solar, l.back / solar]
                    })
                    .collect();
                for i in 1..n {
                    let Some(l) = table.at(times[i]) else {
                        continue;
                    };
                    let got = [l.sun, l.front / solar, l.back / solar];
                    let rounding = TIME_ROUNDINGS * f64::EPSILON * times[i].abs();
                    for c in 0..3 {
                        let slope =
                            (exact[i + 1][c] - exact[i - 1][c]) / (times[i + 1] - times[i - 1]);
                        let allowed = LOAD_TOLERANCE + rounding * slope.abs();
                        worst = worst.max((got[c] - exact[i][c]).abs() / allowed);
                    }
                }
            }
        }
        assert!(worst <= 2.0, "{worst}");
        assert!(refused * 20 < parts, "{refused} of {parts} parts refused");
    }
}
