//! `ross_pid`: ROSS's PID of a `MagneticBearingElement` (MODEL.md §13.8), sampled as ROSS
//! samples it, per axis.
//!
//! # Law
//!
//! ROSS's controller `C(s) = k_p + k_i / s + k_d s / (1 + s / n_f)` acts on the error
//! `0 − x` and its output, through the amplifier and sensor gains, is the coil current
//! (`bearing_seal_element.py` 3.1.0 lines 2916–2922; the frequency-domain equivalent at lines
//! 2654–2662 multiplies it by `k_i k_amp k_sense`). On this testbed's sensor voltage
//! `u = A_s x` that is
//!
//! ```text
//! i = bias − A_a · C(s) u
//! ```
//!
//! with the design's bias current (the gravity bias when `controller.gravity_bias`; ROSS has
//! none and lets the integral carry the weight).
//!
//! # Sampled law
//!
//! ROSS discretises `C(s)` by Tustin at its time step (`control.sample_system(C, dt,
//! method="tustin")`, line 2988); so does this law, at the controller's period `T`
//! (`a = 2/T`), term by term:
//!
//! ```text
//! I_k = I_{k−1} + (T/2)(u_k + u_{k−1})                                   (k_i / s)
//! D_k = (k_d n_f a (u_k − u_{k−1}) − (n_f − a) D_{k−1}) / (a + n_f)      (k_d s / (1 + s/n_f))
//! i_k = bias − A_a (k_p u_k + k_i I_k + D_k)
//! ```
//!
//! all states zero before the first sample (`u_{−1} = 0`, as ROSS's state-space starts at
//! rest), but for the integral without the gravity bias (`controller.gravity_bias = false`,
//! ROSS's way: the integral carries the weight): it starts at `I_y = −m g / (k_i A_a k_i_pid)`,
//! the value that holds the plane's share of the weight `m g` at a zero reading, so that at the
//! plant's rest (the sensors at zero, MODEL.md §13.6) the law's first command is the static
//! current and nothing moves (issue 38). The integral is held while the current is beyond the amplifier's limit and the
//! increment pushes it further (as `pid` does; ROSS has no limit).

use crate::law::{ControlLaw, Design, LawEntry, LawError, Sample};
use crate::params::{Check, Params};

/// `ross_pid`: parameters `kp` (V/V), `ki_per_s` (1/s), `kd_s` (s), `n_f_rad_s` (rad/s,
/// default 10 000, ROSS's).
pub const LAW: LawEntry = LawEntry {
    name: "ross_pid",
    summary: "ROSS's MagneticBearingElement PID kp + ki/s + kd s/(1 + s/n_f), Tustin-sampled (params kp, ki_per_s, \
              kd_s, n_f_rad_s)",
    build,
};

/// ROSS's default derivative filter cutoff `n_f` (rad/s).
pub const ROSS_N_F: f64 = 10_000.0;

fn build(design: &Design, params: &Params) -> Result<Box<dyn ControlLaw>, LawError> {
    let mut p = params.reader(LAW.name);
    let gains = RossPidGains {
        kp: p.number("kp", "", 0.0, Check::Finite)?,
        ki: p.number("ki_per_s", "1/s", 0.0, Check::Finite)?,
        kd: p.number("kd_s", "s", 0.0, Check::Finite)?,
        n_f: p.number("n_f_rad_s", "rad/s", ROSS_N_F, Check::Positive)?,
    };
    p.finish()?;
    let c = &design.constants;
    let weight_a = c.rotor_mass_kg * c.gravity_m_s2 / c.ki_n_per_a;
    let bias_y = if design.gravity_bias { weight_a } else { 0.0 };
    let law = RossPid::new(gains, c.amp_gain_a_per_v, [0.0, bias_y], design.period_s, design.current_limit_a);
    // Without the bias the integral carries the weight (ROSS's way): it starts where it holds
    // it, so that the law's first command at the rest (the sensors at zero) is the weight's
    // current, not nothing (MODEL.md §13.6; the wire's hello carries the mass, gravity and k_i,
    // so the controller process preloads it alike).
    Ok(Box::new(if design.gravity_bias { law } else { law.holding_at_rest([0.0, weight_a]) }))
}

/// ROSS's PID gains (on the sensor voltage, V/V, 1/s, s) and its derivative filter (rad/s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RossPidGains {
    /// `kp_pid`.
    pub kp: f64,
    /// `ki_pid` (1/s).
    pub ki: f64,
    /// `kd_pid` (s).
    pub kd: f64,
    /// `n_f` (rad/s).
    pub n_f: f64,
}

impl RossPidGains {
    /// `C(s)` at `s = re + j im`, as (real, imaginary): the continuous controller.
    pub fn at(&self, re: f64, im: f64) -> (f64, f64) {
        let inv = |(a, b): (f64, f64)| {
            let d = a * a + b * b;
            (a / d, -b / d)
        };
        let mul = |(a, b): (f64, f64), (c, d): (f64, f64)| (a * c - b * d, a * d + b * c);
        let (ir, ii) = inv((re, im));
        // s / (1 + s/n_f)
        let (fr, fi) = mul((re, im), inv((1.0 + re / self.n_f, im / self.n_f)));
        (self.kp + self.ki * ir + self.kd * fr, self.ki * ii + self.kd * fi)
    }
}

/// The Tustin-sampled ROSS PID of one plane (module doc).
#[derive(Clone, Debug)]
pub struct RossPid {
    gains: RossPidGains,
    amp_gain: f64,
    bias: [f64; 2],
    period_s: f64,
    limit_a: f64,
    prev_u: [f64; 2],
    integral: [f64; 2],
    derivative: [f64; 2],
    /// The integral before the first sample (zero, or the one holding the weight).
    rest_integral: [f64; 2],
}

impl RossPid {
    /// The law with `gains`, amplifier gain `A_a` (A/V), bias current per axis (A), period (s)
    /// and current limit (A).
    pub fn new(gains: RossPidGains, amp_gain: f64, bias: [f64; 2], period_s: f64, limit_a: f64) -> Self {
        Self {
            gains,
            amp_gain,
            bias,
            period_s,
            limit_a,
            prev_u: [0.0; 2],
            integral: [0.0; 2],
            derivative: [0.0; 2],
            rest_integral: [0.0; 2],
        }
    }

    /// The law with its integral preloaded so that, at a zero sensor reading and before any
    /// sample, its current is `bias + current_a` per axis (A): the static current the integral
    /// carries at the rest. Without the integral term (`ki = 0`) there is nothing to preload:
    /// the law is returned as it is.
    pub fn holding_at_rest(mut self, current_a: [f64; 2]) -> Self {
        let ki = self.gains.ki;
        if ki != 0.0 && self.amp_gain != 0.0 {
            // i = bias − A_a k_i I at u = 0 with the derivative's state at rest.
            self.rest_integral = current_a.map(|i| -i / (self.amp_gain * ki));
            self.integral = self.rest_integral;
        }
        self
    }
}

impl ControlLaw for RossPid {
    fn name(&self) -> &'static str {
        LAW.name
    }

    fn update(&mut self, s: &Sample) -> [f64; 2] {
        let RossPidGains { kp, ki, kd, n_f } = self.gains;
        let t = self.period_s;
        let a = 2.0 / t;
        let mut out = [0.0; 2];
        for (k, o) in out.iter_mut().enumerate() {
            let u = s.sensor_v[k];
            let du = u - self.prev_u[k];
            self.derivative[k] = (kd * n_f * a * du - (n_f - a) * self.derivative[k]) / (a + n_f);
            let candidate = self.integral[k] + 0.5 * t * (u + self.prev_u[k]);
            let current = |integral: f64| self.bias[k] - self.amp_gain * (kp * u + ki * integral + self.derivative[k]);
            let i = current(candidate);
            let step = -self.amp_gain * ki * (candidate - self.integral[k]);
            let winds_up = (i > self.limit_a && step > 0.0) || (i < -self.limit_a && step < 0.0);
            if !winds_up {
                self.integral[k] = candidate;
            }
            *o = current(self.integral[k]);
            self.prev_u[k] = u;
        }
        out
    }

    /// Around levitation (no saturation) the law is linear: `i = bias − A_a C(z) u` with `C(z)`
    /// its three Tustin terms over one denominator `(1 − z⁻¹)(1 − p z⁻¹)`, `p = (a − n_f)/(a +
    /// n_f)`: a second-order filter of the sensor voltage behind the proportional gain 1 (what
    /// `plant assess` and `plant linear` take the closed form of).
    fn linear(&self) -> Option<crate::law::LinearLaw> {
        let RossPidGains { kp, ki, kd, n_f } = self.gains;
        let a = 2.0 / self.period_s;
        let p = (a - n_f) / (a + n_f);
        let h = 0.5 * ki * self.period_s;
        let g = kd * n_f * a / (a + n_f);
        let b = [kp + h + g, -kp * (1.0 + p) + h * (1.0 - p) - 2.0 * g, (kp - h) * p + g];
        // Without the integral term (ROSS's UFU rig has ki_pid = 0) the numerator vanishes at
        // z = 1 as the denominator does: the first-order filter (b₀ + (b₀ + b₁) z⁻¹)/(1 − p z⁻¹)
        // that remains, not a pole on the unit circle that only rounding cancels.
        let filter = if ki == 0.0 { ([b[0], b[0] + b[1], 0.0], [-p, 0.0]) } else { (b, [-(1.0 + p), p]) };
        Some(crate::law::LinearLaw { pd: crate::law::LinearPd { kp: 1.0, kd: 0.0 }, filter: Some(filter) })
    }

    fn holds_weight_at_rest(&self) -> bool {
        self.rest_integral != [0.0; 2]
    }

    fn reset(&mut self) {
        self.prev_u = [0.0; 2];
        self.integral = self.rest_integral;
        self.derivative = [0.0; 2];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// In steady state under a sampled sine `u_k = sin(ω k T)`, the Tustin law's response is
    /// `C(s)` at the warped frequency `s = j (2/T) tan(ωT/2)` (Tustin's map of `z = e^{jωT}`):
    /// the law's output fitted to a sine and cosine equals that closed form.
    #[test]
    fn the_sampled_law_is_rosss_pid_by_tustin() {
        let g = RossPidGains { kp: 2.0, ki: 30.0, kd: 3e-3, n_f: 5000.0 };
        let t = 5e-5;
        let (amp, bias) = (1.5, [0.0, 0.25]);
        for f_hz in [5.0, 50.0, 400.0, 2000.0] {
            let w = 2.0 * std::f64::consts::PI * f_hz;
            let mut law = RossPid::new(g, amp, bias, t, f64::INFINITY);
            // Settle the filter's and the integral's transients (the integral's mean under a
            // sine starting at 0 is a constant offset: fitted away with a constant term).
            let n_settle = 200_000;
            let period = (1.0 / (f_hz * t)).round() as usize;
            let cycles = 20;
            let n_fit = period * cycles;
            let (mut ss, mut sc, mut cc, mut ys, mut yc, mut y1, mut s1, mut c1) =
                (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
            let mut rows = Vec::new();
            for k in 0..(n_settle + n_fit) {
                let ph = w * k as f64 * t;
                let u = ph.sin();
                let i =
                    law.update(&Sample { seq: k as u64, t_s: k as f64 * t, sensor_v: [u, 0.0], ..Default::default() });
                assert_eq!(i[1], bias[1], "the y axis sees no input");
                if k >= n_settle {
                    // −(i − bias)/A_a = C u
                    rows.push((ph.sin(), ph.cos(), -(i[0] - bias[0]) / amp));
                }
            }
            // Least squares on [sin, cos, 1].
            let n = rows.len() as f64;
            for &(s, c, y) in &rows {
                ss += s * s;
                sc += s * c;
                cc += c * c;
                ys += y * s;
                yc += y * c;
                y1 += y;
                s1 += s;
                c1 += c;
            }
            let m = nalgebra::Matrix3::new(ss, sc, s1, sc, cc, c1, s1, c1, n);
            let x = m.lu().solve(&nalgebra::Vector3::new(ys, yc, y1)).unwrap();
            // y = Re(C) sin + Im(C) cos for u = sin.
            let warped = 2.0 / t * (w * t / 2.0).tan();
            let (re, im) = g.at(0.0, warped);
            let scale = re.hypot(im);
            assert!((x[0] - re).abs() < 1e-6 * scale, "{f_hz} Hz: Re {} against {re}", x[0]);
            assert!((x[1] - im).abs() < 1e-6 * scale, "{f_hz} Hz: Im {} against {im}", x[1]);
        }
    }

    /// Its linear form (a gain behind a second-order filter, as `plant assess` runs it) answers
    /// as the law does on small motions, sample by sample, from rest.
    #[test]
    fn its_linear_form_is_the_law() {
        for ki in [2.8, 0.0] {
            linear_form_answers_as_the_law(RossPidGains { kp: 0.28, ki, kd: 1.33e-4, n_f: 5000.0 });
        }
        // Without the integral term, no pole at z = 1 is left to cancel: the filter is first order.
        let law = RossPid::new(RossPidGains { kp: 0.28, ki: 0.0, kd: 1.33e-4, n_f: 5000.0 }, 1.5, [0.0; 2], 5e-5, 1.0);
        let (b, a) = law.linear().unwrap().filter.unwrap();
        assert_eq!((b[2], a[1]), (0.0, 0.0));
        assert!(a[0].abs() < 1.0, "{a:?}");
    }

    fn linear_form_answers_as_the_law(g: RossPidGains) {
        let (t, amp, bias) = (5e-5, 1.5, [0.0, 0.4]);
        let mut law = RossPid::new(g, amp, bias, t, f64::INFINITY);
        let linear = law.linear().unwrap();
        let (b, a) = linear.filter.unwrap();
        let (mut u1, mut u2, mut y1, mut y2) = ([0.0; 2], [0.0; 2], [0.0; 2], [0.0; 2]);
        for k in 0..4000u64 {
            let ph = k as f64 * 0.013;
            let u = [1e-3 * ph.sin() + 2e-4, -2e-3 * (0.7 * ph).cos()];
            let got = law.update(&Sample { seq: k, t_s: k as f64 * t, sensor_v: u, ..Default::default() });
            for ax in 0..2 {
                let y = b[0] * u[ax] + b[1] * u1[ax] + b[2] * u2[ax] - a[0] * y1[ax] - a[1] * y2[ax];
                let want = bias[ax] - amp * (linear.pd.kp * y);
                assert!(
                    (got[ax] - want).abs() <= 1e-10 * (1.0 + want.abs()),
                    "sample {k} axis {ax}: {} against {want}",
                    got[ax]
                );
                (u2[ax], u1[ax], y2[ax], y1[ax]) = (u1[ax], u[ax], y1[ax], y);
            }
        }
    }

    /// Its parameters: named, checked, unknown keys refused.
    #[test]
    fn its_parameters_are_read_and_checked() {
        let design = crate::wire::Hello::example("run").design();
        let ok = Params::parse("kp = 2.0\nki_per_s = 30\nkd_s = 0.003\nn_f_rad_s = 5000.0").unwrap();
        assert_eq!(build(&design, &ok).unwrap().name(), "ross_pid");
        for (text, expect) in
            [("n_f_rad_s = 0.0", "n_f_rad_s"), ("kp = \"two\"", "kp"), ("kp = nan", "kp"), ("kd = 1.0", "kd")]
        {
            let err = build(&design, &Params::parse(text).unwrap()).err().unwrap().to_string();
            assert!(err.contains(expect), "{text}: {err}");
        }
    }

    /// Without the gravity bias (ROSS's way) the integral starts holding the plane's weight: at a
    /// zero reading the first current, and every one after, is `m g / k_i` on y (by hand from
    /// the design's constants), 0 on x, and a reset goes back there; with the bias the integral
    /// starts at zero and the bias holds it alike; without the integral there is nothing to
    /// preload.
    #[test]
    fn without_the_bias_its_integral_starts_holding_the_weight() {
        let mut design = Design::study();
        design.gravity_bias = false;
        let c = design.constants;
        let weight = c.rotor_mass_kg * c.gravity_m_s2 / c.ki_n_per_a;
        let params = Params::parse("kp = 0.28\nki_per_s = 2.8\nkd_s = 0.000133\nn_f_rad_s = 5000.0").unwrap();
        let sample = |k: u64| Sample { seq: k, t_s: k as f64 * design.period_s, ..Default::default() };
        for bias in [false, true] {
            design.gravity_bias = bias;
            let mut law = build(&design, &params).unwrap();
            assert_eq!(law.holds_weight_at_rest(), !bias);
            for k in 0..100 {
                let i = law.update(&sample(k));
                assert!(i[0] == 0.0 && (i[1] - weight).abs() <= 1e-12 * weight, "bias {bias}, sample {k}: {i:?}");
            }
            law.reset();
            let i = law.update(&sample(0));
            assert!((i[1] - weight).abs() <= 1e-12 * weight, "after a reset: {i:?}");
        }
        design.gravity_bias = false;
        let no_integral = Params::parse("kp = 0.28\nki_per_s = 0.0\nkd_s = 0.000133").unwrap();
        let mut law = build(&design, &no_integral).unwrap();
        assert!(!law.holds_weight_at_rest());
        assert_eq!(law.update(&sample(0)), [0.0, 0.0]);
    }
}
