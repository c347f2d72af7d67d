//! `pd_notch`: the delay-aware discrete PD of `pd_delay` behind a notch filter on each sensor
//! axis, the filter every industrial AMB controller carries against a flexible rotor's bending
//! mode.
//!
//! # The notch
//!
//! As ROSS's `notch_filter(w_n, zeta_z, zeta_p)` describes one:
//!
//! ```text
//! H(s) = (s² + 2 ζ_z ω_n s + ω_n²) / (s² + 2 ζ_p ω_n s + ω_n²)
//! ```
//!
//! unity at DC and far above, `ζ_z/ζ_p` at `ω_n`. Its parameters (`[controller.params]`):
//! `frequency_hz` `f_n = ω_n/2π`; `width_hz` `W = 2 ζ_p f_n`, the −3 dB width of the notch (exact
//! for an infinitely deep one, `ζ_z = 0`: its −3 dB edges are `ω_n (√(1 + ζ_p²) ± ζ_p)`);
//! `depth_db` `D`, the attenuation at `f_n`: `ζ_z = ζ_p 10^(−D/20)`.
//!
//! # Sampled
//!
//! Bilinear (Tustin) with the frequency prewarped at the notch,
//! `s = K (1 − z⁻¹)/(1 + z⁻¹)`, `K = ω_n / tan(ω_n T/2)`: the sampled filter's response at a
//! frequency `ω` below Nyquist is the continuous one's at `K tan(ωT/2)`, so the notch's centre
//! and depth are exact at any rate. A second-order section per axis (direct form II
//! transposed), from rest; the PD then acts on the filtered voltages.

use crate::discrete_pd::{DelayPd, DelayPdGains};
use crate::law::{ControlLaw, Design, LawEntry, LawError, Sample};
use crate::params::{Check, Params};
use num_complex::Complex64;

/// `pd_notch`: parameters `frequency_hz` (Hz, > 0, below the rate's Nyquist frequency; default
/// 1000), `width_hz` (Hz, > 0; default 100), `depth_db` (dB, ≥ 0; default 40).
pub const LAW: LawEntry = LawEntry {
    name: "pd_notch",
    summary: "pd_delay behind a notch filter on each sensor axis, as ROSS's notch_filter (params frequency_hz, width_hz, depth_db)",
    build,
};

fn build(design: &Design, params: &Params) -> Result<Box<dyn ControlLaw>, LawError> {
    let mut p = params.reader(LAW.name);
    let spec = NotchSpec {
        frequency_hz: p.number("frequency_hz", "Hz", 1000.0, Check::Positive)?,
        width_hz: p.number("width_hz", "Hz", 100.0, Check::Positive)?,
        depth_db: p.number("depth_db", "dB", 40.0, Check::NonNegative)?,
    };
    let nyquist = 0.5 / design.period_s;
    if spec.frequency_hz >= nyquist {
        return Err(p.error(
            "frequency_hz",
            spec.frequency_hz,
            "Hz",
            format!("must be below the Nyquist frequency of the law's rate, {nyquist} Hz"),
        ));
    }
    let notch = Notch::new(&spec, design.period_s);
    if !notch.is_finite() {
        return Err(p.error(
            "width_hz",
            spec.width_hz,
            "Hz",
            format!("with frequency_hz = {} Hz gives a filter whose coefficients overflow", spec.frequency_hz),
        ));
    }
    p.finish()?;
    let gains = DelayPdGains::from_design(&design.pd(), &design.constants, design.period_s, design.delay_samples)?;
    Ok(Box::new(PdNotch { notch, pd: DelayPd::new(gains, design.period_s) }))
}

/// A notch's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NotchSpec {
    /// Centre f_n (Hz).
    pub frequency_hz: f64,
    /// −3 dB width `W = 2 ζ_p f_n` (Hz).
    pub width_hz: f64,
    /// Attenuation at the centre (dB, ≥ 0).
    pub depth_db: f64,
}

impl NotchSpec {
    /// `(ω_n, ζ_z, ζ_p)`: ROSS's `notch_filter` arguments.
    pub fn ross(&self) -> (f64, f64, f64) {
        let zeta_p = self.width_hz / (2.0 * self.frequency_hz);
        (std::f64::consts::TAU * self.frequency_hz, zeta_p * 10f64.powf(-self.depth_db / 20.0), zeta_p)
    }

    /// The continuous filter's response `H(jω)` at `omega` (rad/s).
    pub fn response(&self, omega: f64) -> Complex64 {
        let (wn, zz, zp) = self.ross();
        let s = Complex64::new(0.0, omega);
        (s * s + s * (2.0 * zz * wn) + wn * wn) / (s * s + s * (2.0 * zp * wn) + wn * wn)
    }
}

/// The sampled notch on two axes.
#[derive(Clone, Debug)]
pub struct Notch {
    b: [f64; 3],
    a: [f64; 2],
    state: [[f64; 2]; 2],
}

impl Notch {
    /// The Tustin notch of `spec` at sampling period `period_s` (s), prewarped at its centre.
    pub fn new(spec: &NotchSpec, period_s: f64) -> Self {
        let (wn, zz, zp) = spec.ross();
        let k = wn / (wn * period_s / 2.0).tan();
        let quadratic = |zeta: f64| {
            [k * k + 2.0 * zeta * wn * k + wn * wn, 2.0 * (wn * wn - k * k), k * k - 2.0 * zeta * wn * k + wn * wn]
        };
        let (n, d) = (quadratic(zz), quadratic(zp));
        Notch { b: [n[0] / d[0], n[1] / d[0], n[2] / d[0]], a: [d[1] / d[0], d[2] / d[0]], state: [[0.0; 2]; 2] }
    }

    /// Every coefficient is finite (an extreme width against its centre overflows them).
    pub fn is_finite(&self) -> bool {
        self.b.iter().chain(&self.a).all(|v| v.is_finite())
    }

    /// Filters one sample of both axes.
    pub fn filter(&mut self, u: [f64; 2]) -> [f64; 2] {
        let mut out = [0.0; 2];
        for (k, (x, s)) in u.iter().zip(&mut self.state).enumerate() {
            let y = self.b[0] * x + s[0];
            s[0] = self.b[1] * x - self.a[0] * y + s[1];
            s[1] = self.b[2] * x - self.a[1] * y;
            out[k] = y;
        }
        out
    }

    /// Back to rest.
    pub fn reset(&mut self) {
        self.state = [[0.0; 2]; 2];
    }
}

/// `pd_notch`: the notch, then `pd_delay`.
#[derive(Clone, Debug)]
pub struct PdNotch {
    notch: Notch,
    pd: DelayPd,
}

impl ControlLaw for PdNotch {
    fn name(&self) -> &'static str {
        LAW.name
    }

    fn update(&mut self, s: &Sample) -> [f64; 2] {
        let filtered = Sample { sensor_v: self.notch.filter(s.sensor_v), ..*s };
        self.pd.update(&filtered)
    }

    fn reset(&mut self) {
        self.notch.reset();
        self.pd.reset();
    }

    fn linear(&self) -> Option<crate::law::LinearLaw> {
        let pd = self.pd.linear_pd()?;
        Some(crate::law::LinearLaw { pd, filter: Some((self.notch.b, self.notch.a)) })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    /// The sampled notch's steady response to a sine, measured by running the filter (amplitude
    /// and phase by projection on the last whole periods).
    fn measured(spec: &NotchSpec, period: f64, hz: f64) -> Complex64 {
        let mut n = Notch::new(spec, period);
        let w = TAU * hz;
        // Settle for many time constants of the notch's poles (1/(ζ_p ω_n)), then measure over
        // whole periods of the input.
        let (wn, _, zp) = spec.ross();
        let settle = (40.0 / (zp * wn) / period) as usize;
        let per = (1.0 / (hz * period)).round().max(1.0);
        let cycles = (2000.0 / per).ceil().max(1.0);
        let count = (per * cycles) as usize;
        let mut acc = Complex64::new(0.0, 0.0);
        for k in 0..settle + count {
            let t = k as f64 * period;
            let y = n.filter([(w * t).sin(), 0.0])[0];
            if k >= settle {
                acc += Complex64::new(0.0, w * t).exp() * y;
            }
        }
        // y = Im(H e^{jωt}) = (H e^{jωt} − conj) / 2j: ⟨y e^{−jωt}⟩ ≈ H/(2j) … use e^{+jωt}: −conj(H)/(2j)
        let mean = acc / count as f64;
        (mean * Complex64::new(0.0, 2.0) * -1.0).conj()
    }

    /// Frequencies that fit whole periods in whole samples at 20 kHz.
    #[test]
    fn sampled_notch_matches_the_closed_form_at_the_prewarped_frequency() {
        let period = 5e-5;
        let spec = NotchSpec { frequency_hz: 500.0, width_hz: 100.0, depth_db: 30.0 };
        let (wn, _, _) = spec.ross();
        let k = wn / (wn * period / 2.0).tan();
        for hz in [50.0, 250.0, 400.0, 500.0, 625.0, 1000.0, 2500.0] {
            let ours = measured(&spec, period, hz);
            let closed = spec.response(k * (TAU * hz * period / 2.0).tan());
            assert!((ours - closed).norm() < 2e-3 * closed.norm().max(0.03), "{hz} Hz: {ours} against {closed}");
        }
        // The centre: exactly the depth (−30 dB) thanks to the prewarping.
        let centre = spec.response(k * (wn * period / 2.0).tan());
        assert!((centre.norm() - 10f64.powf(-1.5)).abs() < 1e-12, "{centre}");
        assert!((measured(&spec, period, 500.0).norm() - 10f64.powf(-1.5)).abs() < 1e-3);
    }

    /// The parameters mean what they say: the closed form is ROSS's with `ζ_p = W/(2 f_n)`,
    /// `ζ_z = ζ_p 10^(−D/20)`; unity at DC and far above, the depth at the centre, and for a
    /// deep notch −3 dB at `ω_n (√(1 + ζ_p²) ± ζ_p)`, edges `W` apart.
    #[test]
    fn notch_parameters_are_centre_width_and_depth() {
        let spec = NotchSpec { frequency_hz: 400.0, width_hz: 80.0, depth_db: 200.0 };
        let (wn, zz, zp) = spec.ross();
        assert!((zp - 0.1).abs() < 1e-15 && (zz - 1e-10 * zp).abs() < 1e-24);
        assert!((spec.response(0.0).norm() - 1.0).abs() < 1e-15);
        assert!((spec.response(1e3 * wn).norm() - 1.0).abs() < 1e-6);
        assert!(spec.response(wn).norm() < 1e-9);
        let (lo, hi) = (wn * ((1.0 + zp * zp).sqrt() - zp), wn * ((1.0 + zp * zp).sqrt() + zp));
        for edge in [lo, hi] {
            assert!((spec.response(edge).norm() - 0.5f64.sqrt()).abs() < 1e-6, "{}", spec.response(edge).norm());
        }
        assert!(((hi - lo) / TAU - spec.width_hz).abs() < 1e-9);
        let shallow = NotchSpec { depth_db: 20.0, ..spec };
        assert!((shallow.response(wn).norm() - 0.1).abs() < 1e-12);
    }

    /// What the law says it is around levitation ([`ControlLaw::linear`], the closed form
    /// `plant assess` takes of a flexible rotor's loop): the filter's difference equation, then
    /// the PD on the filtered voltage with the rate as the backward difference, answers as the
    /// law does, sample by sample (the bias is the design's, read from a zero input).
    #[test]
    fn the_law_is_the_linear_filter_it_says() {
        let design = crate::wire::Hello::example("run").design();
        let p = Params::parse("frequency_hz = 480.0\nwidth_hz = 120.0\ndepth_db = 25.0").unwrap();
        let mut law = (LAW.build)(&design, &p).unwrap();
        let linear = law.linear().expect("a linear law");
        let (b, a) = linear.filter.expect("a filter");
        let bias = {
            let mut zero = (LAW.build)(&design, &p).unwrap();
            zero.update(&Sample { seq: 0, t_s: 0.0, sensor_v: [0.0; 2], ..Default::default() })
        };
        let amp = design.constants.amp_gain_a_per_v;
        let (mut u1, mut u2, mut y1, mut y2, mut prev) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for k in 0..400u64 {
            // From rest (the backward difference reads zero at the first sample).
            let u = 1e-3 * ((k as f64) * 0.37).sin() + 4e-4 * ((k as f64) * 1.9).sin();
            let y = b[0] * u + b[1] * u1 + b[2] * u2 - a[0] * y1 - a[1] * y2;
            let rate = (y - prev) / design.period_s;
            let expected = bias[0] - amp * (linear.pd.kp * y + linear.pd.kd * rate);
            let got = law.update(&Sample {
                seq: k,
                t_s: k as f64 * design.period_s,
                sensor_v: [u, 0.0],
                ..Default::default()
            });
            assert!(
                (got[0] - expected).abs() < 1e-9 * expected.abs().max(1e-3),
                "sample {k}: {got:?} against {expected}"
            );
            (u2, u1, y2, y1, prev) = (u1, u, y1, y, y);
        }
    }

    /// Below the notch the law is `pd_delay` (the filter is transparent at DC); a centre at or
    /// above Nyquist is refused naming the key.
    #[test]
    fn the_law_is_pd_delay_at_dc_and_refuses_a_centre_past_nyquist() {
        let design = crate::wire::Hello::example("run").design();
        let mut notch = (LAW.build)(&design, &Params::default()).unwrap();
        let mut plain = (crate::pd_delay::LAW.build)(&design, &Params::default()).unwrap();
        let s = Sample { seq: 0, t_s: 0.0, sensor_v: [0.2, -0.1], ..Default::default() };
        let (mut a, mut b) = ([0.0; 2], [0.0; 2]);
        for k in 0..4000 {
            let s = Sample { seq: k, t_s: k as f64 * design.period_s, ..s };
            a = notch.update(&s);
            b = plain.update(&s);
        }
        assert!((a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9, "{a:?} against {b:?}");
        let p = Params::parse(&format!("frequency_hz = {}", 0.5 / design.period_s)).unwrap();
        let e = (LAW.build)(&design, &p).err().unwrap().to_string();
        assert!(e.contains("controller.params.frequency_hz") && e.contains("Nyquist"), "{e}");
        let p = Params::parse("frequency_hz = 1e-300\nwidth_hz = 1e300").unwrap();
        let e = (LAW.build)(&design, &p).err().unwrap().to_string();
        assert!(e.contains("controller.params.width_hz") && e.contains("overflow"), "{e}");
    }
}
