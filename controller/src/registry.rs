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
//! ```

pub use crate::law::{BuildLaw, LawEntry};
use crate::law::{ControlLaw, Design, LawError};
use crate::params::Params;

/// Every law, in the order help texts list them.
pub const LAWS: &[LawEntry] = &[crate::pd::LAW, crate::pid::LAW, crate::pd_delay::LAW, crate::relev::LAW];

/// The entry of a law, by name.
pub fn find_law(name: &str) -> Option<&'static LawEntry> {
    LAWS.iter().find(|e| e.name == name)
}

/// The names of the registered laws.
pub fn law_names() -> Vec<&'static str> {
    LAWS.iter().map(|e| e.name).collect()
}

/// Builds law `name` from the common design and its parameters.
pub fn build_law(name: &str, design: &Design, params: &Params) -> Result<Box<dyn ControlLaw>, LawError> {
    let entry = find_law(name).ok_or_else(|| LawError::Unknown { name: name.to_string(), known: law_names() })?;
    (entry.build)(design, params)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::law::Sample;

    fn design() -> Design {
        Design {
            stiffness_n_per_m: 1e6,
            damping_ratio: 0.05,
            period_s: 5e-5,
            gravity_bias: true,
            current_limit_a: 2.0,
            delay_samples: 1,
            constants: crate::law::LoopConstants::study(),
        }
    }

    #[test]
    fn every_registered_law_builds_and_reports_its_name() {
        assert!(LAWS.len() >= 4);
        for entry in LAWS {
            let mut law = build_law(entry.name, &design(), &Params::default())
                .unwrap_or_else(|e| panic!("law {} does not build with default parameters: {e}", entry.name));
            assert_eq!(law.name(), entry.name, "law registered as {} reports another name", entry.name);
            assert!(!entry.summary.is_empty(), "{} has no summary", entry.name);
            let i = law.update(&Sample { seq: 0, t_s: 0.0, sensor_v: [0.1, -0.1] });
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
        for entry in LAWS {
            assert!(e.contains(entry.name), "{e}");
        }
    }
}
