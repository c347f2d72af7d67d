//! Validation: a raw scene ([`crate::config::raw`]) into SI parameter types, each
//! value checked with a message naming the full key, the value and its unit.
//!
//! # Bounds
//!
//! Every size that allocates or loops is bounded here, so a run stays finite
//! and its allocations small (the key table of docs/guide/scenes.md lists them):
//!
//! | quantity | bound |
//! |---|---|
//! | `scene.duration_s` | ≤ [`MAX_DURATION_S`] |
//! | `controller.rate_hz` | [`MIN_RATE_HZ`] to [`MAX_RATE_HZ`] |
//! | controller ticks, `duration_s × rate_hz` | ≤ [`MAX_TICKS`] |
//! | `output.rate_hz` | ≤ [`MAX_OUTPUT_RATE_HZ`] |
//! | output rows, `duration_s × output.rate_hz` | ≤ [`MAX_OUTPUT_ROWS`] |
//! | `[controller.params]` as TOML text | ≤ [`controller::PARAMS_LEN`] bytes |
//! | `controller.stiffness_n_per_m` | ≤ [`MAX_STIFFNESS_N_PER_M`] |
//!
//! Every numeric key has a physical range besides ([`bounds::BOUNDS`], one table): a finite
//! value no machine has (a mass of 1e300 or 1e-300 kg) is bad input, not a divergence.
//!
//! A run with fewer than [`FEW_TICKS`] controller ticks is allowed, with a warning.
//!
//! Every key is checked whatever the choices that read it: a NaN
//! `amb.nominal_gap_mm` is refused with the linear bearing too, and a NaN
//! `touchdown.palmgren_f0` with the constant drag.

use super::raw::*;
use super::{
    ConfigError, ControllerSettings, CosimSettings, InitialSettings, IntegratorSettings, Rotor, Scene, Source,
};
use crate::force::lumped::LumpedSupport;
use crate::force::{amb::AmbLaw, balls::BallSet, drag::RaceDrag, friction::Friction, rotor_race::RotorRace};
use crate::integrate::Method;
use crate::model::{Params, RaceWhenClear, Release, Spin, Support, TouchdownGeometry};
use controller::LoopConstants;
use std::path::Path;

// The bearing planes' tables, validated for every model's key struct (`config/models/`,
// `RotorKeys::build`) through `Context`.
mod bearing;
pub mod bounds;
mod controller_keys;
mod hardware_keys;
mod ross_ambs;
mod ross_axes;

pub use super::checks::{finite, non_negative, positive, range};
use super::models::Share;
use controller_keys::{cosim_settings, migrate_relev_aliases, resolve_command, stiffness};
use hardware_keys::hardware;

/// What a rotor model's key struct is built with ([`crate::config::models::BuildContext`],
/// implemented in `bearing.rs`): the scene as written (its bearing planes' tables), the shared
/// `[rotor]` keys validated, the scene's folder (the model's files).
struct Context<'a> {
    /// The scene as written.
    raw: &'a RawScene,
    /// The shared `[rotor]` keys, validated.
    whole: &'a Share,
    /// The scene's folder.
    base_dir: &'a Path,
}

/// Longest simulated time (s): about 11.6 days.
pub const MAX_DURATION_S: f64 = 1e6;
/// Lowest controller rate (Hz): one tick per 1000 s.
pub const MIN_RATE_HZ: f64 = 1e-3;
/// Highest controller rate (Hz).
pub const MAX_RATE_HZ: f64 = 1e7;
/// Most controller ticks (macro steps) in a run: `scene.duration_s × controller.rate_hz`.
pub const MAX_TICKS: f64 = 1e9;
/// Highest trace rate (Hz).
pub const MAX_OUTPUT_RATE_HZ: f64 = 1e7;
/// The live view's rate when `output.live_rate_hz` is not set (Hz): a screen's rate.
pub const DEFAULT_LIVE_RATE_HZ: f64 = 200.0;

/// `output.live_rate_hz`: > 0 and at most the output rate (the live view sends trace rows);
/// unset, [`DEFAULT_LIVE_RATE_HZ`] or the output rate if that is lower.
fn live_rate(key: Option<f64>, output_rate: f64) -> Result<f64, ConfigError> {
    let Some(rate) = key else { return Ok(DEFAULT_LIVE_RATE_HZ.min(output_rate)) };
    let rate = positive("output.live_rate_hz", rate, "Hz")?;
    if rate > output_rate {
        let why = format!("must be <= output.rate_hz = {output_rate} Hz: the live view sends trace rows");
        return Err(range("output.live_rate_hz", rate, "Hz", &why));
    }
    Ok(rate)
}

/// Most trace rows in a run: `scene.duration_s × output.rate_hz` (1000 s at 10 kHz).
pub const MAX_OUTPUT_ROWS: f64 = 1e7;
/// Stiffest loop the controller may be designed for (N/m): a closed-loop natural frequency
/// √(k_e / m_r) near 50 kHz for the study's rotor, six decades above the study's largest k_e.
/// The integrators must resolve the loop, so their work grows as √k_e; far beyond this the
/// current saturates within nanometres of the centre and the loop chatters: a 5 ms run at
/// k_e = 1e300 took minutes of computing and a full-length one would not end.
pub const MAX_STIFFNESS_N_PER_M: f64 = 1e12;
/// Fewer controller ticks than this in a run gets a warning.
pub const FEW_TICKS: f64 = 10.0;

/// Validates a raw scene into SI parameter types. `base_dir` resolves relative file paths.
///
/// The deprecated `controller.relev_*` keys become `controller.params` keys
/// (with law `relev`; ignored otherwise), each with a warning in
/// [`Scene::warnings`]; the resolved scene ([`Scene::to_toml`]) holds the
/// parameters only.
///
/// A realtime scene on `integrator.realtime = "fixed"` (the default) is then given the
/// fixed-step setting ([`Scene::fixed_step_overrides`]), written into the resolved scene, with
/// a warning when that changes its integrator.
pub fn validate(raw: RawScene, base_dir: &Path) -> Result<Scene, ConfigError> {
    let scene = validate_as_written(raw, base_dir)?;
    if scene.controller.mode != ControlMode::Realtime || scene.integrator.realtime != RealtimeSetting::Fixed {
        return Ok(scene);
    }
    let overrides = scene.fixed_step_overrides();
    let mut table = scene.table()?;
    for arg in &overrides {
        super::apply_override(&mut table, arg)?;
    }
    let fixed = super::parse_raw(table, "the realtime setting")?;
    let mut fixed = validate_as_written(fixed, base_dir)?;
    // The first pass's warnings (deprecated keys are moved by it and not seen again).
    fixed.warnings = scene.warnings;
    let (was, is) = (scene.source.raw.integrator_and_race(), fixed.source.raw.integrator_and_race());
    if was != is {
        fixed.warnings.push(format!(
            "controller.mode = \"realtime\" runs the fixed-step setting (integrator.realtime = \"fixed\", a bounded \
             cost per tick): {is} instead of the scene's {was}; integrator.realtime = \"scene\" keeps the scene's"
        ));
    }
    Ok(fixed)
}

/// [`validate`] without the realtime setting: the scene as written.
fn validate_as_written(mut raw: RawScene, base_dir: &Path) -> Result<Scene, ConfigError> {
    let mut warnings = Vec::new();
    migrate_relev_aliases(&mut raw.controller, &mut warnings)?;
    resolve_command(&mut raw.controller, base_dir)?;
    let fmu = super::fmu::resolve(&mut raw.controller, base_dir)?;
    // A ROSS file's AMB elements as the planes' AMBs (rotor.ross_ambs): written into the scene.
    let mut file_ambs = ross_ambs::apply(&mut raw, base_dir)?;
    ross_axes::apply(&mut raw, &mut file_ambs)?;
    // Every numeric key within its physical range, before any model is built from them.
    bounds::check(&raw)?;
    let (gravity, duration) = span(&raw)?;
    let (whole, unbalance_phase) = whole_rotor(&raw.rotor, gravity)?;
    // The rotor model, built from the scene by its own key struct.
    let mut rotor = raw.rotor.model.build(&Context { raw: &raw, whole: &whole, base_dir })?;
    // A ROSS file's bearings that act besides the AMBs, and its AMB elements made the planes'
    // AMBs: the run's first line says so.
    if let Rotor::Flexible(f) = &mut rotor {
        if let Some(note) = super::models::flexible::file_bearings_note(&raw.rotor, f) {
            warnings.insert(0, note);
        }
        if let Some(note) = ross_ambs::note(&raw, &file_ambs) {
            warnings.insert(0, note);
        }
        f.file_ambs = file_ambs;
    }
    // The sensor's and the controller's loop constants are the scene's (`[amb]`,
    // `[controller]`), the same on every plane.
    let loop_constants = rotor.plane(0).loop_constants;

    let controller = controller_settings(&raw.controller, duration, &mut warnings)?;
    let rate = controller.rate_hz;

    let integrator = integrator_settings(&raw.integrator)?;

    let output_rate = output_rate(&raw.output, duration)?;
    let initial = initial_settings(&raw.initial, unbalance_phase)?;
    if raw.sensor.adc_bits > 24 {
        return Err(range("sensor.adc_bits", raw.sensor.adc_bits, "bits", "must be between 0 (ideal) and 24"));
    }
    let sensor = crate::sensor::SensorSettings {
        gain: loop_constants.sensor_gain_v_per_m,
        noise_v: non_negative("sensor.noise_v_rms", raw.sensor.noise_v_rms, "V")?,
        seed: raw.sensor.noise_seed,
        adc_bits: raw.sensor.adc_bits,
        adc_range_v: positive("sensor.adc_range_v", raw.sensor.adc_range_v, "V")?,
    };
    let gaps: Vec<f64> = rotor.bearings().map(|p| p.contact.gap).collect();
    let laws: Vec<AmbLaw> = rotor.bearings().map(|p| p.amb).collect();
    let hardware = hardware(&raw, rotor.planes(), &gaps, &laws, &integrator, 1.0 / rate)?;
    let base = shock_table::programme_from_specs(&raw.shock, base_dir)?;
    // The resolved scene states the rotor model's defaults.
    rotor.record_defaults(&mut raw.rotor);
    let scene = Scene {
        name: raw.scene.name.clone(),
        description: raw.scene.description.clone(),
        duration,
        rotor,
        base,
        controller,
        integrator,
        initial,
        sensor,
        hardware,
        output_interval: 1.0 / output_rate,
        plots: raw.output.plots,
        mcap: raw.output.mcap.unwrap_or(false),
        live_rate_hz: live_rate(raw.output.live_rate_hz, output_rate)?,
        mcap_compression: raw.output.mcap_compression.unwrap_or(super::McapCompression::None),
        warnings,
        source: Source { shocks: raw.shock.len(), raw, base_dir: base_dir.to_path_buf() },
    };
    // The law validates its own parameters: a scene it refuses is bad input, before any run.
    // A controller command serves laws of its own: it checks them, in the handshake.
    if let Some(spec) = &fmu {
        super::fmu::check(spec, scene.rotor_design().axes() as usize)?;
    } else if scene.controller.cosim.command.is_none() {
        controller::build_rotor_law(&scene.controller.law, &scene.rotor_design(), &scene.controller.params)?;
    }
    Ok(scene)
}

/// `scene.gravity_m_s2` and `scene.duration_s` (bounded), and `housing.mass_kg` checked.
fn span(raw: &RawScene) -> Result<(f64, f64), ConfigError> {
    let gravity = non_negative("scene.gravity_m_s2", raw.scene.gravity_m_s2, "m/s²")?;
    let duration = positive("scene.duration_s", raw.scene.duration_s, "s")?;
    if duration > MAX_DURATION_S {
        return Err(range("scene.duration_s", duration, "s", &format!("must be <= {MAX_DURATION_S:e} s")));
    }
    positive("housing.mass_kg", raw.housing.mass_kg, "kg")?;
    Ok((gravity, duration))
}

/// The shared `[rotor]` keys: the whole rotor as each model shares it out over its planes, and
/// the unbalance's angle at t = 0 (rad).
fn whole_rotor(r: &RawRotor, gravity: f64) -> Result<(Share, f64), ConfigError> {
    let unbalance_phase = finite("rotor.unbalance_phase_deg", r.unbalance_phase_deg, "deg")?.to_radians();
    let rotor_mass = positive("rotor.mass_kg", r.mass_kg, "kg")?;
    let eccentricity = non_negative("rotor.eccentricity_um", r.eccentricity_um, "µm")? * 1e-6;
    let rotor_inertia = positive("rotor.polar_inertia_kg_m2", r.polar_inertia_kg_m2, "kg·m²")?;
    let rotor_radius = positive("rotor.radius_mm", r.radius_mm, "mm")? * 1e-3;
    let speed = non_negative("rotor.speed_hz", r.speed_hz, "Hz")? * std::f64::consts::TAU;
    let drive_gain = non_negative("rotor.drive_gain_n_m_s", r.drive_gain_n_m_s, "N·m·s/rad")?;
    let torque_limit = non_negative("rotor.drive_torque_limit_n_m", r.drive_torque_limit_n_m, "N·m")?;
    let spin = match r.spin {
        SpinChoice::Held => Spin::Held,
        SpinChoice::Free => Spin::Free { drive_gain, torque_limit },
    };
    let whole =
        Share { gravity, mass: rotor_mass, eccentricity, inertia: rotor_inertia, radius: rotor_radius, speed, spin };
    Ok((whole, unbalance_phase))
}

/// `[controller]` validated: its rate within the bounds and the run's ticks (a warning when
/// there are few), its parameters' length, its delay.
fn controller_settings(
    ctl: &RawController,
    duration: f64,
    warnings: &mut Vec<String>,
) -> Result<ControllerSettings, ConfigError> {
    let rate = positive("controller.rate_hz", ctl.rate_hz, "Hz")?;
    if !(MIN_RATE_HZ..=MAX_RATE_HZ).contains(&rate) {
        return Err(range(
            "controller.rate_hz",
            rate,
            "Hz",
            &format!("must be between {MIN_RATE_HZ:e} and {MAX_RATE_HZ:e} Hz"),
        ));
    }
    let ticks = (duration * rate).ceil();
    if ticks > MAX_TICKS {
        return Err(range(
            "scene.duration_s",
            duration,
            "s",
            &format!(
                "with controller.rate_hz = {rate} Hz the run has {ticks:e} controller ticks: at most {MAX_TICKS:e} \
                 (shorten the run or lower the rate)"
            ),
        ));
    }
    if ticks < FEW_TICKS {
        warnings.push(format!(
            "controller.rate_hz = {rate} Hz gives {ticks} controller tick(s) in scene.duration_s = {} s \
             (fewer than {FEW_TICKS}): the controller acts once per tick",
            plant_physics::number::shown(duration)
        ));
    }
    let params = controller::Params::new(ctl.params.clone());
    if let Err(controller::ParamsError::TooLong { len }) = params.to_document() {
        return Err(range(
            "controller.params",
            format!("{len} bytes of TOML text"),
            "",
            &format!("must be at most {} bytes (the handshake carries it)", controller::PARAMS_LEN),
        ));
    }
    let controller = ControllerSettings {
        mode: ctl.mode,
        law: ctl.law.clone(),
        rate_hz: rate,
        period: 1.0 / rate,
        stiffness: stiffness(ctl.stiffness_n_per_m)?,
        damping_ratio: non_negative("controller.damping_ratio", ctl.damping_ratio, "")?,
        delay_samples: ctl.delay_samples,
        gravity_bias: ctl.gravity_bias,
        params,
        cosim: cosim_settings(ctl)?,
        max_invalid_burst: ctl.max_invalid_burst,
        max_invalid_fraction: match ctl.max_invalid_fraction {
            f if f.is_finite() && (0.0..=1.0).contains(&f) => f,
            f => return Err(range("controller.max_invalid_fraction", f, "", "must be between 0 and 1")),
        },
    };
    if ctl.delay_samples > 1000 {
        return Err(range("controller.delay_samples", ctl.delay_samples, "samples", "must be <= 1000"));
    }
    if ctl.mode == ControlMode::Realtime && ctl.delay_samples == 0 {
        return Err(range(
            "controller.delay_samples",
            ctl.delay_samples,
            "samples",
            "must be >= 1 in realtime mode (the reply to sample k arrives during period k)",
        ));
    }
    Ok(controller)
}

/// `[integrator]` validated.
fn integrator_settings(int: &RawIntegrator) -> Result<IntegratorSettings, ConfigError> {
    let rtol = positive("integrator.rtol", int.rtol, "")?;
    let atol_all = positive("integrator.atol", int.atol, "")?;
    let pick = |key: &str, v: Option<f64>, unit: &str| v.map_or(Ok(atol_all), |v| positive(key, v, unit));
    let ap = pick("integrator.atol_position_m", int.atol_position_m, "m")?;
    let av = pick("integrator.atol_velocity_m_s", int.atol_velocity_m_s, "m/s")?;
    let aa = pick("integrator.atol_angle_rad", int.atol_angle_rad, "rad")?;
    let aw = pick("integrator.atol_angular_speed_rad_s", int.atol_angular_speed_rad_s, "rad/s")?;
    if !(1..=100_000).contains(&int.substeps) {
        return Err(range("integrator.substeps", int.substeps, "", "must be between 1 and 100000"));
    }
    if int.contact_substeps > 100_000 {
        return Err(range(
            "integrator.contact_substeps",
            int.contact_substeps,
            "",
            "must be between 0 (= substeps) and 100000",
        ));
    }
    let integrator = IntegratorSettings {
        method: int.method,
        rtol,
        atol_groups: [ap, av, aa, aw],
        substeps: int.substeps,
        contact_substeps: if int.contact_substeps == 0 { int.substeps } else { int.contact_substeps },
        radius_guard: positive("integrator.radius_guard_mm", int.radius_guard_mm, "mm")? * 1e-3,
        realtime: int.realtime,
    };
    Ok(integrator)
}

/// `output.rate_hz`, bounded, and the trace's rows over `duration`.
fn output_rate(output: &RawOutput, duration: f64) -> Result<f64, ConfigError> {
    let output_rate = positive("output.rate_hz", output.rate_hz, "Hz")?;
    if output_rate > MAX_OUTPUT_RATE_HZ {
        return Err(range("output.rate_hz", output_rate, "Hz", &format!("must be <= {MAX_OUTPUT_RATE_HZ:e} Hz")));
    }
    let rows = (duration * output_rate).ceil();
    if rows > MAX_OUTPUT_ROWS {
        return Err(range(
            "output.rate_hz",
            output_rate,
            "Hz",
            &format!(
                "with scene.duration_s = {duration} s the trace has {rows:e} rows: at most {MAX_OUTPUT_ROWS:e} \
                 (lower the output rate or shorten the run)"
            ),
        ));
    }
    Ok(output_rate)
}

/// `[initial]` validated; `unbalance_phase` is `rotor.unbalance_phase_deg` (rad).
fn initial_settings(initial: &RawInitial, unbalance_phase: f64) -> Result<InitialSettings, ConfigError> {
    let initial = InitialSettings {
        unbalance_orbit: initial.unbalance_orbit,
        unbalance_phase,
        rotor_offset: [
            finite("initial.rotor_x_um", initial.rotor_x_um, "µm")? * 1e-6,
            finite("initial.rotor_y_um", initial.rotor_y_um, "µm")? * 1e-6,
        ],
        slope_offset: [
            finite("initial.slope_x_urad", initial.slope_x_urad.unwrap_or(0.0), "µrad")? * 1e-6,
            finite("initial.slope_y_urad", initial.slope_y_urad.unwrap_or(0.0), "µrad")? * 1e-6,
        ],
    };
    Ok(initial)
}

#[cfg(test)]
mod tests {
    use super::range;

    #[test]
    fn huge_values_read_in_scientific_notation_and_others_as_written() {
        assert_eq!(
            range("scene.duration_s", 1e300, "s", "too long").to_string(),
            "scene.duration_s = 1e300 s: too long"
        );
        assert_eq!(range("a.b", 2.5e-20, "m", "w").to_string(), "a.b = 2.5e-20 m: w");
        assert_eq!(range("a.b", 0.5, "m", "w").to_string(), "a.b = 0.5 m: w");
        assert_eq!(range("a.b", f64::NAN, "m", "w").to_string(), "a.b = NaN m: w");
        assert_eq!(range("a.b", "\"long\"", "ms", "w").to_string(), "a.b = \"long\" ms: w");
    }
}
