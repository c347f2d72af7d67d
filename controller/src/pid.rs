//! `pid`: the study's PD design plus integral action on each axis, sampled,
//! with anti-windup against the amplifier's current limit.
//!
//! # Design
//!
//! With `ω_n = √(k_e/m_r)` and an integral corner `ω_i = 1/T_i`, the law
//! places the continuous closed loop `m s³ + c s² + k s + K_I` at
//!
//! ```text
//! m (s² + 2 ξ_e ω_n s + ω_n²)(s + ω_i)
//!   ⇒ k = k_e (1 + 2 ξ_e ω_i/ω_n),   c = m (2 ξ_e ω_n + ω_i),   K_I = k_e ω_i
//! ```
//!
//! so the design's pole pair (ω_n, ξ_e) is kept and the integral adds a real
//! pole at `−ω_i`. (Adding `K_I/s` to an unchanged PD would instead act as a
//! negative damping `K_I/ω_n²` at ω_n, i.e. `Δξ = ω_i/(2 ω_n)`: a decade-below
//! corner would take 0.05 off the damping ratio, and ξ_e = 0.01 would go
//! unstable.) `k` and `c` go through [`PdGains::from_design`] as the design
//! `(k, ξ = c/(2√(k m)))`; the integral gain is `k_I = K_I / (k_i A_a A_s)`
//! (1/s), on the integral of the sensor voltage.
//!
//! Default `T_i = 10/ω_n`: the integral corner a decade below the closed-loop
//! natural frequency (≈ 34 ms for the reference `k_e = 10⁶ N/m`, 11.5 kg).
//!
//! # Sampled law
//!
//! ```text
//! I_k = I_{k−1} + T u_k                      (unless held, below)
//! i_k = i_bias − A_a (k_p u_k + k_d (u_k − u_{k−1})/T + k_I I_k)
//! ```
//!
//! the derivative being [`crate::pd::SampledPd`]'s backward difference. The
//! integral starts at zero. With the gravity bias on, `i_bias` carries the
//! weight and the integral only trims; with it off, the integral converges
//! to the static sag's current `m_r g / k_i` and removes the sag `m_r g/k_e`.
//!
//! **Anti-windup (conditional integration):** if the current with the new
//! increment would exceed `|i| ≤ i_max` and the increment pushes it further
//! out, the integral is held. During a long saturation the integral thus
//! stays where it was when the limit was reached, and the current leaves the
//! limit as soon as the error reverses.

use crate::law::{ControlLaw, Design, LawEntry, LawError, LoopConstants, Sample};
use crate::params::{Check, Params};
use crate::pd::{BackwardDifference, PdDesign, PdGains};

/// `pid`: parameter `integral_time_s` (s, > 0; default `10/ω_n`).
pub const LAW: LawEntry = LawEntry {
    name: "pid",
    summary: "the design's PD plus integral action, anti-windup at the current limit (param integral_time_s)",
    build,
};

fn build(design: &Design, params: &Params) -> Result<Box<dyn ControlLaw>, LawError> {
    let mut p = params.reader(LAW.name);
    let integral_time_s = p.optional_number("integral_time_s", "s", Check::Positive)?;
    p.finish()?;
    let gains = PidGains::from_design(&PidDesign { pd: design.pd(), integral_time_s }, &design.constants)?;
    Ok(Box::new(SampledPid::new(gains, design.period_s, design.current_limit_a)))
}

/// A PID design: the PD design and an integral time constant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PidDesign {
    /// The closed-loop pole pair (k_e, ξ_e) and the gravity bias.
    pub pd: PdDesign,
    /// Integral time constant T_i = 1/ω_i (s); `None` for the default `10/ω_n`.
    pub integral_time_s: Option<f64>,
}

/// PID gains derived from a design.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PidGains {
    /// Proportional and derivative gains and the bias (see the module doc).
    pub pd: PdGains,
    /// Integral gain k_I (1/s) on the integral of the sensor voltage.
    pub ki: f64,
    /// The integral time constant used (s).
    pub integral_time_s: f64,
}

impl PidGains {
    /// Derives the gains (module doc).
    pub fn from_design(d: &PidDesign, c: &LoopConstants) -> Result<Self, LawError> {
        // Validates k_e, ξ_e with the keys the user wrote.
        PdGains::from_design(&d.pd, c)?;
        let wn = (d.pd.stiffness_n_per_m / c.rotor_mass_kg).sqrt();
        let ti = d.integral_time_s.unwrap_or(10.0 / wn);
        if !(ti.is_finite() && ti > 0.0) {
            return Err(LawError::Design {
                key: "controller.params.integral_time_s",
                value: ti,
                unit: "s",
                why: "must be > 0",
            });
        }
        let wi = 1.0 / ti;
        let (ke, xi, m) = (d.pd.stiffness_n_per_m, d.pd.damping_ratio, c.rotor_mass_kg);
        let k = ke * (1.0 + 2.0 * xi * wi / wn);
        let damping = m * (2.0 * xi * wn + wi);
        let pd = PdGains::from_design(
            &PdDesign { stiffness_n_per_m: k, damping_ratio: damping / (2.0 * (k * m).sqrt()), ..d.pd },
            c,
        )?;
        let loop_gain = c.ki_n_per_a * c.amp_gain_a_per_v * c.sensor_gain_v_per_m;
        Ok(Self { pd, ki: ke * wi / loop_gain, integral_time_s: ti })
    }
}

/// The sampled PID with conditional-integration anti-windup (`pid`).
#[derive(Clone, Debug)]
pub struct SampledPid {
    gains: PidGains,
    period_s: f64,
    limit_a: f64,
    anti_windup: bool,
    rate: BackwardDifference,
    integral: [f64; 2],
}

impl SampledPid {
    /// A sampled PID with the given gains, period (s) and current limit (A).
    pub fn new(gains: PidGains, period_s: f64, limit_a: f64) -> Self {
        Self {
            gains,
            period_s,
            limit_a,
            anti_windup: true,
            rate: BackwardDifference::new(period_s),
            integral: [0.0; 2],
        }
    }

    /// The same law with the integral never held (for comparison only: it
    /// winds up during saturation).
    pub fn without_anti_windup(mut self) -> Self {
        self.anti_windup = false;
        self
    }

    /// The integral state `I` per axis (V·s).
    pub fn integral(&self) -> [f64; 2] {
        self.integral
    }
}

impl ControlLaw for SampledPid {
    fn name(&self) -> &'static str {
        LAW.name
    }

    fn update(&mut self, s: &Sample) -> [f64; 2] {
        let u = s.sensor_v;
        let t = self.period_s;
        let u_dot = self.rate.rate(u);
        let pd = self.gains.pd.current(u, u_dot);
        let a = self.gains.pd.amp_gain_a_per_v * self.gains.ki;
        let mut out = [0.0; 2];
        for k in 0..2 {
            let candidate = self.integral[k] + t * u[k];
            let i = pd[k] - a * candidate;
            // The increment's effect on the current: −a T u.
            let step = -a * t * u[k];
            let winds_up = (i > self.limit_a && step > 0.0) || (i < -self.limit_a && step < 0.0);
            if !(self.anti_windup && winds_up) {
                self.integral[k] = candidate;
            }
            out[k] = pd[k] - a * self.integral[k];
        }
        out
    }

    fn reset(&mut self) {
        self.rate.reset();
        self.integral = [0.0; 2];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::law::saturate;
    use crate::test_plant::{simulate, Rig};

    fn design(xi: f64, gravity_bias: bool) -> PidDesign {
        PidDesign { pd: PdDesign { stiffness_n_per_m: 1e6, damping_ratio: xi, gravity_bias }, integral_time_s: None }
    }

    #[test]
    fn gains_place_the_design_pair_and_the_integral_pole() {
        let c = LoopConstants::study();
        let g = PidGains::from_design(&design(0.01, false), &c).unwrap();
        let l = c.ki_n_per_a * c.amp_gain_a_per_v * c.sensor_gain_v_per_m;
        let (m, wn) = (c.rotor_mass_kg, (1e6 / c.rotor_mass_kg).sqrt());
        let wi = wn / 10.0;
        assert!((g.integral_time_s - 10.0 / wn).abs() < 1e-12);
        // m s³ + c s² + k s + K_I must vanish at the design pole and at −ω_i.
        let (k, cc, ki) = (l * g.pd.kp - c.ks_n_per_m, l * g.pd.kd, l * g.ki);
        let at = |re: f64, im: f64| {
            // Evaluate the cubic at re + j im.
            let (r2, i2) = (re * re - im * im, 2.0 * re * im);
            let (r3, i3) = (r2 * re - i2 * im, r2 * im + i2 * re);
            (m * r3 + cc * r2 + k * re + ki, m * i3 + cc * i2 + k * im)
        };
        let s0 = (-0.01 * wn, wn * (1.0 - 1e-4_f64).sqrt());
        let scale = 1e6 * wn;
        let (re, im) = at(s0.0, s0.1);
        assert!(re.abs() < 1e-9 * scale && im.abs() < 1e-9 * scale, "{re} {im}");
        assert!(at(-wi, 0.0).0.abs() < 1e-9 * scale);
    }

    #[test]
    fn integral_removes_the_static_sag_without_gravity_bias() {
        let c = LoopConstants::study();
        let period = 5e-5;
        let g = -c.rotor_mass_kg * c.gravity_m_s2;
        let sag = c.rotor_mass_kg * c.gravity_m_s2 / 1e6;
        // The PD alone (no bias) sags by m g / k_e.
        let mut pd = crate::pd::SampledPd::new(PdGains::from_design(&design(0.2, false).pd, &c).unwrap(), period);
        let (xs, _) = simulate(&mut pd, &c, Rig { period, delay: 1, limit: 2.0 }, [[0.0; 2]; 2], [0.0, g], 20_000);
        let y_pd = xs.last().unwrap()[1];
        assert!((y_pd + sag).abs() < 0.01 * sag, "pd sag {y_pd} vs {sag}");
        // The PID brings it back to the centre.
        let gains = PidGains::from_design(&design(0.2, false), &c).unwrap();
        let mut pid = SampledPid::new(gains, period, 2.0);
        let (xs, cmds) = simulate(&mut pid, &c, Rig { period, delay: 1, limit: 2.0 }, [[0.0; 2]; 2], [0.0, g], 20_000);
        let y = xs.last().unwrap()[1];
        eprintln!("pd sag {y_pd:.4e} m, pid residual {y:.3e} m after 1 s");
        assert!(y.abs() < 1e-3 * sag, "pid residual {y} vs sag {sag}");
        let i_g = c.rotor_mass_kg * c.gravity_m_s2 / c.ki_n_per_a;
        assert!((cmds.last().unwrap()[1] - i_g).abs() < 1e-3 * i_g);
    }

    #[test]
    fn integral_starts_at_zero_with_gravity_bias_and_the_loop_is_stable() {
        let c = LoopConstants::study();
        let period = 5e-5;
        // ξ_e = 0.2: at ξ_e = 0.01, 20 kHz and d = 1 the PID's pair is as
        // unstable as the naive PD's (the same sampled-PD lag; see `pd_delay`).
        let gains = PidGains::from_design(&design(0.2, true), &c).unwrap();
        let mut pid = SampledPid::new(gains, period, 2.0);
        let (xs, _) = simulate(
            &mut pid,
            &c,
            Rig { period, delay: 1, limit: 2.0 },
            [[0.0; 2]; 2],
            [0.0, -c.rotor_mass_kg * c.gravity_m_s2],
            20_000,
        );
        assert!(xs.iter().all(|p| p[1].abs() < 1e-9), "the bias carries the weight: {:?}", xs.last());
        assert_eq!(pid.integral()[0], 0.0);
        // A 10 µm offset decays at 20 kHz, d = 1.
        pid.reset();
        let (xs, _) =
            simulate(&mut pid, &c, Rig { period, delay: 1, limit: 2.0 }, [[1e-5, 0.0], [0.0; 2]], [0.0; 2], 40_000);
        let tail = xs[30_000..].iter().fold(0.0_f64, |m, p| m.max(p[0].abs()));
        assert!(tail < 1e-8, "tail {tail}");
    }

    /// Ticks until the saturated current leaves the limit after the error reverses.
    fn ticks_to_leave(law: &mut SampledPid, limit: f64) -> usize {
        let big = Sample { seq: 0, t_s: 0.0, sensor_v: [10.0, 0.0], ..Default::default() }; // 400 µm: k_p u exceeds the limit
        for k in 0..20_000 {
            let i = saturate(law.update(&Sample { seq: k, ..big }), limit);
            assert_eq!(i[0], -limit);
        }
        // −40 µm. The first reversed tick carries the derivative kick, which
        // leaves the limit in any case: count from the tick after it.
        let back = Sample { seq: 0, t_s: 0.0, sensor_v: [-1.0, 0.0], ..Default::default() };
        law.update(&Sample { seq: 20_000, ..back });
        (0..1_000_000)
            .position(|k| saturate(law.update(&Sample { seq: 20_001 + k as u64, ..back }), limit)[0] > -limit)
            .unwrap_or(usize::MAX)
    }

    #[test]
    fn anti_windup_leaves_the_limit_promptly() {
        let c = LoopConstants::study();
        let limit = 2.0;
        let gains = PidGains::from_design(&design(0.2, false), &c).unwrap();
        let held = ticks_to_leave(&mut SampledPid::new(gains, 5e-5, limit), limit);
        let wound = ticks_to_leave(&mut SampledPid::new(gains, 5e-5, limit).without_anti_windup(), limit);
        eprintln!("ticks to leave the limit: anti-windup {held}, wound up {wound}");
        assert!(held <= 2, "held {held}");
        assert!(wound > 1000 && wound > 100 * held.max(1), "wound {wound}");
    }

    #[test]
    fn reset_clears_the_state() {
        let c = LoopConstants::study();
        let gains = PidGains::from_design(&design(0.01, true), &c).unwrap();
        let mut law = SampledPid::new(gains, 5e-5, 2.0);
        assert_eq!(law.name(), "pid");
        let samples: Vec<Sample> = (0..50)
            .map(|k| Sample { seq: k, t_s: k as f64 * 5e-5, sensor_v: [0.01 * k as f64, -0.02], ..Default::default() })
            .collect();
        let first: Vec<[f64; 2]> = samples.iter().map(|s| law.update(s)).collect();
        assert_ne!(law.integral(), [0.0; 2]);
        law.reset();
        assert_eq!(law.integral(), [0.0; 2]);
        let again: Vec<[f64; 2]> = samples.iter().map(|s| law.update(s)).collect();
        assert_eq!(first, again);
    }

    #[test]
    fn bad_integral_time_is_refused() {
        let d = PidDesign { integral_time_s: Some(-1.0), ..design(0.01, true) };
        let e = PidGains::from_design(&d, &LoopConstants::study()).unwrap_err().to_string();
        assert!(e.contains("controller.params.integral_time_s"), "{e}");
    }
}
