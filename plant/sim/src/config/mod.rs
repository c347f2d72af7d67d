//! Scene files: TOML parsed into raw structs ([`raw`], the file format;
//! unknown keys are errors), then validated ([`validate`]) into SI parameter
//! types. Units are in the key names; each key's default is the study's
//! value (MODEL.md §7) and is listed in docs/guide/scenes.md.
//!
//! Any key can be overridden from the command line with `--set a.b=value`
//! ([`overrides`]; the value is read as a TOML literal, else as a string).
//!
//! The validated [`Scene`] is the only source of truth: code outside this
//! module never reads the raw layer. What it needs of the file as written
//! (the resolved scene for `scene.toml`, a re-load with other overrides) is a
//! method of [`Scene`].

pub mod fmu;
pub mod hardware;
pub mod models;
pub mod overrides;
pub mod raw;
pub mod rotor;
#[cfg(test)]
mod rotor_tests;
mod scene_table;
pub mod validate;
// The checks every key goes through (below `models` and `validate`, which both use them).
mod checks;

pub use overrides::apply_override;
pub use raw::{
    ControlMode, DragChoice, Fallback, ForceLaw, McapCompression, Pacing, RaceWhenClearChoice, RawController, RawScene,
    RealtimeSetting, ReleaseChoice, RotorModel, SpinChoice, SupportChoice,
};
pub use rotor::{FailureState, Rotor, RotorParams};
pub use validate::{finite, non_negative, positive, range, validate};

use crate::integrate::Method;
use crate::model::Params;
use serde::Serialize;
use shock_table::{Programme, ShockSpec};
use std::path::{Path, PathBuf};

/// Why a scene could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The file could not be read.
    #[error("cannot read scene file {path}: {source}")]
    Read {
        /// File path.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
    /// TOML syntax or an unknown/mistyped key.
    #[error("{path}: {message}")]
    Parse {
        /// File path (or `--set`).
        path: String,
        /// Parser message (names the key).
        message: String,
    },
    /// A value is out of range.
    #[error("{key} = {value}{unit}: {why}")]
    Range {
        /// Full key, e.g. `touchdown.air_gap_mm`.
        key: String,
        /// The value as given.
        value: String,
        /// Unit, with a leading space, or empty.
        unit: String,
        /// What is allowed.
        why: String,
    },
    /// A `--set` argument is malformed.
    #[error("--set {arg}: {why}")]
    Override {
        /// The argument.
        arg: String,
        /// What is wrong.
        why: String,
    },
    /// The shock programme is invalid.
    #[error("shock: {0}")]
    Shock(#[from] shock_table::ShockError),
    /// The controller design is invalid, or the law refuses its parameters.
    #[error("{0}")]
    Law(#[from] controller::LawError),
    /// A deprecated key and the key replacing it are both given.
    #[error("both {old} (deprecated) and {new} are given: keep {new}")]
    Alias {
        /// The deprecated key.
        old: String,
        /// The key replacing it.
        new: String,
    },
}

/// Controller settings, validated.
#[derive(Clone, Debug, Serialize)]
pub struct ControllerSettings {
    /// Connection mode.
    pub mode: ControlMode,
    /// Law name (a law of [`controller::registry`]).
    pub law: String,
    /// Controller rate (Hz), `controller.rate_hz`.
    pub rate_hz: f64,
    /// Controller period (s), `1 / rate_hz`.
    pub period: f64,
    /// k_e (N/m).
    pub stiffness: f64,
    /// ξ_e.
    pub damping_ratio: f64,
    /// Delay in samples.
    pub delay_samples: u32,
    /// Gravity bias on y.
    pub gravity_bias: bool,
    /// The law's own parameters (`[controller.params]`, the deprecated `relev_*` keys moved in).
    pub params: controller::Params,
    /// Co-simulation settings (used in `lockstep` and `realtime`).
    pub cosim: CosimSettings,
    /// The most non-finite commands in a row before the run ends ([`crate::invalid`]).
    pub max_invalid_burst: u64,
    /// The largest share of non-finite commands ([`crate::invalid`]).
    pub max_invalid_fraction: f64,
}

/// Co-simulation settings, validated (SI).
#[derive(Clone, Debug, Serialize)]
pub struct CosimSettings {
    /// What to apply when the controller is lost.
    pub fallback: Fallback,
    /// Silence before the controller's node is looked up (s).
    pub reply_timeout: f64,
    /// Wait for a new controller after a loss (s); 0 = stop.
    pub reconnect_timeout: f64,
    /// Wait for the first handshake (s).
    pub connect_timeout: f64,
    /// Busy-poll budget before blocking (s).
    pub spin: f64,
    /// Cores for `[plant, controller]`.
    pub pin_cores: Option<[usize; 2]>,
    /// Lockstep: the wait for a reply from a live controller before it is treated as lost (s).
    pub lockstep_timeout: f64,
    /// The controller process to start (argv, paths resolved), instead of the built-in one.
    pub command: Option<Vec<String>>,
    /// `SCHED_FIFO` priority for plant and controller; 0 = off.
    pub realtime_priority: u32,
    /// Realtime: the largest deadline-miss fraction before the run ends (exit 6).
    pub max_miss_fraction: f64,
    /// Realtime: the largest fraction of ticks started more than a period late before the run
    /// ends (exit 10).
    pub max_overrun_fraction: f64,
    /// Realtime: how the plant and the controller wait between ticks.
    pub pacing: Pacing,
}

impl CosimSettings {
    /// The cores of `pin_cores` (none when unpinned): those a realtime run's helper threads keep
    /// off.
    pub fn pinned_cores(&self) -> &[usize] {
        self.pin_cores.as_ref().map_or(&[], |c| &c[..])
    }
}

/// Integrator settings, validated (tolerances per state component).
#[derive(Clone, Debug, Serialize)]
pub struct IntegratorSettings {
    /// Method.
    pub method: Method,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerances of positions (m), velocities (m/s), angles (rad) and angular speeds
    /// (rad/s), from which each model's per-component tolerances are laid out.
    pub atol_groups: [f64; 4],
    /// Substeps per macro step (fixed-step methods).
    pub substeps: u32,
    /// Substeps per macro step while the race is free (fixed-step methods, parked race); ≥ 1.
    pub contact_substeps: u32,
    /// Largest allowed excursion beyond the clearances (m).
    pub radius_guard: f64,
    /// The integrator of realtime runs (`integrator.realtime`); a realtime scene on `fixed`
    /// already holds the fixed-step setting here.
    pub realtime: RealtimeSetting,
}

/// Initial-state settings.
#[derive(Clone, Debug, Serialize)]
pub struct InitialSettings {
    /// Start on the linear unbalance orbit.
    pub unbalance_orbit: bool,
    /// Angle of the unbalance at t = 0 (rad), `rotor.unbalance_phase_deg`.
    pub unbalance_phase: f64,
    /// Rotor offset (m).
    pub rotor_offset: [f64; 2],
    /// Two-plane: offset of the slopes a, b (rad).
    pub slope_offset: [f64; 2],
}

/// A validated scene, SI.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Name.
    pub name: String,
    /// Description.
    pub description: String,
    /// Simulated time (s).
    pub duration: f64,
    /// The rotor: its model and each bearing plane's physics ([`Rotor`]).
    pub rotor: Rotor,
    /// Base motion.
    pub base: Programme,
    /// Controller.
    pub controller: ControllerSettings,
    /// Integrator.
    pub integrator: IntegratorSettings,
    /// Initial state.
    pub initial: InitialSettings,
    /// The sensor as the digital controller reads it.
    pub sensor: crate::sensor::SensorSettings,
    /// The amplifiers and the sensor's front end (all off by default).
    pub hardware: hardware::Hardware,
    /// Trace interval (s).
    pub output_interval: f64,
    /// Write plots.
    pub plots: bool,
    /// Record the run as `run.mcap` (`[output] mcap`, `plant run --mcap`).
    pub mcap: bool,
    /// Rows per simulated second the live view sends (`[output] live_rate_hz`, `plant run --live`).
    pub live_rate_hz: f64,
    /// The compression of `run.mcap`'s chunks (`[output] mcap_compression`).
    pub mcap_compression: McapCompression,
    /// Notes for the user: deprecated keys, a run with few controller ticks. The CLI prints
    /// them as `plant: warning: …`.
    pub warnings: Vec<String>,
    /// The scene as resolved (overrides applied, deprecated keys moved), where it was read
    /// from; only this module reads it.
    source: Source,
}

/// The scene as resolved, and where it was read from.
#[derive(Clone, Debug)]
struct Source {
    /// The file's table with the overrides applied and the deprecated keys moved.
    raw: RawScene,
    /// Folder that relative paths (recorded shock files) are relative to.
    base_dir: PathBuf,
    /// Number of `[[shock]]` entries.
    shocks: usize,
}

impl Scene {
    /// When the base motion first starts (s): the first breakpoint of the programme, or 0.
    pub fn first_shock_start(&self) -> f64 {
        self.base.breakpoints().first().copied().unwrap_or(0.0)
    }

    /// Number of `[[shock]]` entries (`shock[0]` … `shock[n−1]` for `--set`).
    pub fn shock_count(&self) -> usize {
        self.source.shocks
    }

    /// The design of each bearing plane (one for the planar model): the scene's closed loop
    /// with the plane's own loop constants, its load share as the mass (the damping design and
    /// the gravity bias act on it) and its own air gap.
    pub fn plane_designs(&self) -> Vec<controller::Design> {
        self.rotor.bearings().map(|p| self.design_of(p)).collect()
    }

    /// Plane `i`'s design ([`Scene::plane_designs`]).
    pub fn plane_design(&self, i: usize) -> controller::Design {
        self.design_of(self.plane(i))
    }

    /// The whole rotor's design a law is built from (`controller::build_rotor_law`) and the
    /// hello carries: the planar design, or each plane's with the rotor's geometry.
    pub fn rotor_design(&self) -> controller::RotorDesign {
        match self.rotor.geometry() {
            None => controller::RotorDesign::Planar(self.plane_design(0)),
            Some(geometry) => {
                controller::RotorDesign::TwoPlane { planes: [self.plane_design(0), self.plane_design(1)], geometry }
            }
        }
    }

    /// Scale of the absolute tolerances of positions, velocities, angles and angular speeds
    /// (`atol = rtol × scale`, the benches' and the ensembles' reference setting): plane A's
    /// gap, the gap times the spin speed, a turn, the spin speed.
    pub fn atol_scale_groups(&self) -> [f64; 4] {
        let (r0, w) = (self.plane(0).contact.gap, self.rotor.speed().max(1.0));
        [r0, r0 * w, std::f64::consts::TAU, w]
    }

    /// Bearing planes: 1 (planar) or 2.
    pub fn planes(&self) -> usize {
        self.rotor.planes()
    }

    /// Plane `i`'s parameters: its bearing and its share of the rotor ([`Rotor::plane`]).
    pub fn plane(&self, i: usize) -> &Params {
        self.rotor.plane(i)
    }

    fn design_of(&self, params: &Params) -> controller::Design {
        let c = &self.controller;
        controller::Design {
            stiffness_n_per_m: c.stiffness,
            damping_ratio: c.damping_ratio,
            period_s: c.period,
            gravity_bias: c.gravity_bias,
            current_limit_a: params.current_limit,
            delay_samples: c.delay_samples,
            constants: params.loop_constants,
        }
    }

    /// `--set` overrides of the fixed-step setting: RK4 with one step per tick while the race is
    /// parked (the gap clear by a safe margin, [`crate::park`]), and while it is free the
    /// substeps the stability estimate gives under a
    /// [`plant_physics::stability::REFERENCE_CONTACT_FORCE`] contact (3 at 20 kHz on the study's
    /// bearing). Its cost per tick is bounded: at most `4 × contact_substeps + 1` evaluations
    /// of the model (the last for an output sample inside the last substep; twice that in a
    /// tick split at a shock's breakpoint). The default of realtime
    /// runs (`integrator.realtime = "fixed"`) and the fast setting of ensemble members.
    pub fn fixed_step_overrides(&self) -> Vec<String> {
        // Every bearing plane's contact must be stable: the most substeps any plane needs.
        let contact = (0..self.planes())
            .map(|i| {
                plant_physics::stability::safe_contact_substeps(self.plane(i), Method::Rk4, self.controller.period)
            })
            .max()
            .unwrap_or(1)
            .max(1);
        vec![
            "integrator.method=\"rk4\"".into(),
            "integrator.substeps=1".into(),
            format!("integrator.contact_substeps={contact}"),
            "touchdown.race_when_clear=\"parked\"".into(),
            "touchdown.race_release=\"equilibrium\"".into(),
        ]
    }

    /// What a plant's state depends on besides its length (a snapshot's
    /// [`crate::snapshot::Fingerprint`]): every `[rotor]` key as resolved, the hardware's layout,
    /// the integrator as the run uses it, and the controller's and the output's rates. The
    /// controller's law and gains, the touchdown bearings, the shock programme and the duration
    /// are not in it.
    pub fn state_fingerprint(&self) -> Vec<(String, String)> {
        let mut entries = Vec::new();
        if let Ok(toml::Value::Table(rotor)) = toml::Value::try_from(&self.source.raw.rotor) {
            flatten("rotor", &rotor, &mut entries);
        }
        let hw = &self.hardware;
        let layout = if hw.is_unipolar() {
            "unipolar amplifiers"
        } else if hw.is_on() {
            "amplifiers or a sensor front end"
        } else {
            "bare"
        };
        entries.push(("hardware".into(), layout.into()));
        let i = &self.integrator;
        entries.push(("integrator.method".into(), format!("{:?}", i.method)));
        if i.method.is_adaptive() {
            entries.push(("integrator.rtol".into(), format!("{:?}", i.rtol)));
            entries.push(("integrator.atol".into(), format!("{:?}", i.atol_groups)));
        } else {
            entries.push(("integrator.substeps".into(), i.substeps.to_string()));
            entries.push(("integrator.contact_substeps".into(), i.contact_substeps.to_string()));
        }
        entries.push(("controller.rate_hz".into(), format!("{:?}", self.controller.rate_hz)));
        entries.push(("output.rate_hz".into(), format!("{:?}", 1.0 / self.output_interval)));
        entries
    }

    /// The scene as resolved (every key, overrides applied), as a scene file: `scene.toml` of
    /// a run folder, which reproduces the run.
    ///
    /// Every file the scene reads (a recorded shock's `file`, `rotor.ross_file`) is written as
    /// an absolute path, so that the run folder's `scene.toml` finds it wherever the folder is
    /// (`plant analyze`, a rerun).
    pub fn to_toml(&self) -> Result<String, ConfigError> {
        let mut raw = self.source.raw.clone();
        let absolute = |file: &Path| {
            let joined = self.source.base_dir.join(file);
            std::path::absolute(&joined).unwrap_or(joined)
        };
        for shock in &mut raw.shock {
            if let ShockSpec::Recorded { file, .. } = shock {
                *file = absolute(file);
            }
        }
        if let Some(file) = raw.rotor.flexible_mut().and_then(|r| r.ross_file.as_mut()) {
            *file = absolute(Path::new(file)).display().to_string();
        }
        toml::to_string(&raw)
            .map_err(|e| ConfigError::Parse { path: "the resolved scene".into(), message: e.to_string() })
    }

    /// The scene as resolved, read back from [`Scene::to_toml`] (every key, overrides applied,
    /// recorded files absolute): what sweeps and ensembles key their units on and draw
    /// relative to.
    pub fn resolved(&self) -> Result<RawScene, ConfigError> {
        toml::from_str(&self.to_toml()?)
            .map_err(|e| ConfigError::Parse { path: "the resolved scene".into(), message: e.to_string() })
    }

    /// The same scene with more `--set` overrides, validated again.
    pub fn reload(&self, overrides: &[String]) -> Result<Scene, ConfigError> {
        let mut table = self.table()?;
        for arg in overrides {
            apply_override(&mut table, arg)?;
        }
        self.revalidate(table, &format!("--set {}", overrides.join(" --set ")), &self.source.base_dir)
    }

    /// The same scene with another shock programme (recorded files relative to `base_dir`)
    /// and `overrides`, validated again (`plant soak`).
    pub fn with_shocks(
        &self,
        shocks: &[ShockSpec],
        base_dir: &Path,
        overrides: &[String],
    ) -> Result<Scene, ConfigError> {
        let mut table = self.table()?;
        let list = toml::Value::try_from(shocks)
            .map_err(|e| ConfigError::Parse { path: "the shock programme".into(), message: e.to_string() })?;
        table.insert("shock".into(), list);
        for arg in overrides {
            apply_override(&mut table, arg)?;
        }
        self.revalidate(table, "the programme", base_dir)
    }

    /// The same scene with what an external controller ran differently (the `[controller]`
    /// table of its handshake's overrides: `params` replaces the scene's whole, other keys
    /// are set), validated again: the scene the run actually had. Only what a controller may
    /// change ([`check_controller_overrides`]); anything else is refused, never written into a
    /// scene that a run folder would replay.
    pub fn with_controller_overrides(&self, controller: &toml::Table) -> Result<Scene, ConfigError> {
        check_controller_overrides(
            controller,
            self.rotor.bearings().map(|p| p.current_limit).fold(f64::INFINITY, f64::min),
        )
        .map_err(|why| ConfigError::Parse { path: "the controller's handshake overrides".into(), message: why })?;
        let mut table = self.table()?;
        let section = table
            .entry("controller")
            .or_insert_with(|| toml::Value::Table(toml::Table::new()))
            .as_table_mut()
            .ok_or_else(|| ConfigError::Parse {
                path: "the resolved scene".into(),
                message: "no [controller]".into(),
            })?;
        for (key, value) in controller {
            section.insert(key.clone(), value.clone());
        }
        self.revalidate(table, "the controller's overrides", &self.source.base_dir)
    }

    fn table(&self) -> Result<toml::Table, ConfigError> {
        toml::Table::try_from(&self.source.raw)
            .map_err(|e| ConfigError::Parse { path: "the resolved scene".into(), message: e.to_string() })
    }

    fn revalidate(&self, table: toml::Table, blame: &str, base_dir: &Path) -> Result<Scene, ConfigError> {
        validate(parse_raw(table, blame)?, base_dir)
    }
}

/// The `[controller]` keys a controller may send back in its handshake's overrides
/// (docs/wire-protocol.md, "The overrides document"): the law it runs, its design and its
/// parameters. The rest of the run (its program, mode, rate, delay, budgets, timeouts,
/// scheduling) is the scene's, never the controller's.
pub const CONTROLLER_OVERRIDE_KEYS: [&str; 6] =
    ["law", "stiffness_n_per_m", "damping_ratio", "current_limit_a", "gravity_bias", "params"];

/// Checks the `[controller]` table of a controller's handshake overrides: every key one of
/// [`CONTROLLER_OVERRIDE_KEYS`], and `current_limit_a` (the amplifier's limit, a property of
/// the plant) not above the scene's `scene_limit_a` (a controller may saturate lower, never
/// drive the coils harder than the scene's amplifier). `Err` names the key and its value.
pub fn check_controller_overrides(controller: &toml::Table, scene_limit_a: f64) -> Result<(), String> {
    for (key, value) in controller {
        if !CONTROLLER_OVERRIDE_KEYS.contains(&key.as_str()) {
            return Err(format!(
                "controller.{key} = {value}: a controller may change only {} (docs/wire-protocol.md, \
                 \"The overrides document\"); the rest of the run is the scene's",
                CONTROLLER_OVERRIDE_KEYS
                    .map(|k| if k == "params" { "[controller.params]".into() } else { format!("`{k}`") })
                    .join(", ")
            ));
        }
    }
    if let Some(v) = controller.get("current_limit_a") {
        let limit = v.as_float().or_else(|| v.as_integer().map(|i| i as f64));
        match limit {
            Some(a) if a.is_finite() && a > 0.0 && a <= scene_limit_a => {}
            _ => {
                return Err(format!(
                    "controller.current_limit_a = {v} A: a controller may lower the current limit, never raise it \
                     above the scene's controller.current_limit_a = {scene_limit_a} A (the amplifier's)"
                ))
            }
        }
    }
    Ok(())
}

/// Reads a scene file, applies `--set` overrides, validates.
pub fn load_scene(path: &Path, overrides: &[String]) -> Result<Scene, ConfigError> {
    let text = shock_table::input::read_text(path, shock_table::input::MAX_TOML_BYTES)
        .map_err(|source| ConfigError::Read { path: path.to_path_buf(), source })?;
    let mut value: toml::Table = toml::from_str(&text)
        .map_err(|e| ConfigError::Parse { path: path.display().to_string(), message: e.to_string() })?;
    // The file alone first, so that its own mistakes are blamed on it, then with the overrides.
    let mut raw = parse_raw(value.clone(), &path.display().to_string())?;
    if !overrides.is_empty() {
        let file = value.clone();
        for arg in overrides {
            apply_override(&mut value, arg)?;
        }
        raw = parse_raw(value, &format!("--set {}", overrides.join(" --set ")))
            .map_err(|e| blame_override(&file, overrides, e))?;
    }
    if raw.scene.name.is_empty() {
        raw.scene.name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    }
    let base_dir = path.parent().unwrap_or(Path::new("."));
    validate(raw, base_dir)
}

/// The overrides' parse error `e` blamed on the one `--set` that brings it (the first whose
/// prefix of the overrides fails with the same message) instead of on all of them, and said in
/// words where serde names a Rust type ("expected f64": a number). An error that only the
/// overrides together bring keeps naming them all.
fn blame_override(file: &toml::Table, overrides: &[String], e: ConfigError) -> ConfigError {
    let ConfigError::Parse { path, message } = e else { return e };
    // serde's type names are Rust's; the scene's readers know numbers, whole numbers, booleans.
    let words = |m: &str| {
        // serde prints a float as all its digits (1e300: 301 of them); back to exponent form.
        let m: String = m
            .split('`')
            .enumerate()
            .map(|(i, part)| match part.parse::<f64>() {
                Ok(v) if i % 2 == 1 && part.len() > 16 => format!("{v:e}"),
                _ => part.to_string(),
            })
            .collect::<Vec<_>>()
            .join("`");
        m.replace("expected f64", "expected a number")
            .replace("invalid type: unit variant, expected string only", "expected one of the key's names, in quotes")
            .replace("wanted exactly 1 element, found 0 elements", "expected one of the key's names, in quotes")
            .replace("expected u32", "expected a whole number ≥ 0")
            .replace("expected u64", "expected a whole number ≥ 0")
            .replace("expected usize", "expected a whole number ≥ 0")
            .replace("expected i64", "expected a whole number")
            .replace("expected u8", "expected a whole number from 0 to 255")
    };
    let mut value = file.clone();
    for arg in overrides {
        if apply_override(&mut value, arg).is_err() {
            break;
        }
        let failed = match parse_raw(value.clone(), "") {
            Err(ConfigError::Parse { message, .. }) => Some(message),
            _ => None,
        };
        if failed.as_deref() == Some(message.as_str()) {
            return ConfigError::Parse { path: format!("--set {arg}"), message: words(&message) };
        }
    }
    ConfigError::Parse { path, message: words(&message) }
}

/// A scene's table (the file with its overrides) read into the file format, `blame` naming
/// where it came from in a parse error. A `[rotor]` key of another model than the scene's, which
/// the model's key struct refuses, is refused naming the key, its value and both models
/// ([`raw::RawRotor::foreign_key`]).
pub(crate) fn parse_raw(table: toml::Table, blame: &str) -> Result<RawScene, ConfigError> {
    let rotor = table.get("rotor").and_then(toml::Value::as_table).cloned();
    toml::Value::Table(table).try_into::<RawScene>().map_err(|e| {
        rotor
            .as_ref()
            .and_then(raw::RawRotor::foreign_key)
            .unwrap_or_else(|| ConfigError::Parse { path: blame.to_string(), message: e.to_string() })
    })
}

/// `table`'s values as `(prefix.key, value)` pairs, sub-tables flattened, in key order.
fn flatten(prefix: &str, table: &toml::Table, out: &mut Vec<(String, String)>) {
    for (key, value) in table {
        let name = format!("{prefix}.{key}");
        match value {
            toml::Value::Table(t) => flatten(&name, t, out),
            toml::Value::Float(f) => out.push((name, format!("{f:?}"))),
            other => out.push((name, other.to_string())),
        }
    }
}

/// A shipped scene (`config/FILE`) with `sets` applied, for the library's tests.
#[cfg(test)]
pub(crate) fn shipped(file: &str, sets: &[&str]) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config").join(file);
    load_scene(&path, &sets.iter().map(|s| s.to_string()).collect::<Vec<_>>())
        .unwrap_or_else(|e| panic!("config/{file} {sets:?}: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    use super::shipped as scene;

    /// The fixed-step setting sizes the contact substeps for the bearing plane that needs the
    /// most (it read plane A's alone), whichever plane that is.
    #[test]
    fn the_fixed_step_setting_holds_every_planes_contact_stable() {
        for stiff in ["a", "b"] {
            let s = scene(
                "two-plane-asymmetric-10g.toml",
                &[&format!("contact.{stiff}.rotor_race_stiffness_n_per_m10_9=4e11")],
            );
            let need: Vec<u32> = (0..2)
                .map(|i| plant_physics::stability::safe_contact_substeps(s.plane(i), Method::Rk4, s.controller.period))
                .collect();
            assert_ne!(need[0], need[1], "the planes need different substeps");
            let most = need.iter().max().unwrap();
            assert!(
                s.fixed_step_overrides().contains(&format!("integrator.contact_substeps={most}")),
                "{stiff}: {:?}, planes need {need:?}",
                s.fixed_step_overrides()
            );
        }
    }

    /// Issue 31 item 5: of every `[controller]` key of the scene format, a controller may send
    /// back only those of the protocol; each other one is refused, naming it and its value.
    /// A current limit above the scene's (or not a positive number) is refused too.
    #[test]
    fn a_controller_may_override_only_its_law_design_and_parameters() {
        let raw = toml::Value::try_from(RawController::default()).unwrap();
        let keys = raw.as_table().unwrap();
        assert!(keys.len() > CONTROLLER_OVERRIDE_KEYS.len() + 10, "{keys:?}");
        for (key, value) in keys {
            let table = toml::Table::from_iter([(key.clone(), value.clone())]);
            let checked = check_controller_overrides(&table, 2.0);
            if CONTROLLER_OVERRIDE_KEYS.contains(&key.as_str()) {
                assert_eq!(checked, Ok(()), "{key}");
            } else {
                let why = checked.expect_err(key);
                assert!(why.starts_with(&format!("controller.{key} = ")) && why.contains("may change only"), "{why}");
            }
        }
        let command = toml::Value::Array(vec!["/bin/sh".into(), "-c".into(), "touch /tmp/owned".into()]);
        let why = check_controller_overrides(&toml::Table::from_iter([("command".to_string(), command)]), 2.0);
        assert!(why.unwrap_err().contains("controller.command = [\"/bin/sh\""));
        for (limit, ok) in
            [(1.5, true), (2.0, true), (2.0000001, false), (1000.0, false), (0.0, false), (f64::NAN, false)]
        {
            let table = toml::Table::from_iter([("current_limit_a".to_string(), toml::Value::Float(limit))]);
            let checked = check_controller_overrides(&table, 2.0);
            assert_eq!(checked.is_ok(), ok, "{limit}: {checked:?}");
            if !ok {
                assert!(checked.unwrap_err().contains("scene's controller.current_limit_a = 2 A"), "{limit}");
            }
        }
        let text = toml::Table::from_iter([("current_limit_a".to_string(), toml::Value::String("big".into()))]);
        assert!(check_controller_overrides(&text, 2.0).is_err());
        // The scene a run folder records refuses them too: nothing of a refused table is set.
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/cosim-10g.toml");
        let scene = load_scene(&path, &[]).unwrap();
        let mode = toml::Table::from_iter([
            ("damping_ratio".to_string(), toml::Value::Float(0.05)),
            ("mode".to_string(), toml::Value::String("continuous".into())),
        ]);
        let e = scene.with_controller_overrides(&mode).unwrap_err().to_string();
        assert!(e.contains("controller.mode = \"continuous\""), "{e}");
        let design = toml::Table::from_iter([("damping_ratio".to_string(), toml::Value::Float(0.05))]);
        assert_eq!(scene.with_controller_overrides(&design).unwrap().controller.damping_ratio, 0.05);
    }
}
