//! Each axis' gain and phase margins on the report card (issue 39 item 3): **computed** from the
//! law's linear form on the scene's linear plant ([`crate::linear`], the loop of the axis broken
//! where the plant measures it, every other axis closed), where the law has a linear form, and
//! **measured** from the sensitivity the plant measured through the loop, `L = 1/S − 1` at each
//! measured frequency, for every law (a controller process or an FMU is measured only).
//!
//! The measured margins are read between the measured frequencies (`[f_min, f_max]` of the
//! sensitivity part, log-spaced and refined around the peak): a crossing is located by linear
//! interpolation in `ln f` between the two points that bracket it, so it is as fine as the
//! grid there. A crossing outside the band is not measured: an AMB's open loop is unstable, and
//! its lowest phase crossover (the gain may fall by that much) is at DC, which only the
//! computed margins give.

use super::sensitivity::AxisResult;
use crate::config::Scene;
use crate::linear::{self, margins::AxisMargins as Computed};
use nalgebra::Complex;
use serde::Serialize;

type C64 = Complex<f64>;

/// A gain margin and a phase margin with their frequencies.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Margins {
    /// Gain margin (dB) nearest 0 dB: negative, the gain may fall by that much; positive, rise.
    pub gain_margin_db: Option<f64>,
    /// Its frequency (Hz).
    pub gain_margin_hz: Option<f64>,
    /// The smallest phase margin (degrees).
    pub phase_margin_deg: Option<f64>,
    /// Its frequency (Hz).
    pub phase_margin_hz: Option<f64>,
}

/// One axis at one speed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AxisMargins {
    /// Axis name.
    pub axis: String,
    /// Rotor speed (Hz).
    pub speed_hz: f64,
    /// From the law's linear form on the linear plant (`None`: the law has none).
    pub computed: Option<Margins>,
    /// From the measured sensitivity (`None`: an unstable loop, not measured).
    pub measured: Option<Margins>,
    /// The computed open loop `G_o` on [`OPEN_LOOP_POINTS`] log-spaced frequencies, `(f (Hz),
    /// G_o)`, for the report's Bode and Nyquist charts (`super::loop_charts`); empty where the
    /// law has no linear form. Not in `report.json`.
    #[serde(skip)]
    pub open_loop: Vec<(f64, C64)>,
    /// The law's own poles outside the unit circle (its linear form's; 0 without one): an
    /// unstable controller, which the report says. Not in `report.json`.
    #[serde(skip)]
    pub law_unstable_poles: usize,
}

/// Points of the computed open loop drawn on the charts.
pub const OPEN_LOOP_POINTS: usize = 600;

/// The margins of every measured axis of `scene`'s loop.
pub fn of(scene: &Scene, measured: &[AxisResult]) -> Vec<AxisMargins> {
    let law = linear::law::of(scene);
    let names = super::axis_names(scene);
    type AtSpeed = (f64, Vec<Computed>, Vec<Vec<(f64, C64)>>);
    let mut computed_at: Vec<AtSpeed> = Vec::new();
    // The charts' band: the measured one, widened a decade each way (cut at a sampled law's
    // Nyquist frequency).
    let lo = measured.iter().flat_map(|x| x.points.first()).map(|p| p.f_hz).fold(f64::INFINITY, f64::min);
    let hi = measured.iter().flat_map(|x| x.points.last()).map(|p| p.f_hz).fold(0.0, f64::max);
    let (lo, hi) = if lo.is_finite() && hi > lo { (lo / 10.0, hi * 10.0) } else { (1.0, 1e4) };
    let hi = law.as_ref().and_then(|l| l.period()).map_or(hi, |t| hi.min(0.499 / t));
    let freqs: Vec<f64> =
        (0..OPEN_LOOP_POINTS).map(|i| lo * (hi / lo).powf(i as f64 / (OPEN_LOOP_POINTS - 1) as f64)).collect();
    let mut open_loop = Vec::new();
    let unstable = law.as_ref().map_or(0, |l| l.unstable_poles());
    measured
        .iter()
        .map(|x| {
            open_loop = Vec::new();
            let computed = law.as_ref().and_then(|law| {
                if !computed_at.iter().any(|(s, _, _)| *s == x.speed_hz) {
                    let m = linear::build(scene, x.speed_hz).ok().map(|b| {
                        let (lo, hi) = linear::MARGIN_BAND_HZ;
                        let curves = linear::margins::open_loops(law, &b.plant.system, &b.discrete.0, &freqs);
                        let curves = curves.into_iter().map(|c| freqs.iter().copied().zip(c).collect()).collect();
                        (linear::margins::margins(law, &b.plant.system, &b.discrete.0, lo, hi), curves)
                    });
                    let (m, curves) = m.unwrap_or_default();
                    computed_at.push((x.speed_hz, m, curves));
                }
                let (_, all, curves) = computed_at.iter().find(|(s, _, _)| *s == x.speed_hz)?;
                let k = names.iter().position(|n| *n == x.axis)?;
                open_loop = curves.get(k).cloned().unwrap_or_default();
                all.get(k).map(|m| Margins {
                    gain_margin_db: m.gain_margin_db.map(|g| g.0),
                    gain_margin_hz: m.gain_margin_db.map(|g| g.1),
                    phase_margin_deg: m.phase_margin_deg.map(|p| p.0),
                    phase_margin_hz: m.phase_margin_deg.map(|p| p.1),
                })
            });
            let points: Vec<(f64, C64)> =
                x.points.iter().map(|p| (p.f_hz, C64::new(p.s[0], p.s[1]))).filter(|(_, s)| s.norm() > 0.0).collect();
            let measured = (x.stable && points.len() >= 2).then(|| measured_margins(&points));
            AxisMargins {
                axis: x.axis.clone(),
                speed_hz: x.speed_hz,
                computed,
                measured,
                open_loop: open_loop.clone(),
                law_unstable_poles: unstable,
            }
        })
        .collect()
}

/// The margins of the open loop `L = 1/S − 1` read between the measured points `(f, S)`
/// (ascending in `f`): crossings by linear interpolation in `ln f` (module doc).
pub fn measured_margins(points: &[(f64, C64)]) -> Margins {
    let open: Vec<(f64, C64)> = points.iter().map(|(f, s)| (f.ln(), C64::new(1.0, 0.0) / s - 1.0)).collect();
    let mut phase: Vec<(f64, f64)> = Vec::new(); // (f, 1/|L|)
    let mut gain: Vec<(f64, f64)> = Vec::new(); // (f, 180 + arg L)
    let arg = |l: C64| {
        let a = l.im.atan2(l.re).to_degrees();
        if a > 0.0 {
            a - 360.0
        } else {
            a
        }
    };
    for w in open.windows(2) {
        let ((la, p), (lb, q)) = (w[0], w[1]);
        if p.im.signum() != q.im.signum() && p.re < 0.0 && q.re < 0.0 {
            let t = p.im / (p.im - q.im);
            let at = p + (q - p) * t;
            phase.push(((la + t * (lb - la)).exp(), 1.0 / at.norm()));
        }
        let (a, b) = (p.norm() - 1.0, q.norm() - 1.0);
        if a.signum() != b.signum() {
            let t = a / (a - b);
            let at = p + (q - p) * t;
            gain.push(((la + t * (lb - la)).exp(), 180.0 + arg(at)));
        }
    }
    let db = |m: f64| 20.0 * m.log10();
    let gm = phase.iter().min_by(|x, y| db(x.1).abs().total_cmp(&db(y.1).abs()));
    let pm = gain.iter().min_by(|x, y| x.1.abs().total_cmp(&y.1.abs()));
    Margins {
        gain_margin_db: gm.map(|g| db(g.1)),
        gain_margin_hz: gm.map(|g| g.0),
        phase_margin_deg: pm.map(|p| p.1),
        phase_margin_hz: pm.map(|p| p.0),
    }
}

/// The margins in words for the report: `PM 32.1° at 46.9 Hz, GM −10.4 dB at 0.01 Hz`.
pub fn words(m: &Margins) -> String {
    let pm = match (m.phase_margin_deg, m.phase_margin_hz) {
        (Some(p), Some(f)) => format!("PM {p:.1}° at {f:.1} Hz"),
        _ => "PM none in the band".into(),
    };
    let gm = match (m.gain_margin_db, m.gain_margin_hz) {
        // The band's lower end: the open loop is real there (a PD's at DC).
        (Some(g), Some(f)) if f <= crate::linear::MARGIN_BAND_HZ.0 => format!("GM {g:+.1} dB at DC"),
        (Some(g), Some(f)) => format!("GM {g:+.1} dB at {f:.2} Hz"),
        _ => "GM none in the band".into(),
    };
    format!("{pm}, {gm}")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An open loop `L(f) = √(50/f) · e^{jφ(f)}`, `φ` falling from −150° at 50 Hz by 30° per
    /// factor 4 in frequency: |L| falls through 1 at 50 Hz with the phase −150° there (a phase
    /// margin of 30°), and the phase passes −180° at 200 Hz where |L| = 0.5 (a gain margin of
    /// +6.02 dB). The measured margins read them back from `S = 1/(1 + L)` on a log grid.
    #[test]
    fn the_margins_are_read_back_from_the_sensitivity() {
        let l = |f: f64| {
            let mag = (50.0_f64 / f).powf(0.5);
            let phase = -150.0 - 30.0 * (f / 50.0).ln() / (4.0_f64).ln();
            C64::from_polar(mag, phase.to_radians())
        };
        let freqs: Vec<f64> = (0..=400).map(|i| 10.0 * (1000.0_f64 / 10.0).powf(i as f64 / 400.0)).collect();
        let points: Vec<(f64, C64)> = freqs.iter().map(|&f| (f, C64::new(1.0, 0.0) / (l(f) + 1.0))).collect();
        let m = measured_margins(&points);
        let (pm, pf) = (m.phase_margin_deg.unwrap(), m.phase_margin_hz.unwrap());
        assert!((pm - 30.0).abs() < 0.05 && (pf - 50.0).abs() < 0.2, "{m:?}");
        let (gm, gf) = (m.gain_margin_db.unwrap(), m.gain_margin_hz.unwrap());
        assert!((gm - 20.0 * 2.0_f64.log10()).abs() < 0.02 && (gf - 200.0).abs() < 0.5, "{m:?}");
        assert_eq!(words(&m), format!("PM {pm:.1}° at {pf:.1} Hz, GM {gm:+.1} dB at {gf:.2} Hz"));
    }
}
