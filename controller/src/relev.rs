//! `relev`: a re-levitation law. It runs the delay-aware PD of the nominal
//! design (`pd_delay`, so the sampled loop has the design's stiffness and
//! damping) and switches to a heavily damped design of the same stiffness
//! while the rotor touches its touchdown bearing.
//!
//! # Why
//!
//! After a strong shock the reference design (ξ_e = 0.01) can stay in
//! backward dry whirl: the rotor rolls round the inside of the race, and the
//! race's friction drives the whirl faster than the bearing's small damping
//! can take energy out of it (paper-10g: −63 Hz, for the whole run). A design
//! with ξ ≳ 0.05 leaves that state; but a heavily damped loop amplifies the
//! sensor noise and the unbalance response, so the law only uses it while it
//! is needed.
//!
//! # The switching rule
//!
//! The law knows only the sensor: `r = |u| / A_s`, the rotor's radius from the
//! housing centre (m). Two thresholds and a hold time make a hysteresis:
//!
//! ```text
//! nominal    → recovering   when r ≥ enter                (a touch)
//! recovering → nominal      when r < exit for hold seconds (levitating again)
//! ```
//!
//! with `exit < enter`: the nominal design only returns to a rotor that has
//! been levitating, near the centre, for `hold`. Both designs share the same
//! backward difference, so a switch changes the gains, never the rate
//! estimate.

use crate::discrete_pd::DelayPdGains;
use crate::law::{ControlLaw, Design, LawEntry, LawError, LoopConstants, Sample};
use crate::params::{Check, Params};
use crate::pd::{BackwardDifference, PdDesign};

/// `relev` and its parameters (`[controller.params]`):
///
/// | key | unit | default | meaning |
/// |---|---|---|---|
/// | `enter_um` | µm | 0.8 × the air gap | radius at which the rotor counts as touching |
/// | `exit_um` | µm | 0.3 × the air gap | radius below which it counts as levitating again (< `enter_um`) |
/// | `recovery_damping_ratio` | – | 0.2 | damping ratio of the recovery design (0 < ξ < 1) |
/// | `hold_ms` | ms | 50 | time below `exit_um` before the nominal design returns |
/// | `arm_ms` | ms | 0 | time from which the rule acts |
pub const LAW: LawEntry = LawEntry {
    name: "relev",
    summary: "re-levitation: pd_delay, switching to a heavily damped design while the rotor touches \
              (params enter_um, exit_um, recovery_damping_ratio, hold_ms, arm_ms)",
    build,
};

/// The keys of `relev`'s parameters, with the deprecated `[controller]` keys they replace.
pub const ALIASES: &[(&str, &str)] = &[
    ("relev_enter_um", "enter_um"),
    ("relev_exit_um", "exit_um"),
    ("relev_damping_ratio", "recovery_damping_ratio"),
    ("relev_hold_ms", "hold_ms"),
    ("relev_arm_ms", "arm_ms"),
];

fn build(design: &Design, params: &Params) -> Result<Box<dyn ControlLaw>, LawError> {
    let rule = RelevSpec::from_params(params, design.constants.air_gap_m)?;
    Ok(Box::new(Relev::new(&design.pd(), &rule, &design.constants, design.period_s, design.delay_samples)?))
}

/// What the switching rule needs (SI), from `relev`'s parameters.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct RelevSpec {
    /// Radius at which the rotor counts as touching (m).
    pub enter_m: f64,
    /// Radius below which the rotor counts as levitating again (m), < `enter_m`.
    pub exit_m: f64,
    /// Damping ratio of the recovery design.
    pub damping_ratio: f64,
    /// Time below `exit_m` before the nominal design returns (s).
    pub hold_s: f64,
    /// Time from which the rule acts (s); before it the law is the nominal design alone. 0 in
    /// service; later to show a recovery from a contact state the nominal design has settled in.
    pub arm_s: f64,
}

impl RelevSpec {
    /// Reads the rule from `relev`'s parameters (the table in [`LAW`]'s doc); the radii default
    /// to 0.8 and 0.3 of the air gap `air_gap_m` (m).
    pub fn from_params(params: &Params, air_gap_m: f64) -> Result<Self, LawError> {
        let mut p = params.reader(LAW.name);
        let enter = p.number("enter_um", "µm", 0.8e6 * air_gap_m, Check::Positive)?;
        let exit = p.number("exit_um", "µm", 0.3e6 * air_gap_m, Check::Positive)?;
        if exit >= enter {
            return Err(p.error(
                "exit_um",
                exit,
                "µm",
                format!("must be below controller.params.enter_um = {enter} µm"),
            ));
        }
        let damping_ratio = p.number("recovery_damping_ratio", "", 0.2, Check::Between(0.0, 1.0))?;
        let hold_ms = p.number("hold_ms", "ms", 50.0, Check::NonNegative)?;
        let arm_ms = p.number("arm_ms", "ms", 0.0, Check::NonNegative)?;
        p.finish()?;
        Ok(Self {
            enter_m: enter * 1e-6,
            exit_m: exit * 1e-6,
            damping_ratio,
            hold_s: hold_ms * 1e-3,
            arm_s: arm_ms * 1e-3,
        })
    }
}

/// Which design runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// The nominal design.
    Nominal,
    /// The recovery design; `calm` samples in a row below the exit radius.
    Recovering {
        /// Consecutive samples with `r < exit`.
        calm: u64,
    },
}

/// The re-levitation law (`relev`).
#[derive(Clone, Debug)]
pub struct Relev {
    nominal: DelayPdGains,
    recovery: DelayPdGains,
    rate: BackwardDifference,
    /// Thresholds as sensor voltages, squared (V²).
    enter_v2: f64,
    exit_v2: f64,
    hold_samples: u64,
    arm_s: f64,
    phase: Phase,
    switches: u64,
}

impl Relev {
    /// Designs both loops for the sampling period and delay (see
    /// [`DelayPdGains::from_design`]) and checks the rule.
    pub fn new(
        nominal: &PdDesign,
        rule: &RelevSpec,
        c: &LoopConstants,
        period_s: f64,
        delay_samples: u32,
    ) -> Result<Self, LawError> {
        let design = |key, value, unit, why| LawError::Design { key, value, unit, why };
        if !(rule.enter_m.is_finite() && rule.enter_m > 0.0) {
            return Err(design("controller.params.enter_um", rule.enter_m * 1e6, "µm", "must be > 0"));
        }
        if !(rule.exit_m.is_finite() && rule.exit_m > 0.0 && rule.exit_m < rule.enter_m) {
            return Err(design(
                "controller.params.exit_um",
                rule.exit_m * 1e6,
                "µm",
                "must be > 0 and below controller.params.enter_um",
            ));
        }
        if !(rule.hold_s.is_finite() && rule.hold_s >= 0.0) {
            return Err(design("controller.params.hold_ms", rule.hold_s * 1e3, "ms", "must be >= 0"));
        }
        if !(rule.arm_s.is_finite() && rule.arm_s >= 0.0) {
            return Err(design("controller.params.arm_ms", rule.arm_s * 1e3, "ms", "must be >= 0"));
        }
        if !(rule.damping_ratio.is_finite() && rule.damping_ratio > 0.0 && rule.damping_ratio < 1.0) {
            return Err(design(
                "controller.params.recovery_damping_ratio",
                rule.damping_ratio,
                "",
                "must be > 0 and < 1 (the recovery design is a delay-aware PD: a complex pole pair)",
            ));
        }
        let recovery_design = PdDesign { damping_ratio: rule.damping_ratio, ..*nominal };
        let volts = |m: f64| (m * c.sensor_gain_v_per_m).powi(2);
        Ok(Self {
            nominal: DelayPdGains::from_design(nominal, c, period_s, delay_samples)?,
            recovery: DelayPdGains::from_design(&recovery_design, c, period_s, delay_samples)?,
            rate: BackwardDifference::new(period_s),
            enter_v2: volts(rule.enter_m),
            exit_v2: volts(rule.exit_m),
            hold_samples: (rule.hold_s / period_s).round() as u64,
            arm_s: rule.arm_s,
            phase: Phase::Nominal,
            switches: 0,
        })
    }

    /// The design running now.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// Switches so far, either way.
    pub fn switches(&self) -> u64 {
        self.switches
    }

    /// The rule on one sample: the phase after it.
    fn step_phase(&mut self, s: &Sample) -> Phase {
        if s.t_s < self.arm_s {
            return self.phase;
        }
        let u = s.sensor_v;
        let r2 = u[0] * u[0] + u[1] * u[1];
        let next = match self.phase {
            Phase::Nominal if r2 >= self.enter_v2 => Phase::Recovering { calm: 0 },
            Phase::Nominal => Phase::Nominal,
            Phase::Recovering { .. } if r2 >= self.enter_v2 => Phase::Recovering { calm: 0 },
            Phase::Recovering { calm } => {
                let calm = if r2 < self.exit_v2 { calm + 1 } else { 0 };
                if calm > self.hold_samples {
                    Phase::Nominal
                } else {
                    Phase::Recovering { calm }
                }
            }
        };
        if matches!(next, Phase::Nominal) != matches!(self.phase, Phase::Nominal) {
            self.switches += 1;
        }
        self.phase = next;
        next
    }
}

impl ControlLaw for Relev {
    fn name(&self) -> &'static str {
        LAW.name
    }

    fn update(&mut self, s: &Sample) -> [f64; 2] {
        let u_dot = self.rate.rate(s.sensor_v);
        let gains = match self.step_phase(s) {
            Phase::Nominal => &self.nominal,
            Phase::Recovering { .. } => &self.recovery,
        };
        gains.pd.current(s.sensor_v, u_dot)
    }

    fn reset(&mut self) {
        self.rate.reset();
        self.phase = Phase::Nominal;
        self.switches = 0;
    }

    /// The nominal loop (the recovery design acts only while the rotor touches).
    fn linear_pd(&self) -> Option<crate::law::LinearPd> {
        Some(crate::law::LinearPd { kp: self.nominal.pd.kp, kd: self.nominal.pd.kd })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PERIOD: f64 = 5e-5;

    fn law(hold_s: f64) -> Relev {
        let nominal = PdDesign { stiffness_n_per_m: 1e6, damping_ratio: 0.01, gravity_bias: false };
        let rule = RelevSpec { enter_m: 100e-6, exit_m: 30e-6, damping_ratio: 0.2, hold_s, arm_s: 0.0 };
        Relev::new(&nominal, &rule, &LoopConstants::study(), PERIOD, 1).unwrap()
    }

    fn at(law: &mut Relev, k: u64, x_m: f64) -> [f64; 2] {
        let u = [x_m * LoopConstants::study().sensor_gain_v_per_m, 0.0];
        law.update(&Sample { seq: k, t_s: k as f64 * PERIOD, sensor_v: u, ..Default::default() })
    }

    #[test]
    fn enters_on_touch_and_returns_after_the_hold() {
        let mut l = law(1e-3); // 20 samples
        let mut k = 0;
        for _ in 0..5 {
            at(&mut l, k, 10e-6);
            k += 1;
        }
        assert_eq!(l.phase(), Phase::Nominal);
        at(&mut l, k, 120e-6);
        k += 1;
        assert_eq!(l.phase(), Phase::Recovering { calm: 0 });
        // Between the thresholds: still recovering, the calm count does not start.
        for _ in 0..100 {
            at(&mut l, k, 60e-6);
            k += 1;
        }
        assert_eq!(l.phase(), Phase::Recovering { calm: 0 });
        // Below the exit radius: back to nominal after the hold, not before.
        for _ in 0..20 {
            at(&mut l, k, 10e-6);
            k += 1;
        }
        assert!(matches!(l.phase(), Phase::Recovering { calm: 20 }), "{:?}", l.phase());
        at(&mut l, k, 10e-6);
        assert_eq!(l.phase(), Phase::Nominal);
        assert_eq!(l.switches(), 2);
    }

    #[test]
    fn recovery_design_is_the_stronger_damper() {
        // Same displacement, same rate: the recovery gains push harder against the velocity.
        let c = LoopConstants::study();
        let (mut a, mut b) = (law(0.0), law(0.0));
        at(&mut a, 0, 10e-6);
        let slow = at(&mut a, 1, 11e-6);
        at(&mut b, 0, 110e-6);
        let fast = at(&mut b, 1, 111e-6);
        // Subtract the proportional parts: what is left is the derivative action.
        let nominal = DelayPdGains::from_design(
            &PdDesign { stiffness_n_per_m: 1e6, damping_ratio: 0.01, gravity_bias: false },
            &c,
            PERIOD,
            1,
        )
        .unwrap();
        let recovery = DelayPdGains::from_design(
            &PdDesign { stiffness_n_per_m: 1e6, damping_ratio: 0.2, gravity_bias: false },
            &c,
            PERIOD,
            1,
        )
        .unwrap();
        let v = |x: f64| x * c.sensor_gain_v_per_m;
        assert_eq!(slow, nominal.pd.current([v(11e-6), 0.0], [(v(11e-6) - v(10e-6)) / PERIOD, 0.0]));
        assert_eq!(fast, recovery.pd.current([v(111e-6), 0.0], [(v(111e-6) - v(110e-6)) / PERIOD, 0.0]));
        // The extra derivative gain is about the continuous designs' difference in c_e.
        let loop_gain = c.ki_n_per_a * c.amp_gain_a_per_v * c.sensor_gain_v_per_m;
        let extra = 2.0 * (0.2 - 0.01) * (1e6 * c.rotor_mass_kg).sqrt() / loop_gain;
        let got = recovery.pd.kd - nominal.pd.kd;
        assert!((got / extra - 1.0).abs() < 0.2, "extra kd {got} s, continuous designs differ by {extra} s");
    }

    #[test]
    fn the_rule_waits_for_its_arming_time() {
        let nominal = PdDesign { stiffness_n_per_m: 1e6, damping_ratio: 0.01, gravity_bias: false };
        let rule = RelevSpec { enter_m: 100e-6, exit_m: 30e-6, damping_ratio: 0.2, hold_s: 0.0, arm_s: 10.0 * PERIOD };
        let mut l = Relev::new(&nominal, &rule, &LoopConstants::study(), PERIOD, 1).unwrap();
        for k in 0..10 {
            at(&mut l, k, 200e-6);
            assert_eq!(l.phase(), Phase::Nominal, "sample {k}, before arming");
        }
        at(&mut l, 10, 200e-6);
        assert_eq!(l.phase(), Phase::Recovering { calm: 0 });
    }

    #[test]
    fn parameters_default_to_fractions_of_the_air_gap() {
        let rule = RelevSpec::from_params(&Params::default(), 150e-6).unwrap();
        assert!((rule.enter_m - 120e-6).abs() < 1e-18 && (rule.exit_m - 45e-6).abs() < 1e-18, "{rule:?}");
        assert_eq!((rule.damping_ratio, rule.hold_s, rule.arm_s), (0.2, 0.05, 0.0));
        let p = Params::parse("enter_um = 100\nhold_ms = 2.5").unwrap();
        let rule = RelevSpec::from_params(&p, 150e-6).unwrap();
        assert_eq!((rule.enter_m, rule.hold_s), (100.0 * 1e-6, 2.5 * 1e-3));
    }

    #[test]
    fn bad_parameters_name_law_key_value_and_unit() {
        for (doc, needles) in [
            (
                "enter_um = 120.0\nexit_um = 200.0",
                &["law relev", "controller.params.exit_um = 200", "µm", "controller.params.enter_um = 120"][..],
            ),
            (
                "hold_ms = \"long\"",
                &["law relev", "controller.params.hold_ms = \"long\"", "ms", "expected a number"][..],
            ),
            (
                "recovery_damping_ratio = 1.5",
                &["law relev", "controller.params.recovery_damping_ratio = 1.5", "< 1"][..],
            ),
            ("enter_mm = 0.1", &["law relev", "unknown parameter controller.params.enter_mm", "enter_um, exit_um"][..]),
        ] {
            let e = RelevSpec::from_params(&Params::parse(doc).unwrap(), 150e-6).unwrap_err().to_string();
            for n in needles {
                assert!(e.contains(n), "{doc}: no {n:?} in {e}");
            }
        }
    }

    #[test]
    fn reset_forgets_the_phase() {
        let mut l = law(1e-3);
        at(&mut l, 0, 200e-6);
        assert_ne!(l.phase(), Phase::Nominal);
        l.reset();
        assert_eq!((l.phase(), l.switches()), (Phase::Nominal, 0));
    }

    #[test]
    fn bad_rules_name_their_key() {
        let nominal = PdDesign { stiffness_n_per_m: 1e6, damping_ratio: 0.01, gravity_bias: false };
        let ok = RelevSpec { enter_m: 100e-6, exit_m: 30e-6, damping_ratio: 0.2, hold_s: 0.05, arm_s: 0.0 };
        let cases = [
            (RelevSpec { exit_m: 150e-6, ..ok }, "controller.params.exit_um"),
            (RelevSpec { enter_m: -1e-6, ..ok }, "controller.params.enter_um"),
            (RelevSpec { damping_ratio: 1.5, ..ok }, "controller.params.recovery_damping_ratio"),
            (RelevSpec { hold_s: f64::NAN, ..ok }, "controller.params.hold_ms"),
            (RelevSpec { arm_s: -1.0, ..ok }, "controller.params.arm_ms"),
        ];
        for (rule, key) in cases {
            let e = Relev::new(&nominal, &rule, &LoopConstants::study(), PERIOD, 1).unwrap_err().to_string();
            assert!(e.contains(key), "{e}");
        }
    }
}
