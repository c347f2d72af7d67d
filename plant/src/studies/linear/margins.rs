//! Each axis' gain and phase margins from the law's linear form on the linear plant (issue 39
//! item 3, the computed half): a pure function of the loop's sensitivity.
//!
//! The loop of axis `k` is taken where `plant assess` measures it, with every other axis' loop
//! closed: from `S_kk = 1 / (1 + G_o)` ([`super::law::sensitivity`], ISO 14839-3's form),
//! `G_o = 1 / S_kk − 1`, the open loop of the usual negative-feedback form, which a measured
//! sensitivity gives the same way (`L = 1/S − 1` of the issue). On one decoupled axis (the
//! planar rotor) `G_o = −P C`.
//!
//! * **Phase crossovers**: where `G_o` crosses the negative real axis; the gain margin there is
//!   `1 / |G_o|`. An AMB's open loop is unstable (the negative stiffness), so its Nyquist plot
//!   starts on the negative real axis at `|G_o| > 1`: the gain may fall by that margin (below
//!   1, a negative number of dB) as well as rise by one above 1 (at the crossing the delay and
//!   the sampling make). Both are listed; the margin said is the one nearest 0 dB, as
//!   python-control's `stability_margins` says it.
//! * **Gain crossovers**: where `|G_o| = 1`; the phase margin there is `180° + arg G_o`
//!   (`arg` in `(−360°, 0°]`). The margin said is the smallest.
//!
//! Found on a log grid of the band, each crossing refined by bisection in `ln f`; the DC end
//! (`f → 0`, where a PD's `G_o` is real) is the band's lower end `f_min`, taken when `G_o` is
//! within 1° of the negative real axis there (give an `f_min` well below the loop's modes).

use super::law::{self, LinearLaw};
use super::model::System;
use nalgebra::Complex;

type C64 = Complex<f64>;

/// One crossing: its frequency (Hz) and the margin there (a gain ratio, or degrees).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Crossing {
    /// Frequency (Hz).
    pub f_hz: f64,
    /// The margin: `1 / |G_o|` at a phase crossover, `180° + arg G_o` (degrees) at a gain one.
    pub margin: f64,
}

/// One axis' margins.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct AxisMargins {
    /// Axis index (the plant's input and output order).
    pub axis: usize,
    /// Every phase crossover in the band, ascending in frequency (the lower end's when `G_o`
    /// is real and negative there).
    pub phase_crossovers: Vec<Crossing>,
    /// Every gain crossover in the band, ascending.
    pub gain_crossovers: Vec<Crossing>,
    /// The gain margin nearest 0 dB (dB; negative: a reduction of the gain), and its frequency.
    pub gain_margin_db: Option<(f64, f64)>,
    /// The smallest phase margin (degrees), and its frequency.
    pub phase_margin_deg: Option<(f64, f64)>,
}

/// Points of the log grid the crossings are first looked for on.
const GRID: usize = 2000;

/// The margins of every axis of the loop `law` closes on the plant (`continuous`, or
/// `discrete` for a sampled law) over `[f_min, f_max]` (Hz; a sampled law's band is cut at
/// 0.499 of its rate).
pub fn margins(law: &LinearLaw, continuous: &System, discrete: &System, f_min: f64, f_max: f64) -> Vec<AxisMargins> {
    let f_max = match law.period() {
        Some(period) => f_max.min(0.499 / period),
        None => f_max,
    };
    let axes = continuous.b.ncols();
    let g = |f: f64| -> Vec<C64> {
        let s = law::sensitivity(law, continuous, discrete, f);
        (0..axes).map(|k| C64::new(1.0, 0.0) / s[(k, k)] - 1.0).collect()
    };
    let (a, b) = (f_min.ln(), f_max.ln());
    let grid: Vec<f64> = (0..=GRID).map(|i| a + (b - a) * i as f64 / GRID as f64).collect();
    let values: Vec<Vec<C64>> = grid.iter().map(|lf| g(lf.exp())).collect();
    (0..axes)
        .map(|k| {
            let at = |lf: f64| g(lf.exp())[k];
            let mut phase = Vec::new();
            let mut gain = Vec::new();
            let first = values[0][k];
            // The DC end: a PD's `G_o` tends to the negative real axis as `f → 0`; within 1° of it
            // at `f_min` the crossing is taken there.
            if first.re < 0.0 && first.im.abs() < (1f64).to_radians().sin() * first.norm() {
                phase.push(Crossing { f_hz: f_min, margin: 1.0 / first.norm() });
            }
            for i in 1..grid.len() {
                let (p, q) = (values[i - 1][k], values[i][k]);
                // The negative real axis: Im changes sign with Re < 0 on both sides.
                if p.im.signum() != q.im.signum() && p.re < 0.0 && q.re < 0.0 {
                    let lf = bisect(grid[i - 1], grid[i], &|lf| at(lf).im, p.im);
                    phase.push(Crossing { f_hz: lf.exp(), margin: 1.0 / at(lf).norm() });
                }
                if (p.norm() - 1.0).signum() != (q.norm() - 1.0).signum() {
                    let lf = bisect(grid[i - 1], grid[i], &|lf| at(lf).norm() - 1.0, p.norm() - 1.0);
                    let v = at(lf);
                    let arg = v.im.atan2(v.re).to_degrees();
                    let arg = if arg > 0.0 { arg - 360.0 } else { arg };
                    gain.push(Crossing { f_hz: lf.exp(), margin: 180.0 + arg });
                }
            }
            let db = |c: &Crossing| 20.0 * c.margin.log10();
            let gain_margin_db =
                phase.iter().min_by(|x, y| db(x).abs().total_cmp(&db(y).abs())).map(|c| (db(c), c.f_hz));
            let phase_margin_deg =
                gain.iter().min_by(|x, y| x.margin.abs().total_cmp(&y.margin.abs())).map(|c| (c.margin, c.f_hz));
            AxisMargins { axis: k, phase_crossovers: phase, gain_crossovers: gain, gain_margin_db, phase_margin_deg }
        })
        .collect()
}

/// Each axis' open loop `G_o = 1 / S_kk − 1` (the margins' loop, every other axis closed) at
/// each of `freqs` (Hz): `[axis][frequency]`, for the report card's Bode and Nyquist charts.
pub fn open_loops(law: &LinearLaw, continuous: &System, discrete: &System, freqs: &[f64]) -> Vec<Vec<C64>> {
    let axes = continuous.b.ncols();
    let mut out = vec![Vec::with_capacity(freqs.len()); axes];
    for &f in freqs {
        let s = law::sensitivity(law, continuous, discrete, f);
        for (k, row) in out.iter_mut().enumerate() {
            row.push(C64::new(1.0, 0.0) / s[(k, k)] - 1.0);
        }
    }
    out
}

/// The root of `h` in `[lo, hi]` where it changes sign (`h(lo)` has the sign of `at_lo`), by
/// bisection to the last bits of `f`.
fn bisect(mut lo: f64, mut hi: f64, h: &dyn Fn(f64) -> f64, at_lo: f64) -> f64 {
    let sign = at_lo.signum();
    // A grid step is 0.007 in ln f: 44 halvings leave 4e-16 of it.
    for _ in 0..44 {
        let mid = 0.5 * (lo + hi);
        if h(mid).signum() == sign {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shipped;
    use std::f64::consts::TAU;

    /// The planar rotor on its continuous PD, by hand: `G_o = −(k_e + k_s + j c_e ω) /
    /// (m ω² + k_s)`; real and negative only at DC, where `1/|G_o| = k_s / (k_e + k_s)` (the
    /// gain may fall that far); `|G_o| = 1` at `m² ω⁴ + (2 m k_s − c_e²) ω² + k_s² − (k_e +
    /// k_s)² = 0`, the phase margin there `atan(c_e ω / (k_e + k_s))`.
    #[test]
    fn the_continuous_pd_margins_are_the_hand_derived_ones() {
        let scene = shipped("paper-10g.toml", &[]);
        let b = super::super::build(&scene, 0.0).expect("model");
        let law = law::of(&scene).expect("law");
        let m = margins(&law, &b.plant.system, &b.discrete.0, 0.01, 1e4);
        // The scene's design: k_e = 1e6 N/m, ξ_e as the scene says, c_e = 2 ξ_e √(k_e m).
        let (mass, ks, ke) = (11.5, 4.32e5, 1e6);
        let g = crate::run::plane_gains(&scene).expect("gains")[0];
        let ce = 216.0 * g.amp_gain_a_per_v * 25_000.0 * g.kd;
        assert!((216.0 * g.amp_gain_a_per_v * 25_000.0 * g.kp - ks - ke).abs() < 1e-6 * ke);
        let (qa, qb, qc) = (mass * mass, 2.0 * mass * ks - ce * ce, ks * ks - (ke + ks) * (ke + ks));
        let w2 = (-qb + (qb * qb - 4.0 * qa * qc).sqrt()) / (2.0 * qa);
        let wc = w2.sqrt();
        let pm = (ce * wc / (ke + ks)).atan().to_degrees();
        for axis in &m {
            let (gm, f0) = axis.gain_margin_db.expect("a phase crossover at DC");
            assert!((gm - 20.0 * (ks / (ke + ks)).log10()).abs() < 1e-6 && f0 == 0.01, "{axis:?}");
            assert_eq!(axis.phase_crossovers.len(), 1, "{axis:?}");
            let (p, fc) = axis.phase_margin_deg.expect("a gain crossover");
            assert!(
                (p - pm).abs() < 1e-9 && (fc / (wc / TAU) - 1.0).abs() < 1e-12,
                "{p}° at {fc} Hz against {pm}° at {} Hz",
                wc / TAU
            );
        }
    }
}
