//! `pd_notch`: the design's PD (the testbed's `pd`, naively sampled) behind a
//! notch filter on the sensor signal, so that the controller does not answer
//! the synchronous unbalance response at the rotor speed: the rotor then
//! spins about its centre of mass instead of being forced onto its
//! geometric centre, and the coil currents lose their once-per-revolution
//! ripple.
//!
//! The filter, per axis, is the continuous notch
//!
//! ```text
//! H(s) = (s² + 2 ζ_z ω₀ s + ω₀²) / (s² + 2 ζ_p ω₀ s + ω₀²),
//! ζ_p = 1 / (2 Q),  ζ_z = ζ_p (1 − depth)
//! ```
//!
//! discretised with the bilinear transform prewarped at ω₀
//! (`K = ω₀ / tan(ω₀ T / 2)`), run in direct form II transposed, and started
//! at rest on the first sample (its state set so that a constant input
//! passes unchanged: no start-up transient).
//!
//! Parameters (`[controller.params]`): `notch_hz` (Hz, default 500: the
//! study's rotor speed; > 0 and below half the sampling rate), `quality`
//! (Q, default 2; > 0), `depth` (0 = no notch, 1 = full notch, default 1).

use controller::{Check, ControlLaw, Design, LawEntry, LawError, Params, PdGains, Sample, SampledPd};

/// The law's registry entry: what `controller::serve` is given.
pub const LAW: LawEntry = LawEntry {
    name: "pd_notch",
    summary: "the design's PD behind a notch filter on the sensor (default at the rotor speed)",
    build,
};

/// Builds the law from the plant's design and the scene's `[controller.params]`.
pub fn build(design: &Design, params: &Params) -> Result<Box<dyn ControlLaw>, LawError> {
    let mut p = params.reader(LAW.name);
    let nyquist = 0.5 / design.period_s;
    let notch_hz = p.number("notch_hz", "Hz", 500.0, Check::Between(0.0, nyquist))?;
    let quality = p.number("quality", "", 2.0, Check::Positive)?;
    let depth = p.number("depth", "", 1.0, Check::NonNegative)?;
    if depth > 1.0 {
        return Err(LawError::Param {
            law: LAW.name,
            key: "depth".into(),
            value: depth.to_string(),
            unit: "",
            why: "must be between 0 (no notch) and 1 (full notch)".into(),
        });
    }
    p.finish()?;
    let gains = PdGains::from_design(&design.pd(), &design.constants)?;
    let notch = Notch::new(notch_hz, quality, depth, design.period_s);
    Ok(Box::new(PdNotch { pd: SampledPd::new(gains, design.period_s), notch, state: None }))
}

/// Biquad coefficients, normalised (`a0 = 1`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Notch {
    /// Numerator b0, b1, b2.
    pub b: [f64; 3],
    /// Denominator a1, a2.
    pub a: [f64; 2],
}

impl Notch {
    /// The notch at `hz` with quality `q` and `depth` for sampling period `period_s` (s).
    pub fn new(hz: f64, q: f64, depth: f64, period_s: f64) -> Self {
        let w0 = std::f64::consts::TAU * hz;
        let k = w0 / (w0 * period_s / 2.0).tan();
        let zeta_p = 1.0 / (2.0 * q);
        let zeta_z = zeta_p * (1.0 - depth);
        let (k2, w2) = (k * k, w0 * w0);
        let a0 = k2 + 2.0 * zeta_p * w0 * k + w2;
        Self {
            b: [(k2 + 2.0 * zeta_z * w0 * k + w2) / a0, 2.0 * (w2 - k2) / a0, (k2 - 2.0 * zeta_z * w0 * k + w2) / a0],
            a: [2.0 * (w2 - k2) / a0, (k2 - 2.0 * zeta_p * w0 * k + w2) / a0],
        }
    }

    /// The state (z1, z2) at rest on a constant input `x` (output = `x`).
    pub fn rest(&self, x: f64) -> [f64; 2] {
        let z2 = (self.b[2] - self.a[1]) * x;
        [(self.b[1] - self.a[0]) * x + z2, z2]
    }

    /// One sample through the filter (direct form II transposed).
    pub fn step(&self, x: f64, z: &mut [f64; 2]) -> f64 {
        let y = self.b[0] * x + z[0];
        z[0] = self.b[1] * x - self.a[0] * y + z[1];
        z[1] = self.b[2] * x - self.a[1] * y;
        y
    }
}

/// The PD behind the notch.
pub struct PdNotch {
    pd: SampledPd,
    notch: Notch,
    /// Filter state per axis; `None` before the first sample.
    state: Option<[[f64; 2]; 2]>,
}

impl ControlLaw for PdNotch {
    fn name(&self) -> &'static str {
        LAW.name
    }

    fn update(&mut self, s: &Sample) -> [f64; 2] {
        let notch = self.notch;
        let state = self.state.get_or_insert_with(|| [notch.rest(s.sensor_v[0]), notch.rest(s.sensor_v[1])]);
        let filtered = [notch.step(s.sensor_v[0], &mut state[0]), notch.step(s.sensor_v[1], &mut state[1])];
        self.pd.update(&Sample { sensor_v: filtered, ..*s })
    }

    fn reset(&mut self) {
        self.pd.reset();
        self.state = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gain_at(n: &Notch, hz: f64, period_s: f64) -> f64 {
        // |H(e^{jωT})| from the coefficients.
        let w = std::f64::consts::TAU * hz * period_s;
        let (c1, s1, c2, s2) = (w.cos(), w.sin(), (2.0 * w).cos(), (2.0 * w).sin());
        let num = ((n.b[0] + n.b[1] * c1 + n.b[2] * c2).powi(2) + (n.b[1] * s1 + n.b[2] * s2).powi(2)).sqrt();
        let den = ((1.0 + n.a[0] * c1 + n.a[1] * c2).powi(2) + (n.a[0] * s1 + n.a[1] * s2).powi(2)).sqrt();
        num / den
    }

    #[test]
    fn the_notch_removes_its_frequency_and_passes_the_others() {
        let t = 5e-5;
        let n = Notch::new(500.0, 2.0, 1.0, t);
        assert!(gain_at(&n, 500.0, t) < 1e-9);
        assert!((gain_at(&n, 0.0, t) - 1.0).abs() < 1e-12);
        assert!((gain_at(&n, 47.0, t) - 1.0).abs() < 0.01, "{}", gain_at(&n, 47.0, t));
        let half = Notch::new(500.0, 2.0, 0.5, t);
        assert!((gain_at(&half, 500.0, t) - 0.5).abs() < 1e-9);
    }

    #[test]
    fn a_constant_input_passes_unchanged_from_the_first_sample() {
        let n = Notch::new(500.0, 2.0, 1.0, 5e-5);
        let mut z = n.rest(0.3);
        for _ in 0..10 {
            assert!((n.step(0.3, &mut z) - 0.3).abs() < 1e-12);
        }
    }

    #[test]
    fn parameters_are_checked_naming_law_key_value_and_unit() {
        let design = controller::wire::Hello::example("r").design();
        let e = build(&design, &Params::parse("notch_hz = 20000.0").unwrap()).err().unwrap().to_string();
        assert!(e.contains("law pd_notch") && e.contains("notch_hz = 20000") && e.contains("Hz"), "{e}");
        let e = build(&design, &Params::parse("depth = 2.0").unwrap()).err().unwrap().to_string();
        assert!(e.contains("depth = 2"), "{e}");
        let e = build(&design, &Params::parse("gain = 2.0").unwrap()).err().unwrap().to_string();
        assert!(e.contains("unknown parameter controller.params.gain"), "{e}");
        assert_eq!(build(&design, &Params::default()).unwrap().name(), "pd_notch");
    }
}
