//! The `[controller]` table of a TOML file, as the `controller` binary reads
//! it (`controller --config FILE`). A whole scene file works: other tables
//! are ignored, and so are the `[controller]` keys that only the plant uses
//! ([`PLANT_SIDE_KEYS`]). Any other key is an error naming it.

use std::path::Path;

/// `[controller]` keys that describe the connection, not the law: read by the
/// plant, accepted and ignored here.
pub const PLANT_SIDE_KEYS: &[&str] = &[
    "mode",
    "delay_samples",
    "fallback",
    "reply_timeout_ms",
    "reconnect_timeout_ms",
    "connect_timeout_ms",
    "spin_us",
    "pin_cores",
];

/// `[controller]` keys the controller process uses.
pub const LAW_KEYS: &[&str] = &[
    "law",
    "rate_hz",
    "stiffness_n_per_m",
    "damping_ratio",
    "current_limit_a",
    "gravity_bias",
    "relev_enter_um",
    "relev_exit_um",
    "relev_damping_ratio",
    "relev_hold_ms",
    "relev_arm_ms",
];

/// What a `--config` file sets; `None` = take the plant's value from the hello.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LawOverrides {
    /// Law name.
    pub law: Option<String>,
    /// Rate the controller is built for (Hz): a plant at another rate is refused.
    pub rate_hz: Option<f64>,
    /// k_e (N/m).
    pub stiffness_n_per_m: Option<f64>,
    /// ξ_e.
    pub damping_ratio: Option<f64>,
    /// i_max (A).
    pub current_limit_a: Option<f64>,
    /// Gravity bias on y.
    pub gravity_bias: Option<bool>,
    /// `relev`: touch radius (µm).
    pub relev_enter_um: Option<f64>,
    /// `relev`: levitating-again radius (µm).
    pub relev_exit_um: Option<f64>,
    /// `relev`: damping ratio of the recovery design.
    pub relev_damping_ratio: Option<f64>,
    /// `relev`: hold before the nominal design returns (ms).
    pub relev_hold_ms: Option<f64>,
    /// `relev`: time from which the rule acts (ms).
    pub relev_arm_ms: Option<f64>,
}

impl LawOverrides {
    /// The `relev` rule: these overrides on top of the plant's.
    pub fn relev(&self, plant: crate::RelevSpec) -> crate::RelevSpec {
        let or = |v: Option<f64>, scale: f64, fallback: f64| v.map_or(fallback, |v| v * scale);
        crate::RelevSpec {
            enter_m: or(self.relev_enter_um, 1e-6, plant.enter_m),
            exit_m: or(self.relev_exit_um, 1e-6, plant.exit_m),
            damping_ratio: or(self.relev_damping_ratio, 1.0, plant.damping_ratio),
            hold_s: or(self.relev_hold_ms, 1e-3, plant.hold_s),
            arm_s: or(self.relev_arm_ms, 1e-3, plant.arm_s),
        }
    }
}

/// Why a controller file was rejected.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    /// Unreadable file.
    #[error("cannot read {path}: {source}")]
    Read {
        /// Path.
        path: String,
        /// Cause.
        source: std::io::Error,
    },
    /// Bad TOML, unknown key, wrong type or out-of-range value.
    #[error("{path}: {message}")]
    Invalid {
        /// Path.
        path: String,
        /// What is wrong (names the key).
        message: String,
    },
}

/// Reads the `[controller]` table of a file.
pub fn load(path: &Path) -> Result<LawOverrides, FileError> {
    let shown = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| FileError::Read { path: shown.clone(), source })?;
    parse(&text).map_err(|message| FileError::Invalid { path: shown, message })
}

/// Parses the `[controller]` table of a TOML text.
///
/// ```
/// let o = controller::file::parse("[controller]\nrate_hz = 10000.0\nmode = \"lockstep\"\n").unwrap();
/// assert_eq!(o.rate_hz, Some(10000.0));
/// assert!(controller::file::parse("[controller]\nbogus = 1\n").unwrap_err().contains("controller.bogus"));
/// ```
pub fn parse(text: &str) -> Result<LawOverrides, String> {
    let table: toml::Table = toml::from_str(text).map_err(|e| e.to_string())?;
    let mut out = LawOverrides::default();
    let Some(section) = table.get("controller") else {
        return Ok(out);
    };
    let section = section.as_table().ok_or("`controller` is not a table")?;
    for (key, value) in section {
        let name = format!("controller.{key}");
        let number = |unit: &str| -> Result<f64, String> {
            let v = value
                .as_float()
                .or_else(|| value.as_integer().map(|i| i as f64))
                .ok_or_else(|| format!("{name} = {value}: expected a number ({unit})"))?;
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(format!("{name} = {v} {unit}: must be a finite number > 0"))
            }
        };
        let non_negative = |unit: &str| -> Result<f64, String> {
            let v = value
                .as_float()
                .or_else(|| value.as_integer().map(|i| i as f64))
                .ok_or_else(|| format!("{name} = {value}: expected a number ({unit})"))?;
            if v.is_finite() && v >= 0.0 {
                Ok(v)
            } else {
                Err(format!("{name} = {v} {unit}: must be a finite number >= 0"))
            }
        };
        match key.as_str() {
            "relev_enter_um" => out.relev_enter_um = Some(number("µm")?),
            "relev_exit_um" => out.relev_exit_um = Some(number("µm")?),
            "relev_damping_ratio" => out.relev_damping_ratio = Some(number("")?),
            "relev_hold_ms" => out.relev_hold_ms = Some(non_negative("ms")?),
            "relev_arm_ms" => out.relev_arm_ms = Some(non_negative("ms")?),
            "law" => {
                let law = value.as_str().ok_or_else(|| format!("{name} = {value}: expected a string"))?;
                if !crate::LAW_NAMES.contains(&law) {
                    return Err(crate::LawError::Unknown(law.to_string()).to_string());
                }
                out.law = Some(law.to_string());
            }
            "rate_hz" => out.rate_hz = Some(number("Hz")?),
            "stiffness_n_per_m" => out.stiffness_n_per_m = Some(number("N/m")?),
            "damping_ratio" => out.damping_ratio = Some(non_negative("")?),
            "current_limit_a" => out.current_limit_a = Some(number("A")?),
            "gravity_bias" => {
                out.gravity_bias =
                    Some(value.as_bool().ok_or_else(|| format!("{name} = {value}: expected true or false"))?)
            }
            k if PLANT_SIDE_KEYS.contains(&k) => {}
            _ => {
                return Err(format!(
                    "unknown key {name} (the controller reads {} and ignores {})",
                    LAW_KEYS.join(", "),
                    PLANT_SIDE_KEYS.join(", ")
                ))
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn out_of_range_names_key_value_and_unit() {
        let e = parse("[controller]\nrate_hz = -5.0\n").unwrap_err();
        assert!(e.contains("controller.rate_hz") && e.contains("-5") && e.contains("Hz"), "{e}");
    }

    #[test]
    fn unknown_law_lists_known_laws() {
        let e = parse("[controller]\nlaw = \"nope\"\n").unwrap_err();
        assert!(e.contains("nope") && e.contains("pd"), "{e}");
    }

    #[test]
    fn relev_keys_override_the_plants_rule() {
        let o = parse("[controller]\nrelev_enter_um = 100\nrelev_arm_ms = 0\n").unwrap();
        let plant = crate::RelevSpec { enter_m: 1.2e-4, exit_m: 4.5e-5, damping_ratio: 0.2, hold_s: 0.05, arm_s: 0.5 };
        assert_eq!(o.relev(plant), crate::RelevSpec { enter_m: 100.0 * 1e-6, arm_s: 0.0, ..plant });
        let e = parse("[controller]\nrelev_hold_ms = -1\n").unwrap_err();
        assert!(e.contains("controller.relev_hold_ms") && e.contains("ms"), "{e}");
    }

    #[test]
    fn other_tables_are_ignored() {
        let o = parse("[rotor]\nmass_kg = 3.0\n[controller]\ndamping_ratio = 0.1\n").unwrap();
        assert_eq!(o, LawOverrides { damping_ratio: Some(0.1), ..Default::default() });
    }
}
