//! The one list of the built-in control laws: the only place where the laws
//! are named together. Each law's file defines its [`LawEntry`] (`pd::LAW`,
//! …; the type lives beside [`ControlLaw`] in [`crate::law`] and is
//! re-exported here) with its name, a one-line summary and its constructor;
//! adding a law is that file plus one line here. Nothing but this list and
//! its look-ups lives here: the laws do not import the registry.
//!
//! ```
//! use controller::{registry, Params};
//! let design = controller::wire::Hello::example("run").design();
//! let law = registry::build_law("pd", &design, &Params::default()).unwrap();
//! assert_eq!(law.name(), "pd");
//! assert!(registry::build_law("nope", &design, &Params::default()).is_err());
//! // Any law on a two-plane rotor (a per-plane law runs once per plane):
//! let rotor = controller::RotorDesign::symmetric_study();
//! assert_eq!(registry::build_rotor_law("modal", &rotor, &Params::default()).unwrap().name(), "modal");
//! assert_eq!(registry::build_rotor_law("relev", &rotor, &Params::default()).unwrap().name(), "relev");
//! ```

use crate::law::{build_among, AnyLaw, ControlLaw, Design, LawError, RotorDesign, RotorLaw, RotorLawEntry};
pub use crate::law::{BuildLaw, LawEntry};
use crate::params::Params;

/// Every per-plane law, in the order help texts list them: each runs the planar model and,
/// one instance per plane, the two-plane rotor.
pub const LAWS: &[LawEntry] = &[
    crate::pd::LAW,
    crate::pid::LAW,
    crate::pd_delay::LAW,
    crate::relev::LAW,
    crate::notch::LAW,
    crate::ross_pid::LAW,
    crate::transfer_function::LAW,
];

/// Every law of the whole rotor (`modal` drives the two-plane rotor only, `state_space` both).
pub const ROTOR_LAWS: &[RotorLawEntry] = &[crate::modal::LAW, crate::state_space::LAW];

/// Every law of either kind: what the `controller` binary serves.
pub const ALL_LAWS: &[AnyLaw] = &[
    AnyLaw::Plane(crate::pd::LAW),
    AnyLaw::Plane(crate::pid::LAW),
    AnyLaw::Plane(crate::pd_delay::LAW),
    AnyLaw::Plane(crate::relev::LAW),
    AnyLaw::Plane(crate::notch::LAW),
    AnyLaw::Plane(crate::ross_pid::LAW),
    AnyLaw::Plane(crate::transfer_function::LAW),
    AnyLaw::Rotor(crate::modal::LAW),
    AnyLaw::Rotor(crate::state_space::LAW),
];

/// The entry of a per-plane law, by name.
pub fn find_law(name: &str) -> Option<&'static LawEntry> {
    LAWS.iter().find(|e| e.name == name)
}

/// The names of the per-plane laws (the laws a planar scene can name).
pub fn law_names() -> Vec<&'static str> {
    LAWS.iter().map(|e| e.name).collect()
}

/// The names of every law, per-plane and of the whole rotor.
pub fn all_law_names() -> Vec<&'static str> {
    ALL_LAWS.iter().map(AnyLaw::name).collect()
}

/// Builds per-plane law `name` from one plane's design and its parameters (the planar
/// model's law, or one plane's). A law of the whole rotor is refused ([`LawError::Axes`]),
/// an unknown name naming every law.
pub fn build_law(name: &str, design: &Design, params: &Params) -> Result<Box<dyn ControlLaw>, LawError> {
    if let Some(entry) = find_law(name) {
        return (entry.build)(design, params);
    }
    match ROTOR_LAWS.iter().find(|e| e.name == name) {
        // Not "two-plane only": state_space drives a planar rotor too, as a law of the rotor.
        Some(e) => Err(LawError::Axes {
            law: e.name,
            axes: 2,
            drives: "the whole rotor at once, not one plane (build it with build_rotor_law)",
        }),
        None => Err(LawError::Unknown { name: name.to_string(), known: all_law_names() }),
    }
}

/// Builds law `name` (any kind) for a rotor: a per-plane law once per plane, each from its
/// plane's design; a law of the whole rotor from the whole design.
pub fn build_rotor_law(name: &str, design: &RotorDesign, params: &Params) -> Result<Box<dyn RotorLaw>, LawError> {
    build_among(ALL_LAWS, name, design, params)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::law::{LoopConstants, Sample};

    fn design() -> Design {
        Design {
            stiffness_n_per_m: 1e6,
            damping_ratio: 0.05,
            period_s: 5e-5,
            gravity_bias: true,
            current_limit_a: 2.0,
            delay_samples: 1,
            constants: LoopConstants::study(),
        }
    }

    /// A law that says it is a PD around levitation ([`ControlLaw::linear_pd`], the closed form
    /// `plant assess` grades it against) answers exactly as that PD does, the rate as the
    /// backward difference, on small motions; `pid` (an integral) says it is none.
    #[test]
    fn a_law_that_says_it_is_a_pd_is_that_pd() {
        let d = design();
        let mut claimed = Vec::new();
        for entry in LAWS {
            let mut law = build_law(entry.name, &d, &Params::default()).unwrap();
            let Some(linear) = law.linear_pd() else { continue };
            // The PD of the design with the gains the law says (bias and amplifier gain are the
            // design's).
            let g = crate::pd::PdGains {
                kp: linear.kp,
                kd: linear.kd,
                ..crate::pd::PdGains::from_design(&d.pd(), &d.constants).unwrap()
            };
            claimed.push(entry.name);
            let mut prev: Option<[f64; 2]> = None;
            for k in 0..20u64 {
                let phase = k as f64 * 0.7;
                let u = [1e-3 * phase.sin(), -2e-3 * phase.cos()];
                let rate = prev.map_or([0.0; 2], |p| [(u[0] - p[0]) / d.period_s, (u[1] - p[1]) / d.period_s]);
                prev = Some(u);
                let sample = Sample { seq: k, t_s: k as f64 * d.period_s, sensor_v: u, ..Default::default() };
                assert_eq!(law.update(&sample), g.current(u, rate), "{} at sample {k}", entry.name);
            }
        }
        assert_eq!(claimed, ["pd", "pd_delay", "relev"]);
    }

    #[test]
    fn every_registered_law_builds_and_reports_its_name() {
        assert!(LAWS.len() >= 4);
        for entry in LAWS {
            let mut law = build_law(entry.name, &design(), &Params::default())
                .unwrap_or_else(|e| panic!("law {} does not build with default parameters: {e}", entry.name));
            assert_eq!(law.name(), entry.name, "law registered as {} reports another name", entry.name);
            assert!(!entry.summary.is_empty(), "{} has no summary", entry.name);
            let i = law.update(&Sample { seq: 0, t_s: 0.0, sensor_v: [0.1, -0.1], ..Default::default() });
            assert!(i.iter().all(|v| v.is_finite()), "{}: {i:?}", entry.name);
        }
    }

    #[test]
    fn names_are_unique() {
        let mut names = law_names();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), LAWS.len());
    }

    #[test]
    fn every_law_refuses_a_parameter_it_does_not_read() {
        let p = Params::parse("no_such_key = 1.0").unwrap();
        for entry in LAWS {
            let e = build_law(entry.name, &design(), &p).err().map(|e| e.to_string()).unwrap_or_default();
            assert!(
                e.contains(&format!("law {}", entry.name)) && e.contains("controller.params.no_such_key"),
                "{}: {e}",
                entry.name
            );
        }
    }

    #[test]
    fn unknown_law_lists_the_known_ones() {
        let e = build_law("nope", &design(), &Params::default()).err().unwrap().to_string();
        for name in all_law_names() {
            assert!(e.contains(name), "{e}");
        }
        let e = build_law("modal", &design(), &Params::default()).err().unwrap();
        assert!(matches!(e, LawError::Axes { law: "modal", axes: 2, .. }), "{e:?}");
        // state_space drives a planar rotor too: the refusal says why it is not a plane's law.
        let e = build_law("state_space", &design(), &Params::default()).err().unwrap().to_string();
        assert!(e.contains("the whole rotor at once") && !e.contains("two-plane"), "{e}");
    }

    /// A per-plane law on the two-plane rotor is that law once per plane, each built from its
    /// own plane's design: with identical planes each plane's currents are the planar law's,
    /// bit for bit; with plane B's design changed, plane B's follow its own design.
    #[test]
    fn per_plane_laws_run_decentralised_from_each_planes_design() {
        use crate::law::{RotorSample, ROTOR_AXES};
        let samples: Vec<RotorSample> = (0..40)
            .map(|k| RotorSample {
                seq: k,
                t_s: k as f64 * 5e-5,
                axes: 4,
                sensor_v: [0.01 * k as f64, -0.02, 0.5 - 0.01 * k as f64, 0.03 * (k % 3) as f64],
                speed_rad_s: 3000.0,
                angle_rad: 0.1 * k as f64,
            })
            .collect();
        let a = design();
        let b = Design { stiffness_n_per_m: 2e6, constants: LoopConstants { rotor_mass_kg: 7.0, ..a.constants }, ..a };
        let geometry = crate::law::Geometry::symmetric_study();
        for entry in LAWS {
            let mut rotor =
                build_rotor_law(entry.name, &RotorDesign::TwoPlane { planes: [a, b], geometry }, &Params::default())
                    .unwrap();
            let mut law_a = build_law(entry.name, &a, &Params::default()).unwrap();
            let mut law_b = build_law(entry.name, &b, &Params::default()).unwrap();
            for s in &samples {
                let i: [f64; ROTOR_AXES] = rotor.update(s);
                let (ia, ib) = (law_a.update(&s.plane(0)), law_b.update(&s.plane(1)));
                assert_eq!(i.map(f64::to_bits), [ia[0], ia[1], ib[0], ib[1]].map(f64::to_bits), "{}", entry.name);
            }
        }
    }
}
