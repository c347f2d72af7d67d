//! The `[controller]` table of a TOML file, as the `controller` binary reads
//! it (`controller --config FILE`). A whole scene file works: other tables
//! are ignored, and so are the `[controller]` keys that only the plant uses
//! ([`PLANT_SIDE_KEYS`]). Any other key is an error naming it.
//!
//! What the file sets overrides the plant's hello ([`LawOverrides::apply`]);
//! whatever that changes is sent back to the plant in the handshake
//! (`Ack.overrides`), which writes it into the run folder, so that the folder
//! reproduces the run.
//!
//! The design keys (`stiffness_n_per_m`, `damping_ratio`, `current_limit_a`,
//! `gravity_bias`) apply to every bearing plane of a two-plane hello alike.
//!
//! `[controller.params]` are the law's own parameters. With the plant's law,
//! its keys replace the hello's one by one; with another law (`law` or
//! `--law`), the hello's parameters (which belong to the plant's law) are
//! dropped and the file's are the law's. The deprecated `relev_*` keys are
//! aliases of `relev`'s parameters (a warning names the new key; giving both
//! is an error); with another law they are ignored, with a warning.

use crate::law::{Design, RotorDesign};
use crate::params::Params;
use crate::wire::{self, Hello};
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
    "command",
    "fmu",
    "lockstep_timeout_ms",
    "realtime_priority",
    "max_miss_fraction",
    "max_overrun_fraction",
    "pacing",
    "max_invalid_burst",
    "max_invalid_fraction",
];

/// `[controller]` keys the controller process uses (the `relev_*` ones are deprecated aliases
/// of `relev`'s parameters).
pub const LAW_KEYS: &[&str] = &[
    "law",
    "rate_hz",
    "stiffness_n_per_m",
    "damping_ratio",
    "current_limit_a",
    "gravity_bias",
    "params",
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
    /// `[controller.params]`, if given.
    pub params: Option<toml::Table>,
    /// Values of the deprecated `relev_*` keys, under their parameter names (`enter_um`, …).
    pub relev_aliases: toml::Table,
    /// Deprecation notes, for the user.
    pub warnings: Vec<String>,
}

/// What the controller runs for one hello.
#[derive(Debug, Clone, PartialEq)]
pub struct Applied {
    /// The law's name.
    pub law: String,
    /// The design (plane A's on a two-plane rotor).
    pub design: Design,
    /// The whole rotor's design (every plane with the overrides applied).
    pub rotor: RotorDesign,
    /// The law's parameters.
    pub params: Params,
    /// What differs from the hello, as the `[controller]` table of a scene (`law`, the design
    /// keys, `params` whole); empty if nothing.
    pub overrides: toml::Table,
    /// Notes for the user (aliases ignored with another law).
    pub warnings: Vec<String>,
}

impl Applied {
    /// The overrides as a TOML document (`[controller]` table), empty if there are none.
    pub fn overrides_document(&self) -> String {
        if self.overrides.is_empty() {
            return String::new();
        }
        let mut doc = toml::Table::new();
        doc.insert("controller".into(), toml::Value::Table(self.overrides.clone()));
        toml::to_string(&doc).unwrap_or_default()
    }
}

impl LawOverrides {
    /// These overrides on top of a hello (see the module doc).
    pub fn apply(&self, hello: &Hello) -> Result<Applied, String> {
        let plant_law = wire::str_of(&hello.law).into_owned();
        let law = self.law.clone().unwrap_or_else(|| plant_law.clone());
        let hello_params =
            Params::parse(hello.params_text().map_err(|e| e.to_string())?).map_err(|e| e.to_string())?.table().clone();
        let mut params = if law == plant_law { hello_params.clone() } else { toml::Table::new() };
        if let Some(file) = &self.params {
            params.extend(file.clone());
        }
        let mut warnings = Vec::new();
        if law == crate::relev::LAW.name {
            params.extend(self.relev_aliases.clone());
        } else {
            for key in self.relev_aliases.keys() {
                warnings.push(format!(
                    "the deprecated controller.relev_* key for `{key}` is ignored: law {law} is not relev"
                ));
            }
        }
        let mut rotor = hello.rotor_design().ok_or_else(|| format!("a hello of {} axes", hello.axes))?;
        let mut design = hello.design();
        let mut overrides = toml::Table::new();
        if law != plant_law {
            overrides.insert("law".into(), toml::Value::String(law.clone()));
        }
        let mut number = |key: &str, given: Option<f64>, field: &mut f64| {
            if let Some(v) = given {
                if v.to_bits() != field.to_bits() {
                    overrides.insert(key.into(), toml::Value::Float(v));
                }
                *field = v;
            }
        };
        number("stiffness_n_per_m", self.stiffness_n_per_m, &mut design.stiffness_n_per_m);
        number("damping_ratio", self.damping_ratio, &mut design.damping_ratio);
        number("current_limit_a", self.current_limit_a, &mut design.current_limit_a);
        if let Some(bias) = self.gravity_bias {
            if bias != design.gravity_bias {
                overrides.insert("gravity_bias".into(), toml::Value::Boolean(bias));
            }
            design.gravity_bias = bias;
        }
        if params != hello_params {
            overrides.insert("params".into(), toml::Value::Table(params.clone()));
        }
        let planes: &mut [Design] = match &mut rotor {
            RotorDesign::Planar(d) => std::slice::from_mut(d),
            RotorDesign::TwoPlane { planes, .. } => planes,
        };
        for plane in planes {
            let (stiffness, damping, limit) = (plane.stiffness_n_per_m, plane.damping_ratio, plane.current_limit_a);
            plane.stiffness_n_per_m = self.stiffness_n_per_m.unwrap_or(stiffness);
            plane.damping_ratio = self.damping_ratio.unwrap_or(damping);
            plane.current_limit_a = self.current_limit_a.unwrap_or(limit);
            plane.gravity_bias = self.gravity_bias.unwrap_or(plane.gravity_bias);
        }
        Ok(Applied { law, design, rotor, params: Params::new(params), overrides, warnings })
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

/// Reads the `[controller]` table of a file (a `law` must be of the registry).
pub fn load(path: &Path) -> Result<LawOverrides, FileError> {
    load_for(path, &crate::registry::all_law_names())
}

/// Reads the `[controller]` table of a file for a controller that serves the laws `served`.
pub fn load_for(path: &Path, served: &[&str]) -> Result<LawOverrides, FileError> {
    let shown = path.display().to_string();
    let text = read_input(path).map_err(|source| FileError::Read { path: shown.clone(), source })?;
    parse_for(&text, served).map_err(|message| FileError::Invalid { path: shown, message })
}

/// The most a `--config` file may hold (a scene file is a few kilobytes).
const MAX_FILE_BYTES: u64 = 16 << 20;

/// Reads a `--config` file without trusting it: a regular file of at most [`MAX_FILE_BYTES`]
/// (a device such as `/dev/zero` or a FIFO is refused before it is read; the plant's files go
/// through `shock_table::input`, which this crate does not depend on).
///
/// Opened with `O_NONBLOCK` (issue 40 item 7): a regular file of `/proc` such as `/proc/kmsg`
/// would wait in its read; a file whose size is 0 but which reads bytes or would wait is refused.
fn read_input(path: &Path) -> std::io::Result<String> {
    use std::io::{Error, ErrorKind, Read};
    let refuse = |why: &str| Error::new(ErrorKind::InvalidInput, why.to_string());
    if !std::fs::metadata(path)?.is_file() {
        return Err(refuse("not a regular file (a device, a FIFO or a folder)"));
    }
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::fs::OpenOptionsExt;
        // Linux's O_NONBLOCK, written here: this crate's libc is only in its `ipc` feature.
        const O_NONBLOCK: i32 = 0o4000;
        options.custom_flags(O_NONBLOCK);
    }
    let file = options.open(path)?;
    let meta = file.metadata()?;
    if !meta.is_file() {
        return Err(refuse("not a regular file (a device, a FIFO or a folder)"));
    }
    let mut text = String::new();
    match file.take(MAX_FILE_BYTES + 1).read_to_string(&mut text) {
        Err(e) if e.kind() == ErrorKind::WouldBlock => {
            return Err(refuse(
                "not a regular file with a size: reading it would wait (a file of /proc such as /proc/kmsg)",
            ))
        }
        r => r?,
    };
    if meta.len() == 0 && !text.is_empty() {
        return Err(refuse(
            "not a regular file with a size: its size is 0 but reading it gives bytes (a file of /proc or /sys)",
        ));
    }
    if text.len() as u64 > MAX_FILE_BYTES {
        return Err(Error::new(ErrorKind::InvalidInput, format!("more than {MAX_FILE_BYTES} bytes")));
    }
    Ok(text)
}

/// Parses the `[controller]` table of a TOML text.
///
/// ```
/// let o = controller::file::parse("[controller]\nrate_hz = 10000.0\nmode = \"lockstep\"\n").unwrap();
/// assert_eq!(o.rate_hz, Some(10000.0));
/// assert!(controller::file::parse("[controller]\nbogus = 1\n").unwrap_err().contains("controller.bogus"));
/// ```
pub fn parse(text: &str) -> Result<LawOverrides, String> {
    parse_for(text, &crate::registry::all_law_names())
}

/// [`parse`] for a controller that serves the laws `served` (a `law` must be one of them).
pub fn parse_for(text: &str, served: &[&str]) -> Result<LawOverrides, String> {
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
        if let Some((old, new)) = crate::relev::ALIASES.iter().find(|(old, _)| old == key) {
            if !(value.is_float() || value.is_integer()) {
                return Err(format!("{name} = {value}: expected a number"));
            }
            out.relev_aliases.insert(new.to_string(), value.clone());
            out.warnings.push(format!("controller.{old} is deprecated: write controller.params.{new} (law relev)"));
            continue;
        }
        match key.as_str() {
            "law" => {
                let law = value.as_str().ok_or_else(|| format!("{name} = {value}: expected a string"))?;
                if !served.contains(&law) {
                    return Err(format!(
                        "{name} = {law:?}: unknown law (this controller serves {})",
                        served.join(", ")
                    ));
                }
                out.law = Some(law.to_string());
            }
            "rate_hz" => out.rate_hz = Some(number("Hz")?),
            "stiffness_n_per_m" => out.stiffness_n_per_m = Some(number("N/m")?),
            "damping_ratio" => {
                let v = value
                    .as_float()
                    .or_else(|| value.as_integer().map(|i| i as f64))
                    .ok_or_else(|| format!("{name} = {value}: expected a number"))?;
                if !(v.is_finite() && v >= 0.0) {
                    return Err(format!("{name} = {v}: must be a finite number >= 0"));
                }
                out.damping_ratio = Some(v);
            }
            "current_limit_a" => out.current_limit_a = Some(number("A")?),
            "gravity_bias" => {
                out.gravity_bias =
                    Some(value.as_bool().ok_or_else(|| format!("{name} = {value}: expected true or false"))?)
            }
            "params" => {
                let t = value.as_table().ok_or_else(|| format!("{name} = {value}: expected a table"))?;
                out.params = Some(t.clone());
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
    if let Some(params) = &out.params {
        for (old, new) in crate::relev::ALIASES {
            if out.relev_aliases.contains_key(*new) && params.contains_key(*new) {
                return Err(format!(
                    "both controller.{old} (deprecated) and controller.params.{new} are given: keep controller.params.{new}"
                ));
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
    fn relev_aliases_become_parameters_with_a_warning() {
        let o = parse("[controller]\nrelev_enter_um = 100\nrelev_arm_ms = 0\n").unwrap();
        let mut hello = Hello::new("r", "relev", &Hello::example("r").design(), 20_000.0, "hold_ms = 20.0\n").unwrap();
        hello.session = 1;
        let a = o.apply(&hello).unwrap();
        let p = a.params.table();
        assert_eq!(p["enter_um"].as_integer(), Some(100));
        assert_eq!(p["arm_ms"].as_integer(), Some(0));
        assert_eq!(p["hold_ms"].as_float(), Some(20.0), "the hello's parameters are kept");
        assert_eq!(o.warnings.len(), 2);
        assert!(
            o.warnings
                .iter()
                .any(|w| w.contains("controller.relev_enter_um") && w.contains("controller.params.enter_um")),
            "{:?}",
            o.warnings
        );
        // What changed goes back to the plant: the whole parameter table.
        assert_eq!(a.overrides["params"].as_table(), Some(p));
        assert!(a.overrides_document().contains("[controller.params]"), "{}", a.overrides_document());
    }

    #[test]
    fn an_alias_and_its_parameter_together_are_refused() {
        let e = parse("[controller]\nrelev_hold_ms = 5\n[controller.params]\nhold_ms = 6\n").unwrap_err();
        assert!(e.contains("controller.relev_hold_ms") && e.contains("controller.params.hold_ms"), "{e}");
    }

    #[test]
    fn another_law_drops_the_plants_parameters() {
        let o = parse("[controller]\nlaw = \"pd\"\n").unwrap();
        let hello = Hello::new("r", "relev", &Hello::example("r").design(), 20_000.0, "hold_ms = 20.0\n").unwrap();
        let a = o.apply(&hello).unwrap();
        assert_eq!(a.law, "pd");
        assert!(a.params.is_empty());
        assert_eq!(a.overrides["law"].as_str(), Some("pd"));
        assert_eq!(a.overrides["params"].as_table().map(|t| t.len()), Some(0));
    }

    #[test]
    fn nothing_changed_means_no_overrides() {
        let o = parse("[controller]\ndamping_ratio = 0.01\nmode = \"lockstep\"\n").unwrap();
        let a = o.apply(&Hello::example("r")).unwrap();
        assert!(a.overrides.is_empty(), "{:?}", a.overrides);
        assert_eq!(a.overrides_document(), "");
        let o = parse("[controller]\ndamping_ratio = 0.02\n").unwrap();
        let a = o.apply(&Hello::example("r")).unwrap();
        assert_eq!(a.design.damping_ratio, 0.02);
        assert_eq!(a.overrides_document(), "[controller]\ndamping_ratio = 0.02\n");
    }

    #[test]
    fn the_design_keys_apply_to_both_planes_of_a_two_plane_hello() {
        let o = parse("[controller]\nstiffness_n_per_m = 2e6\ncurrent_limit_a = 3.0\n").unwrap();
        let a = o.apply(&Hello::example_two_plane("r")).unwrap();
        for plane in a.rotor.planes() {
            assert_eq!((plane.stiffness_n_per_m, plane.current_limit_a, plane.damping_ratio), (2e6, 3.0, 0.01));
        }
        assert_eq!(a.rotor.planes().len(), 2);
        assert_eq!(a.design, a.rotor.planes()[0]);
        assert_eq!(a.overrides_document(), "[controller]\ncurrent_limit_a = 3.0\nstiffness_n_per_m = 2000000.0\n");
        let planar = o.apply(&Hello::example("r")).unwrap();
        assert_eq!(planar.rotor, RotorDesign::Planar(planar.design));
    }

    #[test]
    fn other_tables_are_ignored() {
        let o = parse("[rotor]\nmass_kg = 3.0\n[controller]\ndamping_ratio = 0.1\n").unwrap();
        assert_eq!(o, LawOverrides { damping_ratio: Some(0.1), ..Default::default() });
    }
}
