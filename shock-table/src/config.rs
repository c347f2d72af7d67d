//! TOML configuration of shocks.
//!
//! Raw specs ([`ShockSpec`], tagged by `kind`, unknown keys rejected, units
//! in the key names) are validated into a [`Programme`] by
//! [`programme_from_specs`]; one conversion to SI happens there
//! (`1 G = 9.80665 m/s²`, degrees → radians). Errors name the key, the
//! value and the unit, e.g. `shock[0].f2_hz = -3 Hz: must be > 0`.
//!
//! ```toml
//! [[shock]]
//! kind = "double_half_sine"   # BV043/85
//! peak_g = 10.0               # a_1 in G; or design_accel_g = 20.0 (A_0 = 2 a_1); exactly one
//! f1_hz = 10.0
//! f2_hz = 80.0                # > f1_hz
//! start_s = 0.02              # default 0
//! direction_deg = 90.0        # from +x; default 90 (+y, lifts the base)
//!
//! [[shock]]
//! kind = "half_sine"
//! peak_g = 5.0
//! duration_s = 0.011
//! start_s = 0.5
//!
//! [[shock]]
//! kind = "sine"
//! amplitude_g = 1.0
//! freq_hz = 20.0
//! cycles = 40
//! start_s = 1.0
//!
//! [[shock]]
//! kind = "recorded"
//! file = "records/hit.csv"    # relative to the config file's directory
//! scale = 1.0                 # default 1
//! start_s = 2.0
//! ```

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::double_half_sine::{check_corners, DoubleHalfSine};
use crate::error::{invalid, require_finite, require_non_negative, require_positive, ShockError};
use crate::half_sine::HalfSine;
use crate::programme::{Programme, Shock};
use crate::pulse::Pulse;
use crate::recorded::Recorded;
use crate::sine::SineVibration;
use crate::G0_M_S2;

/// Default `direction_deg`: 90° (+y, the base is lifted).
pub const DEFAULT_DIRECTION_DEG: f64 = 90.0;

fn default_direction_deg() -> f64 {
    DEFAULT_DIRECTION_DEG
}

fn default_scale() -> f64 {
    1.0
}

fn is_default_scale(x: &f64) -> bool {
    *x == 1.0
}

/// One `[[shock]]` table as written in TOML (raw, unvalidated). Tagged by
/// `kind`; unknown keys are rejected. Every kind also takes `start_s`
/// (start time, s, ≥ 0, default 0) and `direction_deg` (direction from +x,
/// degrees, default 90 = +y).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ShockSpec {
    /// BV043/85 double half-sine (`kind = "double_half_sine"`).
    DoubleHalfSine {
        /// Peak acceleration `a_1` of the pulse, G (> 0). Exactly one of
        /// `peak_g` and `design_accel_g`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        peak_g: Option<f64>,
        /// Design acceleration `A_0 = 2 a_1`, G (> 0). Exactly one of
        /// `peak_g` and `design_accel_g`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        design_accel_g: Option<f64>,
        /// Lower SRS corner frequency `f_1`, Hz (> 0).
        f1_hz: f64,
        /// Upper SRS corner frequency `f_2`, Hz (> `f1_hz`).
        f2_hz: f64,
        /// Start time, s (≥ 0, default 0).
        #[serde(default)]
        start_s: f64,
        /// Direction from +x, degrees (default 90 = +y).
        #[serde(default = "default_direction_deg")]
        direction_deg: f64,
    },
    /// Single positive half-sine (`kind = "half_sine"`); leaves the base
    /// moving at `2PT/π`.
    HalfSine {
        /// Peak acceleration, G (> 0).
        peak_g: f64,
        /// Duration, s (> 0).
        duration_s: f64,
        /// Start time, s (≥ 0, default 0).
        #[serde(default)]
        start_s: f64,
        /// Direction from +x, degrees (default 90 = +y).
        #[serde(default = "default_direction_deg")]
        direction_deg: f64,
    },
    /// Sinusoidal vibration over whole cycles (`kind = "sine"`).
    Sine {
        /// Acceleration amplitude, G (> 0).
        amplitude_g: f64,
        /// Frequency, Hz (> 0).
        freq_hz: f64,
        /// Number of whole cycles (≥ 1).
        cycles: i64,
        /// Start time, s (≥ 0, default 0).
        #[serde(default)]
        start_s: f64,
        /// Direction from +x, degrees (default 90 = +y).
        #[serde(default = "default_direction_deg")]
        direction_deg: f64,
    },
    /// Measured acceleration record from a CSV file (`kind = "recorded"`,
    /// header `t_s,accel_m_s2`).
    Recorded {
        /// CSV file, relative to the configuration file's directory.
        file: PathBuf,
        /// Factor on the recorded acceleration (dimensionless, finite,
        /// ≠ 0; default 1).
        #[serde(default = "default_scale", skip_serializing_if = "is_default_scale")]
        scale: f64,
        /// Start time, s (≥ 0, default 0).
        #[serde(default)]
        start_s: f64,
        /// Direction from +x, degrees (default 90 = +y).
        #[serde(default = "default_direction_deg")]
        direction_deg: f64,
    },
}

/// A standalone programme file: an array of `[[shock]]` tables at top level.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProgrammeSpec {
    /// The shocks, in any order.
    #[serde(default)]
    pub shock: Vec<ShockSpec>,
}

impl ShockSpec {
    /// The field that sets the shock's size and its value (`peak_g`, `design_accel_g`,
    /// `amplitude_g` or a recorded pulse's `scale`); `None` for a double half-sine given
    /// neither.
    pub fn size(&self) -> Option<(&'static str, f64)> {
        match self {
            ShockSpec::DoubleHalfSine { peak_g: Some(p), .. } => Some(("peak_g", *p)),
            ShockSpec::DoubleHalfSine { design_accel_g: Some(a), .. } => Some(("design_accel_g", *a)),
            ShockSpec::DoubleHalfSine { .. } => None,
            ShockSpec::HalfSine { peak_g, .. } => Some(("peak_g", *peak_g)),
            ShockSpec::Sine { amplitude_g, .. } => Some(("amplitude_g", *amplitude_g)),
            ShockSpec::Recorded { scale, .. } => Some(("scale", *scale)),
        }
    }

    /// The peak acceleration (G): a double half-sine's `a_1` (`A_0 / 2` when given as its
    /// design acceleration), a half-sine's peak, a sine's amplitude; NaN for a recorded pulse
    /// (its peak is in its file).
    pub fn peak_g(&self) -> f64 {
        match self {
            ShockSpec::DoubleHalfSine { peak_g: Some(p), .. } => *p,
            ShockSpec::DoubleHalfSine { design_accel_g: Some(a0), .. } => a0 / 2.0,
            ShockSpec::HalfSine { peak_g, .. } => *peak_g,
            ShockSpec::Sine { amplitude_g, .. } => *amplitude_g,
            _ => f64::NAN,
        }
    }

    /// The direction from +x (degrees).
    pub fn direction_deg(&self) -> f64 {
        match self {
            ShockSpec::DoubleHalfSine { direction_deg, .. }
            | ShockSpec::HalfSine { direction_deg, .. }
            | ShockSpec::Sine { direction_deg, .. }
            | ShockSpec::Recorded { direction_deg, .. } => *direction_deg,
        }
    }

    /// Validate this spec into a [`Shock`]; a recorded shock's file is
    /// resolved against `base_dir`. Error keys are unprefixed (`f2_hz`);
    /// [`programme_from_specs`] adds `shock[i].`.
    pub fn to_shock(&self, base_dir: &Path) -> Result<Shock, ShockError> {
        let (pulse, start_s, direction_deg) = match self {
            ShockSpec::DoubleHalfSine { peak_g, design_accel_g, f1_hz, f2_hz, start_s, direction_deg } => {
                let pulse = match (peak_g, design_accel_g) {
                    (Some(p), None) => {
                        require_positive("peak_g", *p, "G")?;
                        check_corners(*f1_hz, *f2_hz)?;
                        DoubleHalfSine::from_peak(p * G0_M_S2, *f1_hz, *f2_hz)?
                    }
                    (None, Some(a0)) => {
                        require_positive("design_accel_g", *a0, "G")?;
                        check_corners(*f1_hz, *f2_hz)?;
                        DoubleHalfSine::from_design(a0 * G0_M_S2, *f1_hz, *f2_hz)?
                    }
                    (Some(_), Some(_)) => {
                        return Err(ShockError::InvalidConfig {
                            key: "peak_g".into(),
                            reason: "give exactly one of peak_g (peak a_1, G) and design_accel_g \
                                     (A_0 = 2 a_1, G), not both"
                                .into(),
                        })
                    }
                    (None, None) => {
                        return Err(ShockError::InvalidConfig {
                            key: "peak_g".into(),
                            reason: "missing: give exactly one of peak_g (peak a_1, G) and \
                                     design_accel_g (A_0 = 2 a_1, G)"
                                .into(),
                        })
                    }
                };
                (Pulse::from(pulse), *start_s, *direction_deg)
            }
            ShockSpec::HalfSine { peak_g, duration_s, start_s, direction_deg } => {
                require_positive("peak_g", *peak_g, "G")?;
                require_positive("duration_s", *duration_s, "s")?;
                let p = HalfSine::new(peak_g * G0_M_S2, *duration_s)?;
                (Pulse::from(p), *start_s, *direction_deg)
            }
            ShockSpec::Sine { amplitude_g, freq_hz, cycles, start_s, direction_deg } => {
                require_positive("amplitude_g", *amplitude_g, "G")?;
                require_positive("freq_hz", *freq_hz, "Hz")?;
                let n = u32::try_from(*cycles)
                    .ok()
                    .filter(|&n| n >= 1)
                    .ok_or_else(|| invalid("cycles", *cycles as f64, "", "must be an integer >= 1"))?;
                let p = SineVibration::new(amplitude_g * G0_M_S2, *freq_hz, n)?;
                (Pulse::from(p), *start_s, *direction_deg)
            }
            ShockSpec::Recorded { file, scale, start_s, direction_deg } => {
                require_finite("scale", *scale, "")?;
                if *scale == 0.0 {
                    return Err(invalid("scale", *scale, "", "must be nonzero"));
                }
                let r = Recorded::from_csv(&base_dir.join(file))?;
                let r = if *scale == 1.0 { r } else { r.scaled(*scale) };
                (Pulse::from(r), *start_s, *direction_deg)
            }
        };
        require_non_negative("start_s", start_s, "s")?;
        require_finite("direction_deg", direction_deg, "deg")?;
        Shock::new(pulse, start_s, direction_deg.to_radians())
    }
}

/// Validate raw specs into a [`Programme`]. Files of recorded shocks are
/// resolved against `base_dir` (the configuration file's directory).
/// Errors name the shock, key, value and unit:
/// `shock[0].f2_hz = -3 Hz: must be > 0`.
pub fn programme_from_specs(specs: &[ShockSpec], base_dir: &Path) -> Result<Programme, ShockError> {
    let shocks = specs
        .iter()
        .enumerate()
        .map(|(i, s)| s.to_shock(base_dir).map_err(|e| e.in_shock(i, "file")))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Programme::new(shocks))
}

/// Parse a programme from TOML text (`[[shock]]` tables at top level);
/// `path` is named in errors and its directory resolves recorded files.
pub fn parse_programme(text: &str, path: &Path) -> Result<Programme, ShockError> {
    let spec: ProgrammeSpec =
        toml::from_str(text).map_err(|error| ShockError::Toml { path: path.to_path_buf(), error })?;
    let base = path.parent().unwrap_or(Path::new("."));
    programme_from_specs(&spec.shock, base)
}

/// Load a standalone programme file (`[[shock]]` tables at top level).
/// Recorded files are resolved against the file's directory.
pub fn load_programme(path: &Path) -> Result<Programme, ShockError> {
    let text = crate::input::read_text(path, crate::input::MAX_TOML_BYTES)
        .map_err(|error| ShockError::Io { path: path.to_path_buf(), error })?;
    parse_programme(&text, path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    /// A double half-sine given by its design acceleration A₀ peaks at a₁ = A₀/2 (BV043/85),
    /// is sized by that field, and keeps its direction; a recorded pulse's peak is in its file.
    #[test]
    fn a_shock_names_its_size_peak_and_direction() {
        let design = ShockSpec::DoubleHalfSine {
            peak_g: None,
            design_accel_g: Some(24.0),
            f1_hz: 10.0,
            f2_hz: 80.0,
            start_s: 0.0,
            direction_deg: 30.0,
        };
        assert_eq!(design.size(), Some(("design_accel_g", 24.0)));
        assert_eq!(design.peak_g(), 12.0);
        assert_eq!(design.direction_deg(), 30.0);
        let neither = ShockSpec::DoubleHalfSine {
            peak_g: None,
            design_accel_g: None,
            f1_hz: 10.0,
            f2_hz: 80.0,
            start_s: 0.0,
            direction_deg: 90.0,
        };
        assert_eq!(neither.size(), None);
        assert!(neither.peak_g().is_nan());
    }

    const EXAMPLE: &str = r#"
[[shock]]
kind = "double_half_sine"
peak_g = 10.0
f1_hz = 10.0
f2_hz = 80.0
start_s = 0.02
direction_deg = 90.0

[[shock]]
kind = "half_sine"
peak_g = 5.0
duration_s = 0.011
start_s = 0.5

[[shock]]
kind = "sine"
amplitude_g = 1.0
freq_hz = 20.0
cycles = 40
start_s = 1.0

[[shock]]
kind = "recorded"
file = "records/hit.csv"
scale = 2.0
start_s = 2.0
direction_deg = 0.0
"#;

    /// A scratch directory unique to this test.
    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("shock-table-config-{}-{name}", std::process::id()));
        std::fs::create_dir_all(d.join("records")).unwrap();
        d
    }

    fn parse_err(toml_text: &str) -> String {
        parse_programme(toml_text, Path::new("scene.toml")).unwrap_err().to_string()
    }

    #[test]
    fn example_programme_loads() {
        let dir = scratch("example");
        std::fs::write(dir.join("records/hit.csv"), "t_s,accel_m_s2\n0,1\n0.01,1\n").unwrap();
        let path = dir.join("prog.toml");
        std::fs::write(&path, EXAMPLE).unwrap();
        let p = load_programme(&path).unwrap();
        assert_eq!(p.shocks.len(), 4);
        let s0 = &p.shocks[0];
        assert_eq!(s0.start, 0.02);
        assert_eq!(s0.direction(), FRAC_PI_2);
        match &s0.pulse {
            Pulse::DoubleHalfSine(d) => assert!((d.a1 - 10.0 * G0_M_S2).abs() < 1e-12),
            other => panic!("{other:?}"),
        }
        assert_eq!(p.shocks[1].direction(), FRAC_PI_2, "default direction");
        assert!((p.shocks[2].pulse.duration() - 2.0).abs() < 1e-15);
        // recorded: scale 2, along +x, starts at 2 s
        let k = p.eval(2.01);
        assert!((k.vel[0] - 2.0 * 0.01).abs() < 1e-15);
        let want_y: f64 = p.shocks[..3].iter().map(|s| s.pulse.eval(2.01 - s.start).vel).sum();
        assert!((k.vel[1] - want_y).abs() < 1e-15);
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn spec_round_trips_through_toml() {
        let spec: ProgrammeSpec = toml::from_str(EXAMPLE).unwrap();
        let text = toml::to_string(&spec).unwrap();
        let back: ProgrammeSpec = toml::from_str(&text).unwrap();
        assert_eq!(spec, back);
    }

    #[test]
    fn design_accel_is_twice_peak() {
        let a = r#"[[shock]]
kind = "double_half_sine"
design_accel_g = 20.0
f1_hz = 10.0
f2_hz = 80.0"#;
        let p = parse_programme(a, Path::new("x.toml")).unwrap();
        let b = parse_programme(&a.replace("design_accel_g = 20.0", "peak_g = 10.0"), Path::new("x.toml")).unwrap();
        assert_eq!(p, b);
        assert_eq!(p.shocks[0].start, 0.0);
    }

    #[test]
    fn errors_name_key_value_and_unit() {
        let base = "[[shock]]\nkind = \"double_half_sine\"\npeak_g = 10.0\nf1_hz = 10.0\nf2_hz = 80.0\n";
        let cases = [
            (base.replace("f2_hz = 80.0", "f2_hz = -3.0"), "shock[0].f2_hz = -3 Hz: must be > 0"),
            (base.replace("f2_hz = 80.0", "f2_hz = 5.0"), "shock[0].f2_hz = 5 Hz: must be > f1_hz = 10 Hz"),
            (base.replace("peak_g = 10.0", "peak_g = 0.0"), "shock[0].peak_g = 0 G: must be > 0"),
            (base.replace("peak_g = 10.0", "peak_g = nan"), "shock[0].peak_g = NaN G: must be finite"),
            (format!("{base}start_s = -1.0\n"), "shock[0].start_s = -1 s: must be >= 0"),
            (format!("{base}direction_deg = inf\n"), "shock[0].direction_deg = inf deg: must be finite"),
            (format!("{base}design_accel_g = 20.0\n"), "shock[0].peak_g: give exactly one of"),
            (base.replace("peak_g = 10.0\n", ""), "shock[0].peak_g: missing"),
            (
                format!("{base}[[shock]]\nkind = \"half_sine\"\npeak_g = 5.0\nduration_s = 0.0\n"),
                "shock[1].duration_s = 0 s: must be > 0",
            ),
            (
                "[[shock]]\nkind = \"sine\"\namplitude_g = 1.0\nfreq_hz = 20.0\ncycles = -3\n".into(),
                "shock[0].cycles = -3: must be an integer >= 1",
            ),
            (
                "[[shock]]\nkind = \"sine\"\namplitude_g = -1.0\nfreq_hz = 20.0\ncycles = 3\n".into(),
                "shock[0].amplitude_g = -1 G: must be > 0",
            ),
            (
                "[[shock]]\nkind = \"recorded\"\nfile = \"a.csv\"\nscale = 0.0\n".into(),
                "shock[0].scale = 0: must be nonzero",
            ),
        ];
        for (text, want) in cases {
            let got = parse_err(&text);
            assert!(got.starts_with(want), "got `{got}`, want `{want}…`");
        }
    }

    #[test]
    fn unknown_keys_and_kinds_rejected() {
        let got = parse_err("[[shock]]\nkind = \"half_sine\"\npeak_g = 5.0\nduration_s = 0.01\npeak_G = 3.0\n");
        assert!(got.contains("unknown field `peak_G`"), "{got}");
        assert!(got.starts_with("scene.toml"), "{got}");
        let got = parse_err("[[shock]]\nkind = \"square\"\n");
        assert!(got.contains("unknown variant `square`"), "{got}");
        let got = parse_err("shocks = []\n");
        assert!(got.contains("unknown field `shocks`"), "{got}");
        let got = parse_err("[[shock]]\nkind = \"half_sine\"\npeak_g = 5.0\n");
        assert!(got.contains("missing field `duration_s`"), "{got}");
    }

    #[test]
    fn recorded_file_errors_name_shock_file_and_line() {
        let dir = scratch("badcsv");
        std::fs::write(dir.join("records/bad.csv"), "t_s,accel_m_s2\n0,1\n0.1;2\n").unwrap();
        let text = "[[shock]]\nkind = \"recorded\"\nfile = \"records/bad.csv\"\n";
        let e = parse_programme(text, &dir.join("p.toml")).unwrap_err();
        let msg = e.to_string();
        assert!(msg.starts_with("shock[0].file: "), "{msg}");
        assert!(msg.contains("bad.csv: line 3: 1 field(s)"), "{msg}");
        assert!(!e.is_io());
        let missing = "[[shock]]\nkind = \"recorded\"\nfile = \"records/none.csv\"\n";
        let e = parse_programme(missing, &dir.join("p.toml")).unwrap_err();
        assert!(e.is_io(), "{e}");
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn missing_programme_file_is_io() {
        let e = load_programme(Path::new("/nonexistent/prog.toml")).unwrap_err();
        assert!(e.is_io());
    }
}
