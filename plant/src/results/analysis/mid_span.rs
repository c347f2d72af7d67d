//! A bending rotor's mid-span (the trace's `mid_dx_m`, `mid_dy_m`): how far it goes, and how far
//! the shaft bows there, off the straight line through the rotor at its two touchdown bearings.
//!
//! With `p_A`, `p_B` the rotor at the touchdown bearings and `p_m` at mid-span (each relative to
//! the housing), and `w = (z_m − z_A) / (z_B − z_A)` the mid-span node's place between them, the
//! bow is
//!
//! ```text
//! |p_m − (p_A + w (p_B − p_A))|
//! ```
//!
//! zero for a rigid rotor whatever it does. As the run's other maxima, a row at or after a
//! failure's time is left out ([`MidSpanAnalyzer::finish`]).

use crate::trace::Record;
use serde::Serialize;

/// The mid-span's figures in `summary.json` (`mid_span`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MidSpan {
    /// Largest radius of the rotor at mid-span relative to the housing (m).
    pub max_radius_m: f64,
    /// When (s).
    pub max_radius_time_s: f64,
    /// Largest bow: the rotor at mid-span off the line through the rotor at the two touchdown
    /// bearings (m).
    pub max_bow_m: f64,
    /// When (s).
    pub max_bow_time_s: f64,
}

/// Builds [`MidSpan`] from a run's samples.
#[derive(Clone, Debug)]
pub struct MidSpanAnalyzer {
    /// `w`: the mid-span node's place between the touchdown nodes (0 at A, 1 at B).
    weight: f64,
    /// The figures over the rows taken so far (`None` before the first).
    figures: Option<MidSpan>,
    /// The last row's `(t, radius, bow)`, not yet taken (it may be a failure's).
    pending: Option<[f64; 3]>,
}

impl MidSpanAnalyzer {
    /// For a rotor whose mid-span node lies at `weight` between its touchdown nodes.
    pub fn new(weight: f64) -> Self {
        Self { weight, figures: None, pending: None }
    }

    /// The next sample; a row without the mid-span's columns (a trace written before them) adds
    /// nothing.
    pub fn push(&mut self, r: &Record) {
        let Some(m) = r.mid else { return };
        let (a, b) = (r.plane(0), r.plane(1));
        let at = |a: f64, b: f64| a + self.weight * (b - a);
        let line = [at(a.motion.dx_m, b.motion.dx_m), at(a.motion.dy_m, b.motion.dy_m)];
        let bow = (m.mid_dx_m - line[0]).hypot(m.mid_dy_m - line[1]);
        if let Some(p) = self.pending.replace([r.a.t_s, m.mid_dx_m.hypot(m.mid_dy_m), bow]) {
            self.take(p);
        }
    }

    fn take(&mut self, [t, radius, bow]: [f64; 3]) {
        // A non-finite row (a diverging run's) raises no maximum.
        if !(radius.is_finite() && bow.is_finite()) {
            return;
        }
        let f = self.figures.get_or_insert(MidSpan {
            max_radius_m: radius,
            max_radius_time_s: t,
            max_bow_m: bow,
            max_bow_time_s: t,
        });
        if radius > f.max_radius_m {
            (f.max_radius_m, f.max_radius_time_s) = (radius, t);
        }
        if bow > f.max_bow_m {
            (f.max_bow_m, f.max_bow_time_s) = (bow, t);
        }
    }

    /// The figures, the last row left out if it is at or after `failure_time` (s); `None` if no
    /// row had the mid-span's columns, or none was finite (a non-finite row raises no maximum).
    pub fn finish(mut self, failure_time: Option<f64>) -> Option<MidSpan> {
        if let Some(p) = self.pending.take() {
            if failure_time.is_none_or(|f| p[0] < f) {
                self.take(p);
            }
        }
        self.figures
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::{Mid, Row, RowB};

    /// A sample at `t` with the rotor at `a` (touchdown A), `b` (touchdown B) and `m` (mid-span).
    fn sample(t: f64, a: [f64; 2], b: [f64; 2], m: [f64; 2]) -> Record {
        let mut ra = Row { t_s: t, ..Row::default() };
        ra.motion.dx_m = a[0];
        ra.motion.dy_m = a[1];
        let mut rb = RowB::default();
        rb.motion.dx_m = b[0];
        rb.motion.dy_m = b[1];
        let mid = Mid { mid_dx_m: m[0], mid_dy_m: m[1] };
        Record { a: ra, b: Some(rb), hw: None, magnets: None, mid: Some(mid) }
    }

    /// A straight rotor has no bow however it moves; a bent one bows by its distance from the
    /// line at the mid-span node's place; the largest radius and bow are taken with their
    /// times; the last row is left out at a failure's time, kept before it.
    #[test]
    fn the_bow_is_measured_from_the_line_through_the_journals() {
        let mut m = MidSpanAnalyzer::new(0.25);
        m.push(&sample(-0.1, [0.0, 0.0], [0.0, 0.0], [f64::NAN, 0.0])); // no maximum
        m.push(&sample(0.0, [4e-6, 0.0], [8e-6, 4e-6], [5e-6, 1e-6])); // on the line
        m.push(&sample(0.1, [0.0, 0.0], [0.0, 0.0], [3e-6, -4e-6])); // bowed by 5 µm
        m.push(&sample(0.2, [0.0, 2e-5], [0.0, 2e-5], [0.0, 2e-5])); // farther, straight
        m.push(&sample(0.3, [0.0, 0.0], [0.0, 0.0], [f64::NAN, 1.0])); // a failure's row
        let f = m.clone().finish(Some(0.3)).expect("figures");
        assert!((f.max_bow_m - 5e-6).abs() < 1e-18, "{f:?}");
        assert_eq!((f.max_bow_time_s, f.max_radius_m, f.max_radius_time_s), (0.1, 2e-5, 0.2));
        // Taken when the run did not fail there: a non-finite row raises no maximum.
        assert_eq!(m.finish(None), Some(f));
        // A trace without the mid-span's columns.
        let mut none = MidSpanAnalyzer::new(0.5);
        let mut r = sample(0.0, [0.0; 2], [0.0; 2], [0.0; 2]);
        r.mid = None;
        none.push(&r);
        assert_eq!(none.finish(None), None);
    }
}
