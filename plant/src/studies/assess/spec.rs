//! What to assess: an assessment file (or a scene file with `--laws`), validated before
//! anything runs. Unknown keys and values out of range are bad input (exit 2), named with
//! their key, value and unit.
//!
//! ```toml
//! scene = "../paper-10g.toml"          # relative to this file
//! set = ["controller.mode=\"sampled\""]   # for every controller (optional)
//! parts = ["sensitivity", "vibration", "ladder"]   # the default
//!
//! [[controller]]                        # one per column of the report
//! label = "pd_delay"
//! set = ["controller.law=\"pd_delay\""]  # the controller's own overrides
//!
//! [sensitivity]                         # every key optional (the defaults: docs/guide/assess.md)
//! f_min_hz = 5.0
//! speeds = ["standstill", "rated"]
//!
//! [ladder]
//! peaks_g = [1, 2, 3, 5, 7, 10, 15, 20]
//!
//! [duty]
//! capacity_fraction = 0.5
//! ```

use super::hertz::Materials;
use super::{ladder, sensitivity};
use crate::config::{load_scene, ConfigError};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// A part of the assessment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    /// ISO 14839-3.
    Sensitivity,
    /// ISO 14839-2.
    Vibration,
    /// The shock ladder with the duty.
    Ladder,
}

impl Part {
    /// Its name in files.
    pub fn name(self) -> &'static str {
        match self {
            Part::Sensitivity => "sensitivity",
            Part::Vibration => "vibration",
            Part::Ladder => "ladder",
        }
    }
}

/// A rotor speed the sensitivity is measured at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Speed {
    /// At rest.
    Standstill,
    /// The scene's `rotor.speed_hz`.
    Rated,
}

/// One controller: its label and the scene overrides that make it.
#[derive(Clone, Debug)]
pub struct ControllerSpec {
    /// Label in the report.
    pub label: String,
    /// Every override (the file's `set`, `--set`, the controller's own).
    pub sets: Vec<String>,
    /// The controller's own overrides.
    pub own: Vec<String>,
}

/// A validated assessment.
#[derive(Clone, Debug)]
pub struct Assessment {
    /// The scene file.
    pub scene: PathBuf,
    /// The controllers.
    pub controllers: Vec<ControllerSpec>,
    /// The parts.
    pub parts: Vec<Part>,
    /// Speeds of the sensitivity measurement.
    pub speeds: Vec<Speed>,
    /// The sensitivity measurement.
    pub sensitivity: sensitivity::Settings,
    /// The ladder.
    pub ladder: ladder::Settings,
    /// Materials of the bearing.
    pub materials: Materials,
    /// Counted ball-load cycles have a range of at least this share of one ball's static capacity.
    pub capacity_fraction: f64,
    /// What the settings cannot answer (`ladder::Settings::unreachable`).
    pub warnings: Vec<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFile {
    scene: String,
    #[serde(default)]
    set: Vec<String>,
    #[serde(default)]
    parts: Option<Vec<String>>,
    #[serde(default)]
    controller: Vec<RawController>,
    #[serde(default)]
    sensitivity: RawSensitivity,
    #[serde(default)]
    ladder: RawLadder,
    #[serde(default)]
    duty: RawDuty,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawController {
    label: String,
    #[serde(default)]
    set: Vec<String>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawSensitivity {
    f_min_hz: Option<f64>,
    f_max_hz: Option<f64>,
    points: Option<i64>,
    excitation_um: Option<f64>,
    response_um: Option<f64>,
    auto_level: Option<bool>,
    limit: Option<f64>,
    settle: Option<f64>,
    tolerance: Option<f64>,
    max_settle_s: Option<f64>,
    resolution: Option<f64>,
    probe_um: Option<f64>,
    probe_s: Option<f64>,
    min_cycles: Option<f64>,
    excitation: Option<String>,
    speeds: Option<Vec<String>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawLadder {
    peaks_g: Option<Vec<f64>>,
    members: Option<i64>,
    batch: Option<i64>,
    seed: Option<i64>,
    verify: Option<bool>,
    min_p: Option<f64>,
    duty_g: Option<f64>,
    end_when_decided: Option<bool>,
    robustness: Option<i64>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawDuty {
    youngs_modulus_gpa: Option<f64>,
    poisson: Option<f64>,
    groove_conformity: Option<f64>,
    static_pressure_mpa: Option<f64>,
    capacity_fraction: Option<f64>,
}

fn bad(key: &str, value: impl std::fmt::Display, unit: &str, why: &str) -> ConfigError {
    let unit = if unit.is_empty() { String::new() } else { format!(" {unit}") };
    ConfigError::Range { key: key.into(), value: value.to_string(), unit, why: why.into() }
}

/// `v` if given and inside `(lo, hi)` (both open), else the default.
fn number(key: &str, v: Option<f64>, default: f64, unit: &str, lo: f64, hi: f64) -> Result<f64, ConfigError> {
    match v {
        None => Ok(default),
        Some(x) if x.is_finite() && x > lo && x < hi => Ok(x),
        Some(x) => Err(bad(key, x, unit, &format!("must be a number above {lo} and below {hi}"))),
    }
}

fn count(key: &str, v: Option<i64>, default: usize, lo: i64, hi: i64) -> Result<usize, ConfigError> {
    match v {
        None => Ok(default),
        Some(x) if (lo..=hi).contains(&x) => Ok(x as usize),
        Some(x) => Err(bad(key, x, "", &format!("must be an integer from {lo} to {hi}"))),
    }
}

/// Loads an assessment file, or a scene file as an assessment of its own controller (or of
/// `laws`), with `set` for every controller.
pub fn load(file: &Path, set: &[String], laws: &[String]) -> Result<Assessment, ConfigError> {
    let raw = read_raw(file)?;
    let scene_path = super::relative_to(file, &raw.scene);
    let mut base: Vec<String> = raw.set.clone();
    base.extend(set.iter().cloned());
    let probe = load_scene(&scene_path, &base)?;
    let controllers = controllers(&raw.controller, &base, &probe, laws)?;
    let parts = parts(raw.parts.as_deref())?;
    // The smallest bearing plane's gap: the excitation's default amplitude and the bound of
    // what is injected, so that it stays inside every plane's clearance.
    let gap = (0..probe.planes()).map(|i| probe.plane(i).contact.gap).fold(f64::INFINITY, f64::min);
    let sens = sensitivity_settings(&raw.sensitivity, gap)?;
    let speeds = speeds(&raw.sensitivity)?;
    let ladder = ladder_settings(&raw.ladder, &parts)?;
    let materials = materials(&raw.duty)?;
    let capacity_fraction = number("duty.capacity_fraction", raw.duty.capacity_fraction, 0.5, "", 0.0, 10.0)?;
    // Warned, not refused: a short ladder still shows the shape of P(recovered) over the peaks,
    // and quick checks run with few members; the report says what it cannot conclude.
    let warnings = if parts.contains(&Part::Ladder) { ladder.unreachable().into_iter().collect() } else { Vec::new() };
    Ok(Assessment {
        scene: scene_path,
        controllers,
        parts,
        speeds,
        sensitivity: sens,
        ladder,
        materials,
        capacity_fraction,
        warnings,
    })
}

/// The file as written, or a scene file read as an assessment of its own controller.
fn read_raw(file: &Path) -> Result<RawFile, ConfigError> {
    let text = crate::input::read_text(file, crate::input::MAX_TOML_BYTES)
        .map_err(|source| ConfigError::Read { path: file.into(), source })?;
    let table: toml::Table = toml::from_str(&text)
        .map_err(|e| ConfigError::Parse { path: file.display().to_string(), message: e.to_string() })?;
    let parse_err =
        |e: toml::de::Error| ConfigError::Parse { path: file.display().to_string(), message: e.to_string() };
    let raw = if matches!(table.get("scene"), Some(toml::Value::String(_))) {
        toml::Value::Table(table).try_into::<RawFile>().map_err(parse_err)?
    } else {
        RawFile {
            scene: file.file_name().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default(),
            set: Vec::new(),
            parts: None,
            controller: Vec::new(),
            sensitivity: RawSensitivity::default(),
            ladder: RawLadder::default(),
            duty: RawDuty::default(),
        }
    };
    Ok(raw)
}

/// The controllers compared: `laws` given on the command line, the file's `[[controller]]`
/// tables, or the scene's own controller.
fn controllers(
    raw: &[RawController],
    base: &[String],
    probe: &crate::config::Scene,
    laws: &[String],
) -> Result<Vec<ControllerSpec>, ConfigError> {
    let mut controllers: Vec<ControllerSpec> = Vec::new();
    if !laws.is_empty() {
        for law in laws {
            let mut own = vec![format!("controller.law=\"{law}\"")];
            if *law != probe.controller.law {
                own.push("controller.params={}".into());
            }
            controllers.push(ControllerSpec { label: law.clone(), sets: [base.to_vec(), own.clone()].concat(), own });
        }
    } else if raw.is_empty() {
        let label = if probe.controller.mode == crate::config::ControlMode::Continuous {
            "continuous PD".to_string()
        } else {
            probe.controller.law.clone()
        };
        controllers.push(ControllerSpec { label, sets: base.to_vec(), own: Vec::new() });
    } else {
        for (i, c) in raw.iter().enumerate() {
            if c.label.trim().is_empty() || controllers.iter().any(|x| x.label == c.label) {
                return Err(bad(
                    &format!("controller[{i}].label"),
                    format!("{:?}", c.label),
                    "",
                    "must be a label of its own, not empty",
                ));
            }
            controllers.push(ControllerSpec {
                label: c.label.clone(),
                sets: [base.to_vec(), c.set.clone()].concat(),
                own: c.set.clone(),
            });
        }
    }
    if controllers.len() > 16 {
        return Err(bad("controller", controllers.len(), "controllers", "at most 16 in one report"));
    }
    Ok(controllers)
}

/// The parts measured (all three when not given).
fn parts(list: Option<&[String]>) -> Result<Vec<Part>, ConfigError> {
    Ok(match list {
        None => vec![Part::Sensitivity, Part::Vibration, Part::Ladder],
        Some(list) => {
            let mut out = Vec::new();
            for p in list {
                out.push(match p.as_str() {
                    "sensitivity" => Part::Sensitivity,
                    "vibration" => Part::Vibration,
                    "ladder" => Part::Ladder,
                    other => {
                        return Err(bad(
                            "parts",
                            format!("{other:?}"),
                            "",
                            "each must be sensitivity, vibration or ladder",
                        ))
                    }
                });
            }
            if out.is_empty() {
                return Err(bad("parts", "[]", "", "name at least one part"));
            }
            out
        }
    })
}

/// The `[sensitivity]` settings, the excitation bounded by the smallest plane's `gap` (m).
fn sensitivity_settings(s: &RawSensitivity, gap: f64) -> Result<sensitivity::Settings, ConfigError> {
    let d = sensitivity::Settings::for_gap(gap);
    let k = |name: &str| format!("sensitivity.{name}");
    let gap_um = gap * 1e6;
    let sens = sensitivity::Settings {
        f_min_hz: number(&k("f_min_hz"), s.f_min_hz, d.f_min_hz, "Hz", 0.0, 1e6)?,
        f_max_hz: number(&k("f_max_hz"), s.f_max_hz, d.f_max_hz, "Hz", 0.0, 1e6)?,
        points: count(&k("points"), s.points, d.points, 2, 1000)?,
        excitation_um: number(&k("excitation_um"), s.excitation_um, d.excitation_um, "µm", 0.0, gap_um)?,
        response_um: number(&k("response_um"), s.response_um, d.response_um, "µm", 0.0, gap_um)?,
        auto_level: s.auto_level.unwrap_or(d.auto_level),
        limit: number(&k("limit"), s.limit, d.limit, "", 0.0, 1.0)?,
        settle: number(&k("settle"), s.settle, d.settle, "", 0.0, 1.0)?,
        tolerance: number(&k("tolerance"), s.tolerance, d.tolerance, "", 0.0, 1.0)?,
        max_settle_s: number(&k("max_settle_s"), s.max_settle_s, d.max_settle_s, "s", 0.0, 100.0)?,
        resolution: number(&k("resolution"), s.resolution, d.resolution, "", 1e-5, 1.0)?,
        probe_um: number(&k("probe_um"), s.probe_um, d.probe_um, "µm", 0.0, gap_um)?,
        probe_s: number(&k("probe_s"), s.probe_s, d.probe_s, "s", 0.0, 100.0)?,
        min_cycles: number(&k("min_cycles"), s.min_cycles, d.min_cycles, "periods", 0.99, 1000.0)?,
        excitation: match s.excitation.as_deref() {
            None => d.excitation,
            Some("multisine") => sensitivity::Signal::Multisine,
            Some("stepped") => sensitivity::Signal::Stepped,
            Some(other) => {
                return Err(bad(&k("excitation"), format!("{other:?}"), "", "must be \"multisine\" or \"stepped\""))
            }
        },
    };
    if sens.f_min_hz >= sens.f_max_hz {
        return Err(bad(&k("f_min_hz"), sens.f_min_hz, "Hz", "must be below sensitivity.f_max_hz"));
    }
    let least = sensitivity::least_simulated_s(&sens);
    if least > sensitivity::RUN_CAP_S {
        let why = format!(
            "the grid's periods alone (two of settling and two windows of min_cycles = {} at each of its {} \
             frequencies) take {least:.0} s of simulated time per axis, more than the {} s a measurement may run: \
             raise f_min_hz or lower min_cycles or points",
            sens.min_cycles,
            sens.points,
            sensitivity::RUN_CAP_S
        );
        return Err(bad(&k("f_min_hz"), sens.f_min_hz, "Hz", &why));
    }
    Ok(sens)
}

/// The speeds at which the sensitivity is measured (standstill and rated when not given).
fn speeds(s: &RawSensitivity) -> Result<Vec<Speed>, ConfigError> {
    let k = |name: &str| format!("sensitivity.{name}");
    Ok(match &s.speeds {
        None => vec![Speed::Standstill, Speed::Rated],
        Some(list) if !list.is_empty() => list
            .iter()
            .map(|x| match x.as_str() {
                "standstill" => Ok(Speed::Standstill),
                "rated" => Ok(Speed::Rated),
                other => Err(bad(&k("speeds"), format!("{other:?}"), "", "each must be standstill or rated")),
            })
            .collect::<Result<_, _>>()?,
        Some(_) => return Err(bad(&k("speeds"), "[]", "", "name at least one speed")),
    })
}

/// The `[ladder]` settings; its `duty_g` must be one of its rungs when the ladder is measured.
fn ladder_settings(l: &RawLadder, parts: &[Part]) -> Result<ladder::Settings, ConfigError> {
    let dl = ladder::Settings::default();
    let peaks = l.peaks_g.clone().unwrap_or(dl.peaks_g.clone());
    if peaks.is_empty()
        || peaks.len() > 64
        || peaks.windows(2).any(|w| w[1] <= w[0])
        || peaks.iter().any(|p| !(p.is_finite() && *p > 0.0 && *p <= 1000.0))
    {
        return Err(bad(
            "ladder.peaks_g",
            format!("{peaks:?}"),
            "G",
            "must be 1 to 64 ascending peaks above 0 and at most 1000",
        ));
    }
    // Not given: the rung nearest the study's 10 G.
    let default_duty = peaks.iter().copied().min_by(|a, b| (a - dl.duty_g).abs().total_cmp(&(b - dl.duty_g).abs()));
    let members = count("ladder.members", l.members, dl.members, 1, 10_000)?;
    let ladder = ladder::Settings {
        peaks_g: peaks,
        members,
        batch: count("ladder.batch", l.batch, dl.batch.min(members), 1, members as i64)?,
        seed: count("ladder.seed", l.seed, dl.seed as usize, 0, i64::MAX)? as u64,
        verify: l.verify.unwrap_or(dl.verify),
        min_p: number("ladder.min_p", l.min_p, dl.min_p, "", 0.0, 1.0)?,
        duty_g: number("ladder.duty_g", l.duty_g, default_duty.unwrap_or(dl.duty_g), "G", 0.0, 1e3)?,
        end_when_decided: l.end_when_decided.unwrap_or(dl.end_when_decided),
        robustness: count("ladder.robustness", l.robustness, 0, 0, crate::robustness::MAX_MEMBERS as i64)?,
    };
    // The verdict's duty is that of a rung: a `duty_g` on none would leave it out silently.
    if parts.contains(&Part::Ladder) && !ladder.peaks_g.iter().any(|g| (g - ladder.duty_g).abs() < 1e-9) {
        let why = format!("must be one of ladder.peaks_g {:?} (the rung whose duty the verdict gives)", ladder.peaks_g);
        return Err(bad("ladder.duty_g", ladder.duty_g, "G", &why));
    }
    Ok(ladder)
}

/// The `[duty]` materials.
fn materials(du: &RawDuty) -> Result<Materials, ConfigError> {
    let dm = Materials::default();
    let materials = Materials {
        youngs_modulus_pa: number(
            "duty.youngs_modulus_gpa",
            du.youngs_modulus_gpa,
            dm.youngs_modulus_pa * 1e-9,
            "GPa",
            0.0,
            1e4,
        )? * 1e9,
        poisson: number("duty.poisson", du.poisson, dm.poisson, "", 0.0, 0.5)?,
        groove_conformity: number("duty.groove_conformity", du.groove_conformity, dm.groove_conformity, "", 0.5, 1.0)?,
        static_pressure_pa: number(
            "duty.static_pressure_mpa",
            du.static_pressure_mpa,
            dm.static_pressure_pa * 1e-6,
            "MPa",
            0.0,
            1e5,
        )? * 1e6,
    };
    Ok(materials)
}

#[cfg(test)]
mod tests {
    /// The excitation is bounded by the smallest bearing plane's gap, not plane A's: on the
    /// two-plane machine with plane B's gap cut to 50 µm, 80 µm is refused (plane A's is 150).
    #[test]
    fn the_excitation_is_bounded_by_the_smallest_gap() {
        let dir = crate::util::scratch("assess-spec");
        let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/two-plane-asymmetric-10g.toml");
        let file = dir.join("a.toml");
        let write = |gap_b: f64| {
            let text = format!(
                "scene = {:?}\nset = [\"touchdown.b.air_gap_mm={gap_b}\"]\n[sensitivity]\nexcitation_um = 80.0\n",
                scene.display().to_string()
            );
            std::fs::write(&file, text).unwrap();
        };
        write(0.25);
        assert!(super::load(&file, &[], &[]).is_ok());
        write(0.05);
        let Err(e) = super::load(&file, &[], &[]) else { panic!("80 µm past plane B's 50 µm gap was taken") };
        let e = e.to_string();
        assert!(e.contains("sensitivity.excitation_um"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
