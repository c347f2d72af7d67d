//! Soak programme files: a base scene, overrides, and a long list of shocks
//! (written out, or drawn from a seeded generator), with the pass criteria.
//!
//! ```toml
//! scene = "../cosim-10g.toml"          # relative to this file
//! set = ["controller.damping_ratio=0.026"]  # --set overrides of the scene (optional)
//! mode = "lockstep"                    # or "realtime" (default lockstep)
//! settle_s = 2.0                       # after the last shock's pulse ends (s)
//! rss_every_s = 0.5                    # RSS sampling period, simulated time (s)
//!
//! [recovery]
//! hold_s = 0.2                         # clear this long, to the window's end (s)
//! radius_fraction = 0.5                # "clear": no contact and radius < this × air gap
//!
//! [random]                             # or [[shock]] tables as in scenes
//! count = 100
//! seed = 1
//! first_start_s = 0.1
//! peak_g = [1.0, 20.0]
//! spacing_s = [1.2, 1.8]               # start to start
//! direction_deg = [0.0, 360.0]
//! pulse = { kind = "double_half_sine", f1_hz = 10.0, f2_hz = 80.0 }
//!
//! [criteria]                           # each optional
//! min_recovered_fraction = 0.8
//! max_recovery_s = 1.0
//! max_sequence_gaps = 0
//! max_deadline_miss_fraction = 0.0
//! max_rss_growth_mib = 16.0
//! max_contact_force_n = 5000.0
//! ```
//!
//! The programme's shocks replace the scene's `[[shock]]` tables and its
//! duration becomes the last shock's end plus `settle_s`; `mode` sets
//! `controller.mode`. Random draws use SplitMix64 from `seed` (uniform in
//! each range, in the order start spacing, peak, direction per shock), so a
//! programme is the same on every machine.

use crate::config::{positive, range, ConfigError, ControlMode, Scene};
use crate::rng::SplitMix64;
use serde::{Deserialize, Serialize};
use shock_table::ShockSpec;
use std::path::{Path, PathBuf};

/// `[recovery]`: when a shock counts as recovered.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RawRecovery {
    /// How long the rotor must stay clear, up to the next shock (s). Default 0.2.
    pub hold_s: f64,
    /// Clear means no rotor–race contact and a radius below this fraction of the air gap. Default 0.5.
    pub radius_fraction: f64,
}

impl Default for RawRecovery {
    fn default() -> Self {
        Self { hold_s: 0.2, radius_fraction: 0.5 }
    }
}

/// The pulse of every random shock (its peak is drawn).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum RandomPulse {
    /// BV043/85 double half-sine with these corner frequencies.
    DoubleHalfSine {
        /// f_1 (Hz).
        f1_hz: f64,
        /// f_2 (Hz).
        f2_hz: f64,
    },
    /// Half-sine of this duration.
    HalfSine {
        /// Duration (s).
        duration_s: f64,
    },
}

/// `[random]`: a seeded random programme.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRandom {
    /// Number of shocks (1 to 100000).
    pub count: u32,
    /// Seed of the generator.
    pub seed: u64,
    /// Start of the first shock (s). Default 0.1.
    #[serde(default = "default_first_start")]
    pub first_start_s: f64,
    /// Peak range `[lo, hi]` (G), uniform. Default [1, 20].
    #[serde(default = "default_peak")]
    pub peak_g: [f64; 2],
    /// Start-to-start spacing range `[lo, hi]` (s), uniform.
    pub spacing_s: [f64; 2],
    /// Direction range `[lo, hi]` (deg from +x, 90 = +y), uniform. Default [0, 360].
    #[serde(default = "default_direction")]
    pub direction_deg: [f64; 2],
    /// Pulse shape. Default double half-sine, 10 Hz / 80 Hz.
    #[serde(default = "default_pulse")]
    pub pulse: RandomPulse,
}

fn default_first_start() -> f64 {
    0.1
}
fn default_peak() -> [f64; 2] {
    [1.0, 20.0]
}
fn default_direction() -> [f64; 2] {
    [0.0, 360.0]
}
fn default_pulse() -> RandomPulse {
    RandomPulse::DoubleHalfSine { f1_hz: 10.0, f2_hz: 80.0 }
}

/// `[criteria]`: limits the soak must meet; absent ones are not checked.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Criteria {
    /// Least share of the shocks recovered (0 to 1).
    pub min_recovered_fraction: Option<f64>,
    /// Longest recovery time of a recovered shock (s).
    pub max_recovery_s: Option<f64>,
    /// Most sequence gaps (messages lost).
    pub max_sequence_gaps: Option<u64>,
    /// Largest share of deadline misses.
    pub max_deadline_miss_fraction: Option<f64>,
    /// Largest resident-memory growth of either process, last sample less first (MiB).
    pub max_rss_growth_mib: Option<f64>,
    /// Largest rotor–race contact force (N).
    pub max_contact_force_n: Option<f64>,
}

/// A programme file as written.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawProgramme {
    /// Name (default: the file stem).
    #[serde(default)]
    pub name: String,
    /// Free text.
    #[serde(default)]
    pub description: String,
    /// Base scene, relative to the programme file.
    pub scene: PathBuf,
    /// Overrides of the scene, as for `--set`.
    #[serde(default)]
    pub set: Vec<String>,
    /// `lockstep` (default) or `realtime`.
    #[serde(default)]
    pub mode: SoakMode,
    /// Simulated time after the last shock's pulse ends (s).
    pub settle_s: f64,
    /// RSS sampling period in simulated time (s). Default 0.5.
    #[serde(default = "default_rss_every")]
    pub rss_every_s: f64,
    /// `[recovery]`.
    #[serde(default)]
    pub recovery: RawRecovery,
    /// `[random]`: a seeded random programme (or `[[shock]]`).
    #[serde(default)]
    pub random: Option<RawRandom>,
    /// `[[shock]]`: a fixed programme (or `[random]`).
    #[serde(default)]
    pub shock: Vec<ShockSpec>,
    /// `[criteria]`.
    #[serde(default)]
    pub criteria: Criteria,
}

/// `mode`: how the programme's controller process is driven.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SoakMode {
    /// The plant waits for every reply (default).
    #[default]
    Lockstep,
    /// The plant paces the wall clock.
    Realtime,
}

impl From<SoakMode> for ControlMode {
    fn from(m: SoakMode) -> Self {
        match m {
            SoakMode::Lockstep => ControlMode::Lockstep,
            SoakMode::Realtime => ControlMode::Realtime,
        }
    }
}
fn default_rss_every() -> f64 {
    0.5
}

/// One shock of a programme, as listed in `soak.csv`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PlannedShock {
    /// Start (s).
    pub start_s: f64,
    /// Peak acceleration (G): `peak_g` (or `design_accel_g / 2`), a sine's amplitude; NaN for records.
    pub peak_g: f64,
    /// Direction (deg from +x).
    pub direction_deg: f64,
    /// Pulse duration (s).
    pub duration_s: f64,
}

/// A validated programme.
#[derive(Clone, Debug)]
pub struct Programme {
    /// Name.
    pub name: String,
    /// The scene, with the programme's shocks, duration and mode.
    pub scene: Scene,
    /// The shocks, by start time.
    pub shocks: Vec<PlannedShock>,
    /// Recovery hold (s).
    pub hold: f64,
    /// Each bearing plane's clear radius (m): `recovery.radius_fraction` of its own air gap.
    pub clear_radius: Vec<f64>,
    /// RSS sampling period (s, simulated).
    pub rss_every: f64,
    /// Draw the soak's plots (the scene's `output.plots`, after the overrides).
    pub plots: bool,
    /// Limits.
    pub criteria: Criteria,
    /// The file as written.
    pub raw: RawProgramme,
}

/// A `[lo, hi]` range with `lo <= hi`, both finite and inside `[min, max]`.
fn span(key: &str, [lo, hi]: [f64; 2], unit: &str, (min, max): (f64, f64)) -> Result<[f64; 2], ConfigError> {
    let shown = format!("[{lo}, {hi}]");
    if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
        return Err(range(key, shown, unit, "must be two finite numbers [lo, hi] with lo <= hi"));
    }
    if lo < min || hi > max {
        return Err(range(key, shown, unit, &format!("must lie within [{min}, {max}]")));
    }
    Ok([lo, hi])
}

/// Rounds to 6 significant digits, so that generated values read well in
/// `scene.toml` and `soak.csv` (a start near 100 s moves by up to 50 µs; the
/// spacing check runs on the rounded starts).
fn tidy(v: f64) -> f64 {
    format!("{v:.5e}").parse().unwrap_or(v)
}

/// The shocks of a `[random]` table.
fn random_shocks(r: &RawRandom) -> Result<Vec<ShockSpec>, ConfigError> {
    if !(1..=100_000).contains(&r.count) {
        return Err(range("random.count", r.count, "", "must be between 1 and 100000"));
    }
    let first = r.first_start_s;
    if !(first.is_finite() && first >= 0.0) {
        return Err(range("random.first_start_s", first, "s", "must be a finite number >= 0"));
    }
    let peak = span("random.peak_g", r.peak_g, "G", (1e-6, 1000.0))?;
    let spacing = span("random.spacing_s", r.spacing_s, "s", (1e-6, 1e6))?;
    let direction = span("random.direction_deg", r.direction_deg, "deg", (-360.0, 720.0))?;
    let mut rng = SplitMix64::new(r.seed);
    let mut start = first;
    let mut shocks = Vec::with_capacity(r.count as usize);
    for j in 0..r.count {
        if j > 0 {
            start = tidy(start + rng.uniform(spacing));
        }
        let (peak_g, direction_deg) = (tidy(rng.uniform(peak)), tidy(rng.uniform(direction)));
        shocks.push(match r.pulse {
            RandomPulse::DoubleHalfSine { f1_hz, f2_hz } => ShockSpec::DoubleHalfSine {
                peak_g: Some(peak_g),
                design_accel_g: None,
                f1_hz,
                f2_hz,
                start_s: start,
                direction_deg,
            },
            RandomPulse::HalfSine { duration_s } => {
                ShockSpec::HalfSine { peak_g, duration_s, start_s: start, direction_deg }
            }
        });
    }
    Ok(shocks)
}

/// Most RSS samples over a soak (rows of `rss.csv`).
pub const MAX_RSS_SAMPLES: f64 = 1e6;

/// Reads a programme file, applies the programme's and then `cli_set`
/// overrides to its scene, and validates everything.
pub fn load(path: &Path, cli_set: &[String]) -> Result<Programme, ConfigError> {
    let text = shock_table::input::read_text(path, shock_table::input::MAX_TOML_BYTES)
        .map_err(|source| ConfigError::Read { path: path.to_path_buf(), source })?;
    let mut raw: RawProgramme = toml::from_str(&text)
        .map_err(|e| ConfigError::Parse { path: path.display().to_string(), message: e.to_string() })?;
    if raw.name.is_empty() {
        raw.name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    }
    let dir = path.parent().unwrap_or(Path::new("."));
    let mode = ControlMode::from(raw.mode);
    let settle = positive("settle_s", raw.settle_s, "s")?;
    let rss_every = positive("rss_every_s", raw.rss_every_s, "s")?;
    if settle > crate::config::validate::MAX_DURATION_S {
        return Err(range(
            "settle_s",
            settle,
            "s",
            &format!("must be <= {:e} s", crate::config::validate::MAX_DURATION_S),
        ));
    }
    let hold = positive("recovery.hold_s", raw.recovery.hold_s, "s")?;
    let fraction = raw.recovery.radius_fraction;
    if !(fraction.is_finite() && fraction > 0.0 && fraction <= 1.0) {
        return Err(range("recovery.radius_fraction", fraction, "", "must be > 0 and <= 1"));
    }
    if settle < hold {
        return Err(range("settle_s", settle, "s", &format!("must be >= recovery.hold_s ({hold} s)")));
    }
    check_criteria(&raw.criteria)?;

    let (specs, shocks, list_key) = planned_shocks(&raw, dir, hold)?;
    let last = shocks.last().map_or(0.0, |s| s.start_s + s.duration_s);

    // The scene: its file, the programme's overrides, the command line's, then the programme's
    // mode, shocks and duration.
    let scene_path = dir.join(&raw.scene);
    let mut set = raw.set.clone();
    set.extend(cli_set.iter().cloned());
    let base = crate::config::load_scene(&scene_path, &set)?;
    let plots = base.plots;
    let programme_set = [
        format!("controller.mode={}", toml::Value::String(crate::summary::snake_name(&mode))),
        format!("scene.duration_s={:?}", tidy(last + settle)),
        format!("scene.name={}", toml::Value::String(raw.name.clone())),
        // The soak draws its own plots; `scene.toml` would reproduce the run with the full trace.
        "output.plots=false".to_string(),
    ];
    // Shock files (recorded pulses) are relative to the programme file, like its other paths.
    let scene = base
        .with_shocks(&specs, dir, &programme_set)
        .map_err(|e| blame_duration(e, settle, last, list_key, &shocks))?;
    // One RSS sample per tick at most, and a bounded number of them (each is a row of rss.csv
    // and a few numbers in memory).
    let period = scene.controller.period;
    if rss_every < period || scene.duration / rss_every > MAX_RSS_SAMPLES {
        return Err(range(
            "rss_every_s",
            rss_every,
            "s",
            &format!(
                "must be at least the controller period ({period} s) and give at most {MAX_RSS_SAMPLES:e} samples over the soak's {} s",
                scene.duration
            ),
        ));
    }
    if hold < 10.0 * scene.output_interval {
        return Err(range(
            "recovery.hold_s",
            hold,
            "s",
            &format!("must be at least 10 output samples ({} s at output.rate_hz)", 10.0 * scene.output_interval),
        ));
    }
    let clear_radius = (0..scene.planes()).map(|i| fraction * scene.plane(i).contact.gap).collect();
    Ok(Programme {
        name: raw.name.clone(),
        scene,
        shocks,
        hold,
        clear_radius,
        rss_every,
        plots,
        criteria: raw.criteria.clone(),
        raw,
    })
}

/// The programme's shocks (exactly one of `[random]` and `[[shock]]`), in time order and each
/// far enough from the one before for its pulse and `hold` (s); the key that names their
/// spacing (`shock` or `random.spacing_s`).
fn planned_shocks(
    raw: &RawProgramme,
    dir: &Path,
    hold: f64,
) -> Result<(Vec<ShockSpec>, Vec<PlannedShock>, &'static str), ConfigError> {
    // Shocks: exactly one of [random] and [[shock]].
    let (specs, list_key) = match (&raw.random, raw.shock.is_empty()) {
        (Some(r), true) => (random_shocks(r)?, "random.spacing_s"),
        (None, false) => (raw.shock.clone(), "shock"),
        (Some(_), false) => {
            return Err(range("random", "and [[shock]]", "", "give either [random] or [[shock]], not both"))
        }
        (None, true) => return Err(range("shock", "none", "", "give [random] or at least one [[shock]]")),
    };
    let programme = shock_table::programme_from_specs(&specs, dir)?;
    let mut shocks = Vec::with_capacity(specs.len());
    for (spec, shock) in specs.iter().zip(&programme.shocks) {
        shocks.push(PlannedShock {
            start_s: shock.start,
            peak_g: spec.peak_g(),
            direction_deg: shock.direction().to_degrees(),
            duration_s: shock.pulse.duration(),
        });
    }
    for (j, pair) in shocks.windows(2).enumerate() {
        let (a, b) = (&pair[0], &pair[1]);
        let need = a.duration_s + hold;
        if b.start_s - a.start_s < need - 1e-12 {
            let key = if list_key == "shock" { format!("shock[{}].start_s", j + 1) } else { list_key.to_string() };
            let value = if list_key == "shock" {
                b.start_s.to_string()
            } else {
                format!("{:?}", raw.random.as_ref().map(|r| r.spacing_s).unwrap_or_default())
            };
            return Err(range(
                &key,
                value,
                "s",
                &format!(
                    "shock {} starts {:.4} s after shock {j}, which needs its pulse ({:.4} s) plus recovery.hold_s \
                     ({hold} s) = {need:.4} s: shocks must be in time order and must not overlap",
                    j + 1,
                    b.start_s - a.start_s,
                    a.duration_s
                ),
            ));
        }
    }
    Ok((specs, shocks, list_key))
}

/// A bound of the scene's duration is the programme's to blame: its last shock's end (`last`,
/// s) plus `settle` (s); the scene would name `scene.duration_s`, which the programme sets.
fn blame_duration(e: ConfigError, settle: f64, last: f64, list_key: &str, shocks: &[PlannedShock]) -> ConfigError {
    match e {
        ConfigError::Range { key, value, unit, why }
            if key == "scene.duration_s" || why.contains("scene.duration_s") =>
        {
            let (blame, shown) = if settle >= last || list_key != "shock" {
                ("settle_s".to_string(), settle.to_string())
            } else {
                (format!("shock[{}].start_s", shocks.len() - 1), shocks[shocks.len() - 1].start_s.to_string())
            };
            let why = format!(
                "the soak lasts its last shock's end ({last} s) plus settle_s ({settle} s) = {} s, so {key} = {value}{unit}: {why}",
                last + settle
            );
            range(&blame, shown, "s", &why)
        }
        e => e,
    }
}

fn check_criteria(c: &Criteria) -> Result<(), ConfigError> {
    let fraction = |key: &str, v: Option<f64>| match v {
        Some(v) if !(v.is_finite() && (0.0..=1.0).contains(&v)) => {
            Err(range(&format!("criteria.{key}"), v, "", "must be between 0 and 1"))
        }
        _ => Ok(()),
    };
    let nonneg = |key: &str, v: Option<f64>, unit: &str| match v {
        Some(v) if !(v.is_finite() && v >= 0.0) => {
            Err(range(&format!("criteria.{key}"), v, unit, "must be a finite number >= 0"))
        }
        _ => Ok(()),
    };
    fraction("min_recovered_fraction", c.min_recovered_fraction)?;
    fraction("max_deadline_miss_fraction", c.max_deadline_miss_fraction)?;
    nonneg("max_recovery_s", c.max_recovery_s, "s")?;
    nonneg("max_rss_growth_mib", c.max_rss_growth_mib, "MiB")?;
    nonneg("max_contact_force_n", c.max_contact_force_n, "N")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each bearing plane's clear radius is the fraction of its own air gap (it was plane A's
    /// gap for the whole rotor).
    #[test]
    fn each_plane_is_clear_within_its_own_gap() {
        let dir = crate::util::scratch("soak-gaps");
        let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/two-plane-asymmetric-10g.toml");
        let file = dir.join("p.toml");
        std::fs::write(
            &file,
            format!(
                "name = \"gaps\"\nscene = {:?}\nmode = \"lockstep\"\nsettle_s = 0.2\nrss_every_s = 0.05\n\
                 [recovery]\nhold_s = 0.1\nradius_fraction = 0.5\n\
                 [[shock]]\nkind = \"double_half_sine\"\nstart_s = 0.02\npeak_g = 2.0\nf1_hz = 10.0\nf2_hz = 80.0\n",
                scene.display().to_string()
            ),
        )
        .unwrap();
        let p = load(&file, &[]).unwrap();
        let gaps: Vec<f64> = (0..2).map(|i| p.scene.plane(i).contact.gap).collect();
        assert_ne!(gaps[0], gaps[1]);
        assert_eq!(p.clear_radius, vec![0.5 * gaps[0], 0.5 * gaps[1]]);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn random_programme_is_deterministic_and_in_range() {
        let r = RawRandom {
            count: 50,
            seed: 9,
            first_start_s: 0.1,
            peak_g: [1.0, 20.0],
            spacing_s: [1.0, 2.0],
            direction_deg: [0.0, 360.0],
            pulse: default_pulse(),
        };
        let a = random_shocks(&r).unwrap();
        assert_eq!(a, random_shocks(&r).unwrap());
        let mut last = None;
        for s in &a {
            let ShockSpec::DoubleHalfSine { peak_g: Some(p), start_s, direction_deg, .. } = s else { panic!() };
            assert!((1.0..=20.0).contains(p) && (0.0..=360.0).contains(direction_deg));
            if let Some(l) = last {
                // Starts are rounded to 6 significant digits: within 5e-5 s below 100 s.
                let gap: f64 = start_s - l;
                assert!((1.0 - 1e-4..=2.0 + 1e-4).contains(&gap), "spacing {gap}");
            }
            last = Some(*start_s);
        }
        let other = random_shocks(&RawRandom { seed: 10, ..r }).unwrap();
        assert_ne!(a, other);
    }
}
