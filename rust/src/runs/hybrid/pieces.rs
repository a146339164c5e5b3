//! A long slow-time run cut into pieces of orbits that run at once on the machine's cores.
//!
//! The panel forgets its past: the temperatures within minutes of an orbit, the hinge's ringing
//! at its damping rate (Table 1 on a 540 km orbit: to about half of itself each orbit). So a piece
//! that starts from any plausible state some [`warmup_orbits`] before its first orbit reaches
//! that orbit in the state the run before it ends in, to rounding. Each piece after the first
//! does so, all pieces run in parallel, and then, in order, each piece's warmed-up start is
//! checked against the end of the piece before it ([`agrees`]). A piece that does not agree
//! (flutter, a panel damped too little, a warm-up given back to the full integration where the
//! run was not) is run again from that end: the run is then the serial one, only slower.
//!
//! The cut depends on the run alone (its orbits and panel), not on the number of threads: the
//! same run gives the same numbers on any machine.

use crate::cancel::Cancel;
use crate::error::Result;
use crate::runs::hybrid::{slow, Propagated};
use crate::runs::orbits::OrbitRunSpec;
use nalgebra::Vector4;
use rayon::prelude::*;

/// Orbits a piece costs at least, its warm-up counted: a run of fewer than twice this runs
/// whole.
pub const PIECE_ORBITS: u64 = 2000;
/// Four or more pieces come in a multiple of this, each of the same cost: a whole number of
/// rounds on two or four cores, none idle at the end (27 pieces on two cores ran 14 on one).
const ROUND: u64 = 4;
/// The factor by which the warm-up shrinks a piece's start error, at [`WARMUP_RATE`]. Table 1
/// at 540 km: 38 orbits, over which the decay measured below leaves ~1e-12 rad of a start's
/// error, far inside the 5e-8 rad [`agrees`] allows.
const WARMUP_DECAY: f64 = 1e-10;
/// The rate at which a start error is taken to shrink, as a share of the ringing's structural
/// decay rate c_d/(2 I_B). The thermal coupling takes some damping: Table 1 on `Orbit::leo`
/// (540 km) lost an error from a start 28 orbits early only to 5e-10 rad (0.57 of the
/// structural rate, in log), and to 6e-13 from 55 orbits early, the rounding of two histories.
/// Whatever the rate, the check of each piece's start decides ([`agrees`]).
const WARMUP_RATE: f64 = 0.5;
/// A warm-up of more orbits than this share of a piece is not worth it: such a run runs whole.
const WARMUP_SHARE: f64 = 0.05;
/// The warm-up of a piece, in orbits: enough for the hinge's structural damping to shrink an
/// error of its start by [`WARMUP_DECAY`], and at least two (the temperatures' own memory is
/// under an orbit). None when the hinge is undamped.
pub fn warmup_orbits(spec: &OrbitRunSpec) -> Option<u64> {
    // The ringing's amplitude decays as exp(−c_d t / (2 I_B)).
    let rate = WARMUP_RATE * 0.5 * spec.panel.damping_rate();
    if rate.is_nan() || rate <= 0.0 {
        return None;
    }
    let orbits = (-WARMUP_DECAY.ln() / (rate * spec.orbit.period)).ceil();
    Some(orbits.max(2.0) as u64)
}

/// The pieces of a run of `spec`: (first orbit, orbits) from its start, and the warm-up; one
/// piece when the run is short or its warm-up too long. Each piece costs the same, its warm-up
/// counted (the first, which has none, holds that many orbits more), and four or more come in a
/// multiple of [`ROUND`].
pub fn layout(spec: &OrbitRunSpec) -> (Vec<(u64, u64)>, u64) {
    let n = spec.n_orbits;
    let whole = (vec![(0, n)], 0);
    let Some(warmup) = warmup_orbits(spec) else {
        return whole;
    };
    let mut count = n / PIECE_ORBITS;
    if count >= ROUND {
        count -= count % ROUND;
    }
    if count < 2 || warmup as f64 > WARMUP_SHARE * (n / count) as f64 {
        return whole;
    }
    // The orbits and warm-ups over the pieces: each later piece holds `base` (or one more),
    // the first its share and the warm-up.
    let later = n - (n + (count - 1) * warmup) / count;
    let (base, extra) = (later / (count - 1), later % (count - 1));
    let mut pieces = Vec::with_capacity(count as usize);
    pieces.push((0, n - later));
    let mut first = n - later;
    for k in 1..count {
        let len = base + u64::from(k <= extra);
        pieces.push((first, len));
        first += len;
    }
    (pieces, warmup)
}

/// Whether the warmed-up start `warm` of a piece is the state `end` the piece before it ended
/// in, `ring` the largest dynamic part of that piece's last orbit, as far as slow time can tell
/// ([`slow::indistinct`]). Not to rounding: under the Earth's heat a step across the albedo's
/// kink at the terminator is accepted or not on a hair, so two histories of the same orbits
/// end their orbits apart by up to slow time's tolerances (5e-5 K measured on 540 km equatorial
/// orbits, 1e-11 K under the Sun alone), which the next orbits forget as they forget any step's
/// error.
pub fn agrees(spec: &OrbitRunSpec, warm: &Vector4<f64>, end: &Vector4<f64>, ring: f64) -> bool {
    slow::indistinct(&spec.panel, warm, end, ring)
}

/// The part of `spec` from its orbit `first`, `n` orbits long.
fn part(spec: &OrbitRunSpec, first: u64, n: u64) -> OrbitRunSpec {
    OrbitRunSpec {
        t_start: spec.t_start + first as f64 * spec.orbit.period,
        first_index: spec.first_index + first,
        n_orbits: n,
        ..*spec
    }
}

/// A later piece as run in parallel: its warmed-up start and its run from there (None when its
/// warm-up stopped or failed, which tells nothing: the piece then runs in order).
type Warmed = Option<(Vector4<f64>, Result<Propagated<4>>)>;

/// Runs `spec` from `y0` on slow time, in pieces where it is long ([`layout`]); the same
/// summaries as one piece, the counters with the pieces' warm-ups and reruns added.
pub(crate) fn run_in_pieces(
    spec: &OrbitRunSpec,
    y0: Vector4<f64>,
    cancel: &Cancel,
) -> Result<Propagated<4>> {
    let (pieces, warmup) = layout(spec);
    if pieces.len() < 2 {
        let mut whole = slow::run_slow(spec, y0, cancel)?;
        whole.split.n_pieces = 1;
        return Ok(whole);
    }
    run_cut(spec, y0, cancel, &pieces, warmup)
}

/// [`run_in_pieces`] with its cut given: `pieces` (first orbit, orbits), each after the first
/// warmed up over `warmup` orbits.
fn run_cut(
    spec: &OrbitRunSpec,
    y0: Vector4<f64>,
    cancel: &Cancel,
    pieces: &[(u64, u64)],
    warmup: u64,
) -> Result<Propagated<4>> {
    let (first, later) = pieces.split_first().expect("a cut has at least one piece");
    let (first_run, warmed): (_, Vec<Warmed>) = rayon::join(
        || slow::run_slow(&part(spec, first.0, first.1), y0, cancel),
        || {
            // One piece a task: pieces of equal cost then share out evenly to the last one
            // (rayon's own split left one core idle for up to a piece at the end).
            later
                .par_iter()
                .with_max_len(1)
                .map(|&(first, n)| {
                    // From the run's own start state, `warmup` orbits early.
                    let warm = slow::run_slow(&part(spec, first - warmup, warmup), y0, cancel);
                    match warm {
                        Ok(w) if !w.run.stats.stopped => {
                            let start = w.run.y_end;
                            Some((start, slow::run_slow(&part(spec, first, n), start, cancel)))
                        }
                        _ => None,
                    }
                })
                .collect()
        },
    );
    let mut out = first_run?;
    for (piece, &(first, n)) in warmed.into_iter().zip(later) {
        cancel.check()?;
        if out.run.stats.stopped {
            break;
        }
        let end = out.run.y_end;
        // The largest dynamic part of the orbit that ends there: the ringing's scale.
        let ring = out.run.summaries.last().map_or(0.0, |s| s.jitter_peak);
        let done = match piece {
            Some((start, Ok(p))) if agrees(spec, &start, &end, ring) => p,
            // A start that does not agree, or a piece that failed from it: in order, from the
            // end of the piece before.
            _ => {
                let mut p = slow::run_slow(&part(spec, first, n), end, cancel)?;
                p.split.n_pieces_rerun += 1;
                p
            }
        };
        out = joined(out, done);
        out.split.n_warmup_orbits += warmup;
    }
    out.split.n_pieces = pieces.len() as u64;
    Ok(out)
}

/// Two consecutive runs as one: the summaries in order, the counters added, the later end.
fn joined(mut a: Propagated<4>, b: Propagated<4>) -> Propagated<4> {
    let (ra, rb) = (&mut a.run, b.run);
    ra.summaries.extend(rb.summaries);
    ra.stats.n_steps += rb.stats.n_steps;
    ra.stats.n_rejected += rb.stats.n_rejected;
    ra.stats.n_rhs += rb.stats.n_rhs;
    ra.stats.t_end = rb.stats.t_end;
    ra.stats.stopped = rb.stats.stopped;
    ra.y_end = rb.y_end;
    ra.crossing = ra.crossing.or(rb.crossing);
    a.split.add(&b.split);
    a
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inputs::orbit::Orbit;
    use crate::inputs::panel::Panel;
    use crate::models::hinge::HingeModel;
    use crate::runs::orbits::start_state;

    /// A run of the linear hinge, as slow time's own tests ask for one.
    fn spec(panel: Panel, orbit: Orbit, n: u64) -> OrbitRunSpec {
        crate::runs::hybrid::slow::tests::spec(panel, orbit, HingeModel::Linear, n)
    }

    #[test]
    fn the_pieces_cover_the_run_in_order() {
        let s = spec(Panel::paper(), Orbit::leo(540e3), 10_001);
        let (pieces, warmup) = layout(&s);
        // Five pieces' worth, in a whole number of rounds.
        assert_eq!(pieces.len(), 4);
        assert!((2..PIECE_ORBITS / 10).contains(&warmup), "{warmup}");
        let mut next = 0;
        for (k, &(first, n)) in pieces.iter().enumerate() {
            assert_eq!(first, next);
            // The same cost each, warm-ups counted, to an orbit.
            let cost = n + if k == 0 { 0 } else { warmup };
            let first_cost = pieces[0].1;
            assert!(cost.abs_diff(first_cost) <= 1, "{cost} {first_cost}");
            assert!(cost >= PIECE_ORBITS);
            next += n;
        }
        assert_eq!(next, 10_001);
        // A decade of a low orbit: 27 pieces' worth, 24 pieces.
        assert_eq!(
            layout(&spec(Panel::paper(), Orbit::leo(540e3), 55_110))
                .0
                .len(),
            24
        );
        // Short runs and undamped hinges run whole.
        assert_eq!(
            layout(&spec(Panel::paper(), Orbit::leo(540e3), 3999))
                .0
                .len(),
            1
        );
        let undamped = Panel {
            damping: 0.0,
            ..Panel::paper()
        };
        assert_eq!(
            layout(&spec(undamped, Orbit::leo(540e3), 10_000)).0.len(),
            1
        );
    }

    #[test]
    fn the_warmup_shrinks_the_ringing_by_its_factor() {
        let s = spec(Panel::paper(), Orbit::leo(540e3), 10_000);
        let w = warmup_orbits(&s).unwrap() as f64;
        let decay = |orbits: f64| {
            (-WARMUP_RATE * 0.5 * s.panel.damping_rate() * orbits * s.orbit.period).exp()
        };
        assert!(decay(w) <= WARMUP_DECAY && decay(w - 1.0) > WARMUP_DECAY);
    }

    /// A run in pieces is the run in one piece: every summary within 1e-3 of the accuracy gate
    /// (2 %, or 1e-6 rad below 5e-5 rad) of it. (Not to the bit: the pieces' orbits start at
    /// times rounded apart by ~2e-9 s, and slow time's read of a cylindrical shadow's ringing
    /// moves by ~1e-7 rad from one orbit to the next of the same run.)
    #[test]
    fn a_run_in_pieces_is_the_run_whole() {
        let s = spec(Panel::paper(), Orbit::leo(540e3), 2 * PIECE_ORBITS + 7);
        let y0 = start_state(&s.panel, &s.orbit, s.coupling, s.t_start).unwrap();
        let whole = slow::run_slow(&s, y0, &Cancel::new()).unwrap();
        let cut = run_in_pieces(&s, y0, &Cancel::new()).unwrap();
        assert_eq!(cut.split.n_pieces, 2);
        assert_eq!(cut.split.n_pieces_rerun, 0);
        assert_eq!(cut.split.n_warmup_orbits, layout(&s).1);
        assert_eq!(cut.split.n_slow_steps, whole.split.n_slow_steps);
        assert_eq!(cut.run.summaries.len(), whole.run.summaries.len());
        let mut worst: f64 = 0.0;
        for (a, b) in whole.run.summaries.iter().zip(&cut.run.summaries) {
            assert_eq!(a.index, b.index);
            for (x, y) in [
                (a.theta_max, b.theta_max),
                (a.theta_min, b.theta_min),
                (a.amplitude, b.amplitude),
                (a.jitter_rms, b.jitter_rms),
                (a.jitter_peak, b.jitter_peak),
                (a.entry_theta_min, b.entry_theta_min),
                (a.exit_theta_max, b.exit_theta_max),
            ] {
                let gate = if x.abs() < 5e-5 { 1e-6 } else { 0.02 * x.abs() };
                worst = worst.max((x - y).abs() / gate);
            }
        }
        assert!(worst < 1e-3, "{worst:e}");
        assert!((whole.run.y_end - cut.run.y_end).abs().max() < 1e-9);
    }

    /// A piece whose warmed-up start misses the end of the piece before runs again from that
    /// end: here a warm-up of two orbits, which leaves the hinge's ringing unforgotten.
    #[test]
    fn a_piece_that_misses_its_start_runs_again_in_order() {
        let s = spec(Panel::paper(), Orbit::leo(540e3), 300);
        let y0 = start_state(&s.panel, &s.orbit, s.coupling, s.t_start).unwrap();
        let pieces = [(0, 100), (100, 100), (200, 100)];
        let cut = run_cut(&s, y0, &Cancel::new(), &pieces, 2).unwrap();
        assert_eq!(cut.split.n_pieces_rerun, 2);
        assert_eq!(cut.split.n_warmup_orbits, 4);
        let whole = slow::run_slow(&s, y0, &Cancel::new()).unwrap();
        assert_eq!(cut.split.n_slow_steps, whole.split.n_slow_steps);
        for (a, b) in whole.run.summaries.iter().zip(&cut.run.summaries) {
            let gate = 0.02 * a.theta_min.abs();
            assert!(
                (a.theta_min - b.theta_min).abs() < 1e-3 * gate,
                "{a:?} {b:?}"
            );
        }
        // With the warm-up of the run's own cut the starts agree.
        let (_, warmup) = layout(&spec(Panel::paper(), Orbit::leo(540e3), 2 * PIECE_ORBITS));
        let cut = run_cut(&s, y0, &Cancel::new(), &pieces[..2], warmup).unwrap();
        assert_eq!(cut.split.n_pieces_rerun, 0);
    }
}
