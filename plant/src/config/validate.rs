//! Validation: a raw scene ([`super::raw`]) into SI parameter types, each
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
//! A run with fewer than [`FEW_TICKS`] controller ticks is allowed, with a warning.
//!
//! Every key is checked whatever the choices that read it: a NaN
//! `amb.nominal_gap_mm` is refused with the linear bearing too, and a NaN
//! `touchdown.palmgren_f0` with the constant drag.

use super::raw::*;
use super::{ConfigError, ControllerSettings, CosimSettings, InitialSettings, IntegratorSettings, Scene, Source};
use crate::force::lumped::LumpedSupport;
use crate::force::{amb::AmbLaw, balls::BallSet, drag::RaceDrag, friction::Friction, rotor_race::RotorRace};
use crate::integrate::Method;
use crate::model::{Params, RaceWhenClear, Release, Spin, Support};
use controller::LoopConstants;
use plant_physics::two_plane;
use std::path::Path;

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

/// `controller.stiffness_n_per_m`: > 0 and at most [`MAX_STIFFNESS_N_PER_M`].
fn stiffness(k_e: f64) -> Result<f64, ConfigError> {
    let k_e = positive("controller.stiffness_n_per_m", k_e, "N/m")?;
    if k_e > MAX_STIFFNESS_N_PER_M {
        return Err(range(
            "controller.stiffness_n_per_m",
            k_e,
            "N/m",
            &format!("must be <= {MAX_STIFFNESS_N_PER_M:e} N/m (the loop would chatter and the run not end)"),
        ));
    }
    Ok(k_e)
}

/// An out-of-range error naming the key, the value and its unit.
pub fn range(key: &str, value: impl std::fmt::Display, unit: &str, why: &str) -> ConfigError {
    ConfigError::Range {
        key: key.to_string(),
        value: readable(value.to_string()),
        unit: if unit.is_empty() { String::new() } else { format!(" {unit}") },
        why: why.to_string(),
    }
}

/// A number as it reads best in a message: Rust prints `1e300_f64` as 301 digits, so a long
/// decimal becomes scientific notation (`1e300`); anything else is kept as written.
fn readable(value: String) -> String {
    match value.parse::<f64>() {
        Ok(v) if value.len() > 16 && v.is_finite() => format!("{v:e}"),
        _ => value,
    }
}

/// Checks `value > 0` and finite.
pub fn positive(key: &str, value: f64, unit: &str) -> Result<f64, ConfigError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(range(key, value, unit, "must be a finite number > 0"))
    }
}

/// Checks `value ≥ 0` and finite.
pub fn non_negative(key: &str, value: f64, unit: &str) -> Result<f64, ConfigError> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(range(key, value, unit, "must be a finite number >= 0"))
    }
}

/// Checks that `value` is finite.
pub fn finite(key: &str, value: f64, unit: &str) -> Result<f64, ConfigError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(range(key, value, unit, "must be finite"))
    }
}

/// Validates the co-simulation keys of `[controller]`.
fn cosim_settings(ctl: &RawController) -> Result<CosimSettings, ConfigError> {
    let fallback = ctl.fallback;
    let ms = |key: &str, v: f64, zero_ok: bool| -> Result<f64, ConfigError> {
        let ok = v.is_finite() && (if zero_ok { v >= 0.0 } else { v > 0.0 }) && v <= 3.6e6;
        if ok {
            Ok(v * 1e-3)
        } else {
            Err(range(key, v, "ms", if zero_ok { "must be between 0 and 3.6e6" } else { "must be > 0 and <= 3.6e6" }))
        }
    };
    let reconnect_timeout = ms("controller.reconnect_timeout_ms", ctl.reconnect_timeout_ms, true)?;
    if fallback == Fallback::Stop && reconnect_timeout > 0.0 {
        return Err(range(
            "controller.reconnect_timeout_ms",
            ctl.reconnect_timeout_ms,
            "ms",
            "must be 0 with controller.fallback = \"stop\" (the run stops at the loss)",
        ));
    }
    if !(ctl.spin_us.is_finite() && (0.0..=1e6).contains(&ctl.spin_us)) {
        return Err(range("controller.spin_us", ctl.spin_us, "µs", "must be between 0 and 1e6"));
    }
    let pin_cores = match ctl.pin_cores.as_slice() {
        [] => None,
        &[plant, controller] => {
            let cores = controller::link::cores_online();
            for core in [plant, controller] {
                if core >= cores {
                    return Err(range(
                        "controller.pin_cores",
                        format!("{:?}", ctl.pin_cores),
                        "",
                        &format!("core {core} does not exist (this machine has cores 0 to {})", cores - 1),
                    ));
                }
            }
            Some([plant, controller])
        }
        _ => {
            return Err(range(
                "controller.pin_cores",
                format!("{:?}", ctl.pin_cores),
                "",
                "must be empty or two cores [plant, controller]",
            ))
        }
    };
    if ctl.realtime_priority > 99 {
        return Err(range("controller.realtime_priority", ctl.realtime_priority, "", "must be 0 (off) to 99"));
    }
    if ctl.realtime_priority > 97 && pin_cores.is_some_and(|[p, c]| p == c) {
        return Err(range(
            "controller.realtime_priority",
            ctl.realtime_priority,
            "",
            "must be 0 (off) to 97 with plant and controller on one core (controller.pin_cores): the controller \
             runs one level above the plant there, and the plant's watchdog one above that",
        ));
    }
    if !(ctl.max_miss_fraction.is_finite() && (0.0..=1.0).contains(&ctl.max_miss_fraction)) {
        return Err(range("controller.max_miss_fraction", ctl.max_miss_fraction, "", "must be between 0 and 1"));
    }
    if !(ctl.max_overrun_fraction.is_finite() && (0.0..=1.0).contains(&ctl.max_overrun_fraction)) {
        return Err(range("controller.max_overrun_fraction", ctl.max_overrun_fraction, "", "must be between 0 and 1"));
    }
    Ok(CosimSettings {
        fallback,
        reply_timeout: ms("controller.reply_timeout_ms", ctl.reply_timeout_ms, false)?,
        reconnect_timeout,
        connect_timeout: ms("controller.connect_timeout_ms", ctl.connect_timeout_ms, false)?,
        spin: ctl.spin_us * 1e-6,
        pin_cores,
        lockstep_timeout: ms("controller.lockstep_timeout_ms", ctl.lockstep_timeout_ms, false)?,
        command: super::fmu::command(ctl)?
            .map_or_else(|| ctl.command.as_ref().map(command_argv).transpose(), |c| Ok(Some(c)))?,
        realtime_priority: ctl.realtime_priority,
        max_miss_fraction: ctl.max_miss_fraction,
        max_overrun_fraction: ctl.max_overrun_fraction,
        pacing: ctl.pacing,
    })
}

/// `controller.command` as an argv: one string is a one-element command; a list must hold
/// strings, the first not empty.
fn command_argv(value: &toml::Value) -> Result<Vec<String>, ConfigError> {
    let bad = |why: &str| range("controller.command", value, "", why);
    let argv: Vec<String> = match value {
        toml::Value::String(s) => vec![s.clone()],
        toml::Value::Array(items) => items
            .iter()
            .map(|v| v.as_str().map(str::to_string))
            .collect::<Option<_>>()
            .ok_or_else(|| bad("must be a path (a string) or a list of strings"))?,
        _ => return Err(bad("must be a path (a string) or a list of strings")),
    };
    if argv.first().is_none_or(|a| a.is_empty()) {
        return Err(bad("must name a program (the first element is empty or missing)"));
    }
    Ok(argv)
}

/// Resolves `controller.command` against the scene's folder: an element that is a relative
/// path naming something that exists there becomes that absolute path; the others are kept.
/// The resolved list replaces the key, so that the resolved scene (`scene.toml` of a run
/// folder) runs the same command from anywhere.
fn resolve_command(ctl: &mut RawController, base_dir: &Path) -> Result<(), ConfigError> {
    let Some(value) = &ctl.command else { return Ok(()) };
    let argv = command_argv(value)?;
    let resolved: Vec<toml::Value> = argv
        .into_iter()
        .map(|arg| {
            let here = base_dir.join(&arg);
            let local = !arg.is_empty() && Path::new(&arg).is_relative() && here.exists();
            let arg = if local { std::path::absolute(&here).unwrap_or(here).display().to_string() } else { arg };
            toml::Value::String(arg)
        })
        .collect();
    ctl.command = Some(toml::Value::Array(resolved));
    Ok(())
}

/// The rotor's values a bearing plane's planar parameters take: for the planar model the
/// rotor's own, for a plane of the two-plane rotor its share ([`plant_physics::two_plane::Plane`]).
struct Share {
    gravity: f64,
    mass: f64,
    eccentricity: f64,
    inertia: f64,
    radius: f64,
    speed: f64,
    spin: Spin,
}

/// The full names of a bearing plane's keys: `touchdown.air_gap_mm`, or `touchdown.b.air_gap_mm`
/// where plane B's table sets it.
struct Keys<'a> {
    /// The plane's letter and its own tables of `[touchdown]`, `[contact]`, `[amb]`.
    plane: Option<(&'static str, [Option<&'a toml::Table>; 3])>,
}

impl Keys<'_> {
    fn key(&self, table: usize, field: &str) -> String {
        const TABLES: [&str; 3] = ["touchdown", "contact", "amb"];
        match self.plane {
            Some((plane, own)) if own[table].is_some_and(|t| t.contains_key(field)) => {
                format!("{}.{plane}.{field}", TABLES[table])
            }
            _ => format!("{}.{field}", TABLES[table]),
        }
    }

    fn td(&self, field: &str) -> String {
        self.key(0, field)
    }

    fn ct(&self, field: &str) -> String {
        self.key(1, field)
    }

    fn amb(&self, field: &str) -> String {
        self.key(2, field)
    }
}

/// One bearing plane's parameters, validated: its touchdown bearing (`[touchdown]`), contact
/// laws (`[contact]`) and AMB (`[amb]`, `controller.current_limit_a`), with the rotor's `share`.
fn bearing(
    td: &RawTouchdown,
    ct: &RawContact,
    amb: &RawAmb,
    ctl: &RawController,
    k: &Keys,
    share: &Share,
) -> Result<Params, ConfigError> {
    let gap = positive(&k.td("air_gap_mm"), td.air_gap_mm, "mm")? * 1e-3;
    let race_mass = positive(&k.td("race_mass_kg"), td.race_mass_kg, "kg")?;
    let race_inertia = positive(&k.td("race_polar_inertia_kg_m2"), td.race_polar_inertia_kg_m2, "kg·m²")?;
    let ball_d = positive(&k.td("ball_diameter_mm"), td.ball_diameter_mm, "mm")?;
    let dm = positive(&k.td("pitch_diameter_mm"), td.pitch_diameter_mm, "mm")?;
    if ball_d >= dm {
        return Err(range(
            &k.td("ball_diameter_mm"),
            ball_d,
            "mm",
            &format!("must be smaller than {}", k.td("pitch_diameter_mm")),
        ));
    }
    positive(&k.td("outer_diameter_mm"), td.outer_diameter_mm, "mm")?;
    positive(&k.td("width_mm"), td.width_mm, "mm")?;
    if !(3..=64).contains(&td.ball_count) {
        return Err(range(&k.td("ball_count"), td.ball_count, "", "must be between 3 and 64"));
    }
    let clearance = non_negative(&k.td("ball_clearance_mm"), td.ball_clearance_mm, "mm")? * 1e-3;
    let cage_phase = finite(&k.td("cage_phase_deg"), td.cage_phase_deg, "deg")?.to_radians();
    let (r_in, r_out) = (dm / 2.0 - ball_d / 2.0, dm / 2.0 + ball_d / 2.0);
    let reg_speed = positive(&k.td("drag_smoothing_rad_s"), td.drag_smoothing_rad_s, "rad/s")?;
    let torque = non_negative(&k.td("drag_torque_n_m"), td.drag_torque_n_m, "N·m")?;
    let f0 = non_negative(&k.td("palmgren_f0"), td.palmgren_f0, "")?;
    let nu0_cst = positive(&k.td("palmgren_viscosity_cst"), td.palmgren_viscosity_cst, "cSt")?;
    let f1 = non_negative(&k.td("palmgren_f1"), td.palmgren_f1, "")?;
    let drag = match td.drag {
        DragChoice::Constant => RaceDrag::Constant { torque, reg_speed },
        DragChoice::Palmgren => RaceDrag::Palmgren { f0, nu0_cst, f1, pitch_diameter_mm: dm, reg_speed },
    };

    let damping_depth = positive(&k.ct("damping_depth_mm"), ct.damping_depth_mm, "mm")? * 1e-3;
    let v_static = positive(&k.ct("stribeck_static_m_s"), ct.stribeck_static_m_s, "m/s")?;
    let v_dynamic = positive(&k.ct("stribeck_dynamic_m_s"), ct.stribeck_dynamic_m_s, "m/s")?;
    if v_dynamic < v_static {
        return Err(range(
            &k.ct("stribeck_dynamic_m_s"),
            v_dynamic,
            "m/s",
            &format!("must be >= {}", k.ct("stribeck_static_m_s")),
        ));
    }
    let friction = Friction {
        mu_static: non_negative(&k.ct("friction_static"), ct.friction_static, "")?,
        mu_dynamic: non_negative(&k.ct("friction_dynamic"), ct.friction_dynamic, "")?,
        v_static,
        v_dynamic,
    };
    let contact = RotorRace {
        gap,
        rotor_radius: share.radius,
        bore_radius: share.radius + gap,
        stiffness: positive(
            &k.ct("rotor_race_stiffness_n_per_m10_9"),
            ct.rotor_race_stiffness_n_per_m10_9,
            "N/m^(10/9)",
        )?,
        damping_max: non_negative(&k.ct("rotor_race_damping_n_s_per_m"), ct.rotor_race_damping_n_s_per_m, "N·s/m")?,
        damping_depth,
        friction,
    };
    let balls = BallSet::new(
        td.ball_count as usize,
        clearance,
        positive(&k.ct("ball_stiffness_n_per_m1_5"), ct.ball_stiffness_n_per_m1_5, "N/m^(3/2)")?,
        non_negative(&k.ct("ball_damping_n_s_per_m"), ct.ball_damping_n_s_per_m, "N·s/m")?,
        damping_depth,
    );

    let lumped_reference = positive(&k.td("lumped_reference_mm"), td.lumped_reference_mm, "mm")? * 1e-3;
    let support = match td.support {
        SupportChoice::Balls => Support::Balls,
        SupportChoice::Lumped => Support::Lumped(LumpedSupport::calibrated(&balls, lumped_reference)),
    };
    let release = match td.race_release {
        ReleaseChoice::Equilibrium => Release::Equilibrium,
        ReleaseChoice::Held => Release::Held,
    };
    let race_when_clear = match td.race_when_clear {
        RaceWhenClearChoice::Free => RaceWhenClear::Free,
        RaceWhenClearChoice::Parked => RaceWhenClear::Parked(release),
    };
    let ki = positive(&k.amb("ki_n_per_a"), amb.ki_n_per_a, "N/A")?;
    let ks = non_negative(&k.amb("ks_n_per_m"), amb.ks_n_per_m, "N/m")?;
    let s0 = positive(&k.amb("nominal_gap_mm"), amb.nominal_gap_mm, "mm")? * 1e-3;
    let magnet_force_limit = positive(&k.amb("magnet_force_limit_n"), amb.magnet_force_limit_n, "N")?;
    let amb_law = match amb.force_law {
        ForceLaw::Linear => AmbLaw::Linear { ki, ks },
        ForceLaw::Nonlinear => {
            if ks == 0.0 {
                return Err(range(
                    &k.amb("ks_n_per_m"),
                    ks,
                    "N/m",
                    "must be > 0 for the nonlinear law (it sets the bias current)",
                ));
            }
            if s0 <= gap + clearance {
                return Err(range(
                    &k.amb("nominal_gap_mm"),
                    amb.nominal_gap_mm,
                    "mm",
                    "must exceed the touchdown gap plus ball clearance",
                ));
            }
            AmbLaw::nonlinear_matching(ki, ks, s0, magnet_force_limit)
        }
    };
    let loop_constants = LoopConstants {
        ki_n_per_a: ki,
        ks_n_per_m: ks,
        amp_gain_a_per_v: positive(&k.amb("amp_gain_a_per_v"), amb.amp_gain_a_per_v, "A/V")?,
        sensor_gain_v_per_m: positive(&k.amb("sensor_gain_v_per_m"), amb.sensor_gain_v_per_m, "V/m")?,
        rotor_mass_kg: share.mass,
        gravity_m_s2: share.gravity,
        air_gap_m: gap,
    };
    let current_limit = positive("controller.current_limit_a", ctl.current_limit_a, "A")?;
    Ok(Params {
        gravity: share.gravity,
        rotor_mass: share.mass,
        eccentricity: share.eccentricity,
        rotor_inertia: share.inertia,
        speed: share.speed,
        spin: share.spin,
        race_mass,
        race_inertia,
        cage: td.cage,
        cage_phase,
        cage_ratio: r_in / (r_in + r_out),
        contact,
        balls,
        support,
        race_when_clear,
        drag,
        amb: amb_law,
        loop_constants,
        current_limit,
    })
}

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
    let fixed = toml::Value::Table(table)
        .try_into::<RawScene>()
        .map_err(|e| ConfigError::Parse { path: "the realtime setting".into(), message: e.to_string() })?;
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
    let (r, td, ct, amb, ctl, int) =
        (&raw.rotor, &raw.touchdown, &raw.contact, &raw.amb, &raw.controller, &raw.integrator);
    let gravity = non_negative("scene.gravity_m_s2", raw.scene.gravity_m_s2, "m/s²")?;
    let duration = positive("scene.duration_s", raw.scene.duration_s, "s")?;
    if duration > MAX_DURATION_S {
        return Err(range("scene.duration_s", duration, "s", &format!("must be <= {MAX_DURATION_S:e} s")));
    }
    positive("housing.mass_kg", raw.housing.mass_kg, "kg")?;
    let unbalance_phase = finite("rotor.unbalance_phase_deg", r.unbalance_phase_deg, "deg")?.to_radians();
    let two = r.model == RotorModel::TwoPlane;
    if !two {
        refuse_two_plane_keys(&raw)?;
    }
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
    let (physics, two_plane) = if two {
        let machine = two_plane_params(&raw, &whole)?;
        (machine.planes[0].params.clone(), Some(machine))
    } else {
        (bearing(td, ct, amb, ctl, &Keys { plane: None }, &whole)?, None)
    };
    let loop_constants = physics.loop_constants;

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
            "controller.rate_hz = {rate} Hz gives {ticks} controller tick(s) in scene.duration_s = {duration} s \
             (fewer than {FEW_TICKS}): the controller acts once per tick"
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
        atol: [ap, ap, aa, ap, ap, aa, av, av, aw, av, av, aw],
        atol_groups: [ap, av, aa, aw],
        substeps: int.substeps,
        contact_substeps: if int.contact_substeps == 0 { int.substeps } else { int.contact_substeps },
        radius_guard: positive("integrator.radius_guard_mm", int.radius_guard_mm, "mm")? * 1e-3,
        realtime: int.realtime,
    };

    let output_rate = positive("output.rate_hz", raw.output.rate_hz, "Hz")?;
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
    let initial = InitialSettings {
        unbalance_orbit: raw.initial.unbalance_orbit,
        unbalance_phase,
        rotor_offset: [
            finite("initial.rotor_x_um", raw.initial.rotor_x_um, "µm")? * 1e-6,
            finite("initial.rotor_y_um", raw.initial.rotor_y_um, "µm")? * 1e-6,
        ],
        slope_offset: [
            finite("initial.slope_x_urad", raw.initial.slope_x_urad.unwrap_or(0.0), "µrad")? * 1e-6,
            finite("initial.slope_y_urad", raw.initial.slope_y_urad.unwrap_or(0.0), "µrad")? * 1e-6,
        ],
    };
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
    let planes = if two { 2 } else { 1 };
    let gaps: Vec<f64> = match &two_plane {
        Some(m) => m.planes.iter().map(|p| p.params.contact.gap).collect(),
        None => vec![physics.contact.gap],
    };
    let laws: Vec<AmbLaw> = match &two_plane {
        Some(m) => m.planes.iter().map(|p| p.params.amb).collect(),
        None => vec![physics.amb],
    };
    let hardware = hardware(&raw, planes, &gaps, &laws, &integrator, 1.0 / rate)?;
    let base = shock_table::programme_from_specs(&raw.shock, base_dir)?;
    // The resolved scene states the two-plane rotor's defaults.
    if two_plane.is_some() {
        record_two_plane(&mut raw);
    }
    let scene = Scene {
        name: raw.scene.name.clone(),
        description: raw.scene.description.clone(),
        duration,
        params: physics,
        two_plane,
        base,
        controller,
        integrator,
        initial,
        sensor,
        hardware,
        output_interval: 1.0 / output_rate,
        plots: raw.output.plots,
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

/// The hardware between the wire and the physics (`amb.amplifier` and its keys, per plane;
/// `[sensor]`'s bandwidth, range and runout), validated against the planes' air gaps `gaps` (m),
/// their force laws `laws` (a unipolar amplifier carries the nonlinear law's bias) and the
/// integrator's step (a fixed-step method must resolve the fastest of them).
fn hardware(
    raw: &RawScene,
    planes: usize,
    gaps: &[f64],
    laws: &[AmbLaw],
    integrator: &IntegratorSettings,
    period: f64,
) -> Result<super::hardware::Hardware, ConfigError> {
    use crate::sensor::{Harmonic, LowPass};
    // The largest fixed step: an explicit method is stable on a real pole −ω for ω h ≤ 2
    // (Euler; RK4: 2.79), which also keeps the pole below the step's Nyquist rate 1/(2h).
    let resolve = |key: &str, value: f64, unit: &str, omega: f64, what: &str| -> Result<(), ConfigError> {
        if integrator.method == Method::SymplecticEuler {
            return Err(range(
                key,
                value,
                unit,
                "needs an integrator that steps any state: integrator.method = \"symplectic_euler\" needs the \
                 [positions; velocities] layout and the hardware's states are neither (use rk4, dp5 or dop853)",
            ));
        }
        if integrator.method.is_adaptive() {
            return Ok(());
        }
        let h = period / f64::from(integrator.substeps.min(integrator.contact_substeps));
        if omega * h > 2.0 {
            return Err(range(
                key,
                value,
                unit,
                &format!(
                    "{what} (pole at {omega:.4e} rad/s) is too fast for the fixed step h = {h:e} s \
                     (controller period / integrator.substeps): 2π f h must be ≤ 2, below the step's Nyquist \
                     rate 1/(2h); raise integrator.substeps or use an adaptive method"
                ),
            ));
        }
        Ok(())
    };
    let mut amplifiers = [None; 2];
    let mut unipolar = [None; 2];
    for (i, slot) in amplifiers.iter_mut().enumerate().take(planes) {
        let (amb, own, name) = if planes == 2 {
            let own = if i == 0 { &raw.amb.a } else { &raw.amb.b };
            let letter = ["a", "b"][i];
            (plane_table(&raw.amb, own.as_ref(), &format!("amb.{letter}"))?, own.clone(), Some(letter))
        } else {
            (raw.amb.clone(), None, None)
        };
        let key = |field: &str| match (name, &own) {
            (Some(letter), Some(t)) if t.contains_key(field) => format!("amb.{letter}.{field}"),
            _ => format!("amb.{field}"),
        };
        let v = positive(&key("bus_voltage_v"), amb.bus_voltage_v, "V")?;
        let l = positive(&key("coil_inductance_mh"), amb.coil_inductance_mh, "mH")? * 1e-3;
        let r = non_negative(&key("coil_resistance_ohm"), amb.coil_resistance_ohm, "Ω")?;
        let f = positive(&key("current_loop_hz"), amb.current_loop_hz, "Hz")?;
        let kb = non_negative(&key("back_emf_v_s_per_m"), amb.back_emf_v_s_per_m, "V·s/m")?;
        if amb.amplifier {
            let omega = std::f64::consts::TAU * f;
            resolve(&key("current_loop_hz"), f, "Hz", omega.max(r / l), "the current loop")?;
            *slot = Some(plant_physics::amplifier::Amplifier::design(v, l, r, f, kb));
        }
        if amb.amplifier_topology == AmplifierTopology::Unipolar {
            unipolar[i] = Some(unipolar_drive(&amb, amb.amplifier, laws[i], v, r, &key)?);
        }
    }
    let s = &raw.sensor;
    let bandwidth = non_negative("sensor.bandwidth_hz", s.bandwidth_hz, "Hz")?;
    let low_pass = if bandwidth > 0.0 {
        let corner = std::f64::consts::TAU * bandwidth;
        let lp = match s.filter_order {
            1 => LowPass::First { corner },
            2 => LowPass::Second { corner },
            n => return Err(range("sensor.filter_order", n, "", "must be 1 (first order) or 2 (Butterworth)")),
        };
        resolve("sensor.bandwidth_hz", bandwidth, "Hz", corner, "the sensor's low-pass")?;
        Some(lp)
    } else {
        if !(1..=2).contains(&s.filter_order) {
            return Err(range("sensor.filter_order", s.filter_order, "", "must be 1 (first order) or 2 (Butterworth)"));
        }
        None
    };
    let range_um = non_negative("sensor.range_um", s.range_um, "µm")?;
    if s.runout.len() > MAX_RUNOUT {
        return Err(range("sensor.runout", s.runout.len(), "harmonics", &format!("must be at most {MAX_RUNOUT}")));
    }
    let mut runout = Vec::with_capacity(s.runout.len());
    for (n, h) in s.runout.iter().enumerate() {
        let key = |field: &str| format!("sensor.runout[{n}].{field}");
        let axis = match h.axis {
            RunoutAxis::X => 0,
            RunoutAxis::Y => 1,
            RunoutAxis::XB => 2,
            RunoutAxis::YB => 3,
        };
        if axis >= 2 * planes {
            return Err(range(
                &key("axis"),
                format!("{:?}", h.axis).to_lowercase(),
                "",
                "is plane B's: this scene is planar",
            ));
        }
        if !(1..=MAX_RUNOUT_ORDER).contains(&h.order) {
            return Err(range(
                &key("order"),
                h.order,
                "",
                &format!("must be between 1 (once per revolution) and {MAX_RUNOUT_ORDER}"),
            ));
        }
        let amplitude = non_negative(&key("amplitude_um"), h.amplitude_um, "µm")? * 1e-6;
        let gap = gaps[axis / 2];
        if amplitude > gap {
            return Err(range(
                &key("amplitude_um"),
                h.amplitude_um,
                "µm",
                &format!(
                    "must be at most the air gap ({} µm): the sensor would read the rotor beyond the touchdown bearing",
                    gap * 1e6
                ),
            ));
        }
        let phase = finite(&key("phase_deg"), h.phase_deg, "deg")?.to_radians();
        runout.push(Harmonic { axis, order: h.order, amplitude, phase, kind: h.kind });
    }
    Ok(super::hardware::Hardware {
        amplifiers,
        unipolar,
        front_end: crate::sensor::FrontEnd { low_pass, runout, range: (range_um > 0.0).then_some(range_um * 1e-6) },
    })
}

/// A plane's unipolar drive (`amb.amplifier_topology = "unipolar"`, docs/MODEL.md §12.3): it
/// needs the amplifier on (`amplifier`), the nonlinear law `law` (whose bias each magnet
/// carries), and a bus `v` (V) above the voltage `R i_0` that holds the bias in a coil of
/// resistance `r` (Ω): at or below it the magnets cannot even carry the bias at rest. `key`
/// names a field as the scene wrote it (the plane's own table or the shared one).
fn unipolar_drive(
    amb: &RawAmb,
    amplifier: bool,
    law: AmbLaw,
    v: f64,
    r: f64,
    key: &dyn Fn(&str) -> String,
) -> Result<super::hardware::Unipolar, ConfigError> {
    let topology = key("amplifier_topology");
    if !amplifier {
        return Err(range(
            &topology,
            "unipolar",
            "",
            &format!("needs {} = true: the topology is that of the amplifiers it models", key("amplifier")),
        ));
    }
    let AmbLaw::Nonlinear { i0, .. } = law else {
        return Err(range(
            &topology,
            "unipolar",
            "",
            &format!(
                "needs {} = \"nonlinear\" (it is \"linear\"): each magnet's amplifier carries the bias i_0 \
                 of the two opposed magnets, which the linear law does not have",
                key("force_law")
            ),
        ));
    };
    if v <= r * i0 {
        return Err(range(
            &key("bus_voltage_v"),
            amb.bus_voltage_v,
            "V",
            &format!(
                "must exceed R i_0 = {:.4} V for a unipolar amplifier: the voltage that holds the bias current \
                 i_0 = {i0:.4} A (s_0 k_s / k_i) in a magnet's coil of {r} Ω",
                r * i0
            ),
        ));
    }
    Ok(super::hardware::Unipolar { bias: i0, bridge: amb.unipolar_bridge })
}

/// Most runout harmonics in a scene.
const MAX_RUNOUT: usize = 64;
/// Highest runout order.
const MAX_RUNOUT_ORDER: u32 = 64;

/// The keys of the two-plane rotor given in a planar scene, refused by name: each would be
/// silently ignored otherwise.
fn refuse_two_plane_keys(raw: &RawScene) -> Result<(), ConfigError> {
    let r = &raw.rotor;
    let given = [
        ("rotor.transverse_inertia_kg_m2", r.transverse_inertia_kg_m2, "kg·m²"),
        ("rotor.couple_unbalance_urad", r.couple_unbalance_urad, "µrad"),
        ("rotor.couple_unbalance_phase_deg", r.couple_unbalance_phase_deg, "deg"),
        ("rotor.bearing_a_mm", r.bearing_a_mm, "mm"),
        ("rotor.bearing_b_mm", r.bearing_b_mm, "mm"),
        ("rotor.sensor_a_mm", r.sensor_a_mm, "mm"),
        ("rotor.sensor_b_mm", r.sensor_b_mm, "mm"),
        ("rotor.end_a_mm", r.end_a_mm, "mm"),
        ("rotor.end_b_mm", r.end_b_mm, "mm"),
        ("initial.slope_x_urad", raw.initial.slope_x_urad, "µrad"),
        ("initial.slope_y_urad", raw.initial.slope_y_urad, "µrad"),
    ];
    const WHY: &str = "is a key of the two-plane rotor and this scene is planar (rotor.model = \"planar\"): set \
                       rotor.model = \"two_plane\" or remove the key";
    if let Some((key, value, unit)) = given.iter().find_map(|(k, v, u)| v.map(|v| (*k, v, *u))) {
        return Err(range(key, value, unit, WHY));
    }
    let tables = [
        ("touchdown", &raw.touchdown.a, &raw.touchdown.b),
        ("contact", &raw.contact.a, &raw.contact.b),
        ("amb", &raw.amb.a, &raw.amb.b),
    ];
    for (table, a, b) in tables {
        for (plane, own) in [("a", a), ("b", b)] {
            if let Some(own) = own {
                return Err(ConfigError::Range {
                    key: format!("{table}.{plane}"),
                    value: format!("a table of {} key(s)", own.len()),
                    unit: String::new(),
                    why: format!(
                        "per-plane tables ([{table}.a], [{table}.b]) are for the two-plane rotor and this scene is \
                         planar (rotor.model = \"planar\"): set rotor.model = \"two_plane\" or write the keys in [{table}]"
                    ),
                });
            }
        }
    }
    Ok(())
}

/// A per-plane table: the shared table `shared` (`[touchdown]`) with plane `plane`'s own keys
/// (`[touchdown.b]`) set over it, read as the same table.
fn plane_table<T: serde::Serialize + serde::de::DeserializeOwned>(
    shared: &T,
    own: Option<&toml::Table>,
    name: &str,
) -> Result<T, ConfigError> {
    let parse = |message: String| ConfigError::Parse { path: name.to_string(), message };
    let mut table = toml::Table::try_from(shared).map_err(|e| parse(e.to_string()))?;
    table.remove("a");
    table.remove("b");
    if let Some(own) = own {
        if let Some(nested) = ["a", "b"].into_iter().find(|k| own.contains_key(*k)) {
            return Err(parse(format!("a plane's table holds keys, not another plane's table (`{nested}`)")));
        }
        for (key, value) in own {
            table.insert(key.clone(), value.clone());
        }
    }
    toml::Value::Table(table).try_into::<T>().map_err(|e| parse(e.to_string()))
}

/// The two-plane rotor of a scene (`rotor.model = "two_plane"`), validated: its geometry and
/// inertia from `[rotor]`, each plane's bearing from the shared tables and its own.
fn two_plane_params(raw: &RawScene, whole: &Share) -> Result<two_plane::Params, ConfigError> {
    let r = &raw.rotor;
    let mm = |key: &str, value: f64| finite(key, value, "mm");
    let za = mm("rotor.bearing_a_mm", r.bearing_a_mm.unwrap_or(-180.0))?;
    let zb = mm("rotor.bearing_b_mm", r.bearing_b_mm.unwrap_or(180.0))?;
    const SIDES: &str = "bearing A lies on the −z side of the centre of mass (the origin of z) and bearing B on \
                         the +z side: the centre of mass is between the bearings";
    if za >= 0.0 {
        return Err(range("rotor.bearing_a_mm", za, "mm", &format!("must be < 0: {SIDES}")));
    }
    if zb <= 0.0 {
        return Err(range("rotor.bearing_b_mm", zb, "mm", &format!("must be > 0: {SIDES}")));
    }
    let ea = mm("rotor.end_a_mm", r.end_a_mm.unwrap_or(-230.0))?;
    let eb = mm("rotor.end_b_mm", r.end_b_mm.unwrap_or(230.0))?;
    if ea > za {
        return Err(range(
            "rotor.end_a_mm",
            ea,
            "mm",
            &format!("must be <= rotor.bearing_a_mm = {za} mm: the bearing sits on the rotor"),
        ));
    }
    if eb < zb {
        return Err(range(
            "rotor.end_b_mm",
            eb,
            "mm",
            &format!("must be >= rotor.bearing_b_mm = {zb} mm: the bearing sits on the rotor"),
        ));
    }
    let sensor = |key: &str, value: f64| -> Result<f64, ConfigError> {
        let v = mm(key, value)?;
        if !(ea..=eb).contains(&v) {
            return Err(range(
                key,
                v,
                "mm",
                &format!("must lie on the rotor, between rotor.end_a_mm = {ea} mm and rotor.end_b_mm = {eb} mm"),
            ));
        }
        Ok(v)
    };
    let sa = sensor("rotor.sensor_a_mm", r.sensor_a_mm.unwrap_or(za))?;
    let sb = sensor("rotor.sensor_b_mm", r.sensor_b_mm.unwrap_or(zb))?;
    let transverse = positive("rotor.transverse_inertia_kg_m2", r.transverse_inertia_kg_m2.unwrap_or(0.414), "kg·m²")?;
    let couple = non_negative("rotor.couple_unbalance_urad", r.couple_unbalance_urad.unwrap_or(0.0), "µrad")? * 1e-6;
    let couple_phase =
        finite("rotor.couple_unbalance_phase_deg", r.couple_unbalance_phase_deg.unwrap_or(0.0), "deg")?.to_radians();
    let stations = [za * 1e-3, zb * 1e-3];
    let sensors = [sa * 1e-3, sb * 1e-3];
    let plane = |i: usize| -> Result<two_plane::Plane, ConfigError> {
        let letter = ["a", "b"][i];
        let pick = |a: &Option<toml::Table>, b: &Option<toml::Table>| if i == 0 { a.clone() } else { b.clone() };
        let own = [
            pick(&raw.touchdown.a, &raw.touchdown.b),
            pick(&raw.contact.a, &raw.contact.b),
            pick(&raw.amb.a, &raw.amb.b),
        ];
        let td = plane_table(&raw.touchdown, own[0].as_ref(), &format!("touchdown.{letter}"))?;
        let ct = plane_table(&raw.contact, own[1].as_ref(), &format!("contact.{letter}"))?;
        let amb = plane_table(&raw.amb, own[2].as_ref(), &format!("amb.{letter}"))?;
        let mass = two_plane::load_share(whole.mass, stations, i);
        let fraction = mass / whole.mass;
        let spin = match whole.spin {
            Spin::Held => Spin::Held,
            Spin::Free { drive_gain, torque_limit } => {
                Spin::Free { drive_gain: drive_gain * fraction, torque_limit: torque_limit * fraction }
            }
        };
        let share = Share { mass, inertia: whole.inertia * fraction, spin, ..*whole };
        let keys = Keys { plane: Some((letter, [own[0].as_ref(), own[1].as_ref(), own[2].as_ref()])) };
        let params = bearing(&td, &ct, &amb, &raw.controller, &keys, &share)?;
        Ok(two_plane::Plane { station: stations[i], sensor: sensors[i], params })
    };
    Ok(two_plane::Params {
        gravity: whole.gravity,
        rotor: two_plane::Rotor {
            mass: whole.mass,
            transverse_inertia: transverse,
            polar_inertia: whole.inertia,
            eccentricity: whole.eccentricity,
            couple,
            couple_phase,
            speed: whole.speed,
            spin: whole.spin,
        },
        planes: [plane(0)?, plane(1)?],
    })
}

/// Writes the two-plane rotor's defaults into the raw scene (as the user would have written
/// them, in the file's units), so that the resolved `scene.toml` states them.
fn record_two_plane(raw: &mut RawScene) {
    let r = &mut raw.rotor;
    r.transverse_inertia_kg_m2.get_or_insert(0.414);
    r.couple_unbalance_urad.get_or_insert(0.0);
    r.couple_unbalance_phase_deg.get_or_insert(0.0);
    let a = *r.bearing_a_mm.get_or_insert(-180.0);
    let b = *r.bearing_b_mm.get_or_insert(180.0);
    r.sensor_a_mm.get_or_insert(a);
    r.sensor_b_mm.get_or_insert(b);
    r.end_a_mm.get_or_insert(-230.0);
    r.end_b_mm.get_or_insert(230.0);
}

/// Moves the deprecated `relev_*` keys into `params` (law `relev`) or drops them (another
/// law), with a warning each; both an alias and its parameter given is an error.
fn migrate_relev_aliases(ctl: &mut RawController, warnings: &mut Vec<String>) -> Result<(), ConfigError> {
    let given = [
        ctl.relev_enter_um.take(),
        ctl.relev_exit_um.take(),
        ctl.relev_damping_ratio.take(),
        ctl.relev_hold_ms.take(),
        ctl.relev_arm_ms.take(),
    ];
    let relev = controller::relev::LAW.name;
    for ((old, new), value) in controller::relev::ALIASES.iter().zip(given) {
        let Some(value) = value else { continue };
        if ctl.params.contains_key(*new) {
            return Err(ConfigError::Alias {
                old: format!("controller.{old}"),
                new: format!("controller.params.{new}"),
            });
        }
        if ctl.law == relev {
            warnings.push(format!(
                "controller.{old} is deprecated: write controller.params.{new} (a parameter of law relev)"
            ));
            ctl.params.insert(new.to_string(), toml::Value::Float(value));
        } else {
            warnings.push(format!(
                "controller.{old} is deprecated and ignored: it is controller.params.{new} of law relev, and this scene runs law {}",
                ctl.law
            ));
        }
    }
    Ok(())
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
