//! The tilt of a two-plane run: the rotor axis's angle `|(a, b)|` (its slopes, rad) through the
//! run and over the steady window, and how the two bearing planes move against each other
//! there, which tells the cylindrical motion (the planes in phase: the rotor translates) from
//! the conical one (in opposition: it tilts about a point between them).
//!
//! With `ζ_A`, `ζ_B` the rotor's complex displacement `x + j y` at bearings A and B over the
//! steady window, each less its mean, the planes' correlation is
//!
//! ```text
//! ρ = Re Σ ζ_A ζ̄_B / √(Σ |ζ_A|² Σ |ζ_B|²)      ∈ [−1, 1]
//! ```
//!
//! `cylindrical` for `ρ ≥ 0.5`, `conical` for `ρ ≤ −0.5`, `mixed` between, `none` when neither
//! plane moves (a rotor at rest in the window).

use super::{graded_window, AnalysisSpec};
use crate::trace::Record;
use serde::Serialize;
use std::collections::VecDeque;

/// How the planes move together over the steady window.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum WhirlShape {
    /// In phase: the rotor translates (ρ ≥ 0.5).
    Cylindrical,
    /// In opposition: the rotor tilts (ρ ≤ −0.5).
    Conical,
    /// Between the two.
    Mixed,
    /// Neither plane moves.
    None,
}

/// The tilt's figures (`summary.json`, `planes.tilt`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TiltAnalysis {
    /// Largest tilt angle `|(a, b)|` of the rotor axis over the run (rad).
    pub max_tilt_rad: f64,
    /// Largest tilt angle over the steady window (rad).
    pub steady_max_tilt_rad: f64,
    /// The planes' correlation ρ over the steady window (module doc).
    pub steady_plane_correlation: f64,
    /// `cylindrical`, `conical`, `mixed` or `none` (module doc).
    pub steady_whirl_shape: WhirlShape,
}

/// One row of the steady window.
#[derive(Clone, Copy, Debug)]
struct Row {
    t: f64,
    a: [f64; 2],
    b: [f64; 2],
    tilt: f64,
}

/// The tilt analysis, made as the samples come (memory bounded by the steady window).
#[derive(Clone, Debug)]
pub struct TiltAnalyzer {
    spec: AnalysisSpec,
    window: VecDeque<Row>,
    max_tilt: f64,
    /// The first sample's time.
    first: Option<f64>,
}

impl TiltAnalyzer {
    /// An analysis with the steady window of `spec`.
    pub fn new(spec: AnalysisSpec) -> Self {
        Self { spec, window: VecDeque::new(), max_tilt: 0.0, first: None }
    }

    /// The next two-plane sample (a planar one is ignored).
    pub fn push(&mut self, r: &Record) {
        let (Some(slopes), b) = (r.slopes(), r.plane(1)) else { return };
        let tilt = slopes[0].hypot(slopes[1]);
        if tilt.is_finite() {
            self.max_tilt = self.max_tilt.max(tilt);
        }
        let t = r.a.t_s;
        self.first.get_or_insert(t);
        let (a, b) = (&r.a.motion, &b.motion);
        self.window.push_back(Row { t, a: [a.dx_m, a.dy_m], b: [b.dx_m, b.dy_m], tilt });
        let cutoff = t - self.spec.window_length();
        while self.window.front().is_some_and(|w| w.t < cutoff) {
            self.window.pop_front();
        }
    }

    /// The figures of the samples pushed.
    pub fn finish(self) -> TiltAnalysis {
        let end = self.window.back().map_or(0.0, |w| w.t);
        let ([start, _], _) = graded_window(self.first.unwrap_or(0.0), end, &self.spec);
        let rows: Vec<Row> = self.window.into_iter().filter(|w| w.t >= start && w.tilt.is_finite()).collect();
        let n = rows.len().max(1) as f64;
        let mean = |f: &dyn Fn(&Row) -> [f64; 2]| {
            let s = rows.iter().fold([0.0, 0.0], |acc, r| {
                let v = f(r);
                [acc[0] + v[0], acc[1] + v[1]]
            });
            [s[0] / n, s[1] / n]
        };
        let (ma, mb) = (mean(&|r| r.a), mean(&|r| r.b));
        let (mut cross, mut aa, mut bb) = (0.0, 0.0, 0.0);
        for r in &rows {
            let za = [r.a[0] - ma[0], r.a[1] - ma[1]];
            let zb = [r.b[0] - mb[0], r.b[1] - mb[1]];
            cross += za[0] * zb[0] + za[1] * zb[1];
            aa += za[0] * za[0] + za[1] * za[1];
            bb += zb[0] * zb[0] + zb[1] * zb[1];
        }
        let rho = if aa > 0.0 && bb > 0.0 { cross / (aa * bb).sqrt() } else { 0.0 };
        let shape = if aa == 0.0 && bb == 0.0 {
            WhirlShape::None
        } else if rho >= 0.5 {
            WhirlShape::Cylindrical
        } else if rho <= -0.5 {
            WhirlShape::Conical
        } else {
            WhirlShape::Mixed
        };
        TiltAnalysis {
            max_tilt_rad: self.max_tilt,
            steady_max_tilt_rad: rows.iter().map(|r| r.tilt).fold(0.0, f64::max),
            steady_plane_correlation: rho,
            steady_whirl_shape: shape,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::{Record, RowB};

    fn record(t: f64, a: [f64; 2], b: [f64; 2], slopes: [f64; 2]) -> Record {
        let mut ra = crate::trace::Row { t_s: t, ..Default::default() };
        ra.motion.dx_m = a[0];
        ra.motion.dy_m = a[1];
        let mut rb = RowB::default();
        rb.motion.dx_m = b[0];
        rb.motion.dy_m = b[1];
        rb.tilt.slope_x_rad = slopes[0];
        rb.tilt.slope_y_rad = slopes[1];
        Record { a: ra, b: Some(rb), hw: None, magnets: None, mid: None }
    }

    fn shape_of(sign: f64) -> TiltAnalysis {
        let spec = AnalysisSpec { gap: 1.5e-4, speed: 100.0, phase: 0.0, tolerance: 1e-3 };
        let mut t = TiltAnalyzer::new(spec);
        for k in 0..2000 {
            let time = k as f64 * 1e-4;
            let (s, c) = (80.0 * time).sin_cos();
            let a = [10e-6 * c, 10e-6 * s];
            let b = [sign * 8e-6 * c, sign * 8e-6 * s];
            t.push(&record(time, a, b, [(b[0] - a[0]) / 0.36, (b[1] - a[1]) / 0.36]));
        }
        t.finish()
    }

    #[test]
    fn planes_in_phase_are_cylindrical_and_in_opposition_conical() {
        let cyl = shape_of(1.0);
        assert_eq!(cyl.steady_whirl_shape, WhirlShape::Cylindrical);
        assert!((cyl.steady_plane_correlation - 1.0).abs() < 1e-9);
        let con = shape_of(-1.0);
        assert_eq!(con.steady_whirl_shape, WhirlShape::Conical);
        assert!((con.steady_plane_correlation + 1.0).abs() < 1e-9);
        // |a − b| / span: 18 µm / 0.36 m = 50 µrad.
        assert!((con.max_tilt_rad - 50e-6).abs() < 1e-9, "{}", con.max_tilt_rad);
    }
}
