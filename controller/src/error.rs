//! Why a law could not be built: one error type for the laws, their parameters and the
//! registry. A module of its own so that the parameter reader ([`crate::params`]) and the law
//! contract ([`crate::law`], which names [`crate::Params`]) both use it without depending on
//! each other.

/// Why a law could not be built.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum LawError {
    /// The name is not among the laws on offer (the registry's, or the set a controller
    /// process serves).
    #[error("unknown controller law `{name}` (known laws: {known})", known = known.join(", "))]
    Unknown {
        /// The name asked for.
        name: String,
        /// The names that were on offer.
        known: Vec<&'static str>,
    },
    /// The law cannot drive a rotor with this many axes (a law of the two-plane rotor on the
    /// planar model). A controller answers a hello with it by refusal code 3 (axes).
    #[error("law {law} drives {drives}; this rotor has {axes} axes")]
    Axes {
        /// The law.
        law: &'static str,
        /// The rotor's axes.
        axes: u32,
        /// What the law drives, in words ("a two-plane rotor (4 axes)").
        drives: &'static str,
    },
    /// A value of the common design is out of range.
    #[error("{key} = {value} {unit}: {why}")]
    Design {
        /// Config key.
        key: &'static str,
        /// Offending value.
        value: f64,
        /// Unit of the value.
        unit: &'static str,
        /// What is wrong.
        why: &'static str,
    },
    /// One of the law's own parameters (`[controller.params]`) is refused: wrong type or out
    /// of range.
    #[error("law {law}: controller.params.{key} = {value}{unit}: {why}", unit = unit_suffix(unit))]
    Param {
        /// The law.
        law: &'static str,
        /// The parameter's key inside `[controller.params]`.
        key: String,
        /// The value as given (TOML).
        value: String,
        /// Its unit (empty if dimensionless).
        unit: &'static str,
        /// What is wrong.
        why: String,
    },
    /// The law refuses the design it was given, for a reason of its own (a law of the C API
    /// whose `build` returned NULL, with its message).
    #[error("law {law}: {why}")]
    Refused {
        /// The law.
        law: &'static str,
        /// Its reason.
        why: String,
    },
    /// `[controller.params]` holds a key the law does not read.
    #[error("law {law}: unknown parameter controller.params.{key} = {value} (law {law} reads {known})", known = known_list(known))]
    UnknownParam {
        /// The law.
        law: &'static str,
        /// The key.
        key: String,
        /// Its value as given (TOML).
        value: String,
        /// The keys the law reads.
        known: Vec<&'static str>,
    },
}

fn unit_suffix(unit: &str) -> String {
    if unit.is_empty() {
        String::new()
    } else {
        format!(" {unit}")
    }
}

fn known_list(known: &[&str]) -> String {
    if known.is_empty() {
        "no parameters".to_string()
    } else {
        known.join(", ")
    }
}
