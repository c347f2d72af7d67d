//! The probe: the loop left to decay freely from an offset, its decay rate and dominant
//! frequency read from the free response, and whether the loop is stable.

use super::{Measure, Phase, Signal};
use nalgebra::{DMatrix, DVector};
use std::f64::consts::TAU;

/// The decay rate σ (1/s) and the dominant frequency (Hz) of a free response `(t, u)`, after
/// removing its mean and, at speed, its component at the rotation frequency: a straight line
/// through the logarithm of the block envelopes (blocks of two periods of the dominant
/// frequency), over the blocks above 1e-4 of the first one.
pub fn decay(samples: &[(f64, f64)], speed_hz: f64) -> (f64, f64) {
    if samples.len() < 16 {
        return (f64::NAN, f64::NAN);
    }
    let n = if speed_hz > 0.0 { 3 } else { 1 };
    let mut normal = DMatrix::<f64>::zeros(n, n);
    let mut rhs = DVector::<f64>::zeros(n);
    let basis = |t: f64| {
        let mut v = vec![1.0];
        if speed_hz > 0.0 {
            let w = TAU * speed_hz * t;
            v.extend([w.cos(), w.sin()]);
        }
        DVector::from_vec(v)
    };
    // The fit of the steady part over the second half (where the decay has mostly gone).
    for (t, u) in &samples[samples.len() / 2..] {
        let b = basis(*t);
        normal += &b * b.transpose();
        rhs += &b * *u;
    }
    let fit = normal.lu().solve(&rhs).unwrap_or_else(|| DVector::zeros(n));
    let r: Vec<(f64, f64)> = samples.iter().map(|(t, u)| (*t, u - basis(*t).dot(&fit))).collect();
    // Dominant frequency from the zero crossings of the first half.
    let half = &r[..r.len() / 2];
    let crossings: Vec<f64> = half.windows(2).filter(|w| w[0].1 * w[1].1 < 0.0).map(|w| w[0].0).collect();
    let span = r.last().map_or(0.0, |x| x.0) - r[0].0;
    let f_d = if crossings.len() >= 3 {
        (crossings.len() - 1) as f64 / (2.0 * (crossings[crossings.len() - 1] - crossings[0]))
    } else {
        1.0 / span.max(1e-9)
    };
    let block = (2.0 / f_d).max(span / 200.0).min(span / 8.0);
    let mut env: Vec<(f64, f64)> = Vec::new();
    let mut start = r[0].0;
    let mut peak: f64 = 0.0;
    for (t, u) in &r {
        if *t >= start + block {
            env.push((start + 0.5 * block, peak));
            start += block;
            peak = 0.0;
        }
        peak = peak.max(u.abs());
    }
    let Some(first) = env.first().map(|e| e.1) else { return (f64::NAN, f_d) };
    let used: Vec<(f64, f64)> = env.iter().skip(1).filter(|e| e.1 > 1e-4 * first && e.1 > 0.0).copied().collect();
    if used.len() < 3 {
        // Gone within a few blocks: a fast decay; its rate from the first block down to 1e-4.
        return ((1e4f64).ln() / (block * 3.0), f_d);
    }
    let m = used.len() as f64;
    let (sx, sy) = used.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y.ln()));
    let (mx, my) = (sx / m, sy / m);
    let (sxy, sxx) =
        used.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + (x - mx) * (y.ln() - my), b + (x - mx).powi(2)));
    (-sxy / sxx, f_d)
}

impl Measure<'_> {
    /// The probe ends at `t`: the loop is stable or not, and the excitation starts (the
    /// multisine where it applies, else the stepped sine).
    pub(super) fn finish_probe(&mut self, t: f64) {
        let (sigma, f_d) = decay(&self.probe, self.speed_hz);
        self.sigma = sigma;
        self.probe_hz = f_d;
        if sigma.is_nan() || sigma <= 0.0 {
            self.stable = Some(false);
            self.note = Some(format!(
                "the free decay from {:.1} µm does not decay: its envelope grows at {:.3} 1/s (about {:.1} Hz)",
                self.settings.probe_um, -sigma, f_d
            ));
            self.phase = Phase::Done;
            return;
        }
        self.stable = Some(true);
        self.t_now = t;
        let multi = self.discrete && self.settings.auto_level && self.settings.excitation == Signal::Multisine;
        if multi && self.queue.len() >= 2 {
            let tones: Vec<f64> = self.queue.drain(..).collect();
            let a = self.settings.excitation_um.min(self.settings.response_um) * 1e-6 * self.sensor_gain
                / (tones.len() as f64).sqrt();
            self.start_multi(tones, a, t);
        } else {
            self.next_step(t);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_decay_of_a_damped_sine_with_an_unbalance_line() {
        let (sigma, f) = (2.95, 47.0);
        let s: Vec<(f64, f64)> = (0..20_000)
            .map(|k| {
                let t = k as f64 * 5e-5;
                (t, 1.0 + (-sigma * t).exp() * (TAU * f * t).cos() + 0.05 * (TAU * 500.0 * t + 0.3).sin())
            })
            .collect();
        let (got, fd) = decay(&s, 500.0);
        assert!((got / sigma - 1.0).abs() < 0.05, "σ = {got}");
        assert!((fd / f - 1.0).abs() < 0.02, "f = {fd}");
        let grow: Vec<(f64, f64)> = s.iter().map(|(t, _)| (*t, (0.5 * t).exp() * (TAU * f * t).sin())).collect();
        assert!(decay(&grow, 0.0).0 < 0.0);
    }
}
