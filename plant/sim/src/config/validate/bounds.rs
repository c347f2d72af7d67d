//! The physical range of every numeric scene key, in one table (issue 40, "bad input"): a
//! finite value far outside what a machine of this kind can have (`rotor.mass_kg = 1e300`,
//! a mass of `1e-300` kg, a rotor `1e300` µm off centre) is bad input, refused at load naming
//! key, value, unit and the allowed range, instead of reaching the integrator and ending as a
//! numerical divergence.
//!
//! The ranges are generous: decades beyond any shipped scene, sweep, test or doc, so that they
//! refuse only values no machine has. A key's own check (`positive`, `non_negative`, a
//! choice's bound) still gives its message for a NaN, an infinity and a value of the wrong sign:
//! this table refuses what those let through (too large, too small a positive size, too far
//! below zero), and runs first, before any model is built from the values.

use super::{range, ConfigError, RawScene};

/// A key's range: `lo..=hi` in the key's unit. `lo > 0` is a positive size (a value in
/// `(0, lo)` is refused); `lo == 0` takes any tiny value as the zero it stands for.
#[derive(Clone, Copy, Debug)]
pub struct Bound {
    /// The key as the scene file spells it (`table.key`; a two-plane scene's `[touchdown.a]`
    /// and `[touchdown.b]` keys take their table's).
    pub key: &'static str,
    /// Smallest value.
    pub lo: f64,
    /// Largest value.
    pub hi: f64,
    /// The key's unit, as messages write it.
    pub unit: &'static str,
    /// What the key's own check bounds already, with its own message (listed here all the
    /// same, so that this table is the whole list of ranges).
    pub own: Own,
}

/// What a key's own check bounds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Own {
    /// Its sign only: this table gives the range.
    Sign,
    /// Its largest value: this table gives the smallest.
    Hi,
    /// Its whole range.
    Range,
}

const fn b(key: &'static str, lo: f64, hi: f64, unit: &'static str) -> Bound {
    Bound { key, lo, hi, unit, own: Own::Sign }
}

/// A key whose own check bounds `own` of its range.
const fn o(key: &'static str, lo: f64, hi: f64, unit: &'static str, own: Own) -> Bound {
    Bound { key, lo, hi, unit, own }
}

/// Every numeric key's range. Keys bounded by their own checks already (`controller.rate_hz`,
/// the co-simulation's timeouts and fractions, `amb.axis_angle_deg`, `rotor.modal_damping`) are
/// listed as well, with the same range, so that this table is the whole list.
pub const BOUNDS: &[Bound] = &[
    // [scene]: any positive duration is a run (the rows' bound is `output_rate`'s).
    o("scene.duration_s", 0.0, super::MAX_DURATION_S, "s", Own::Range),
    b("scene.gravity_m_s2", 0.0, 1e4, "m/s²"),
    // [rotor], every model's shared keys.
    b("rotor.mass_kg", 1e-6, 1e6, "kg"),
    b("rotor.eccentricity_um", 0.0, 1e5, "µm"),
    b("rotor.polar_inertia_kg_m2", 1e-12, 1e6, "kg·m²"),
    b("rotor.radius_mm", 1e-3, 1e5, "mm"),
    b("rotor.speed_hz", 0.0, 1e6, "Hz"),
    b("rotor.unbalance_phase_deg", -1e6, 1e6, "deg"),
    b("rotor.drive_gain_n_m_s", 0.0, 1e9, "N·m·s/rad"),
    b("rotor.drive_torque_limit_n_m", 0.0, 1e9, "N·m"),
    // [rotor], the two-plane rotor's own.
    b("rotor.transverse_inertia_kg_m2", 1e-12, 1e6, "kg·m²"),
    b("rotor.couple_unbalance_urad", 0.0, 1e6, "µrad"),
    b("rotor.couple_unbalance_phase_deg", -1e6, 1e6, "deg"),
    b("rotor.bearing_a_mm", -1e5, 1e5, "mm"),
    b("rotor.bearing_b_mm", -1e5, 1e5, "mm"),
    b("rotor.sensor_a_mm", -1e5, 1e5, "mm"),
    b("rotor.sensor_b_mm", -1e5, 1e5, "mm"),
    b("rotor.end_a_mm", -1e5, 1e5, "mm"),
    b("rotor.end_b_mm", -1e5, 1e5, "mm"),
    // [rotor], the flexible rotor's own (its node keys are bounded by the shaft's nodes).
    b("rotor.cutoff_hz", 1e-3, 1e9, "Hz"),
    o("rotor.modal_damping", 0.0, 1.0, "", Own::Range),
    // [touchdown]
    b("touchdown.air_gap_mm", 1e-6, 1e3, "mm"),
    b("touchdown.race_mass_kg", 1e-9, 1e6, "kg"),
    b("touchdown.race_polar_inertia_kg_m2", 1e-15, 1e6, "kg·m²"),
    b("touchdown.ball_diameter_mm", 1e-3, 1e4, "mm"),
    b("touchdown.pitch_diameter_mm", 1e-3, 1e5, "mm"),
    b("touchdown.outer_diameter_mm", 1e-3, 1e5, "mm"),
    b("touchdown.width_mm", 1e-3, 1e5, "mm"),
    b("touchdown.ball_clearance_mm", 0.0, 1e3, "mm"),
    b("touchdown.lumped_reference_mm", 1e-9, 1e3, "mm"),
    b("touchdown.cage_phase_deg", -1e6, 1e6, "deg"),
    b("touchdown.drag_torque_n_m", 0.0, 1e6, "N·m"),
    b("touchdown.drag_smoothing_rad_s", 1e-9, 1e9, "rad/s"),
    b("touchdown.palmgren_f0", 0.0, 1e3, ""),
    b("touchdown.palmgren_viscosity_cst", 1e-6, 1e7, "cSt"),
    b("touchdown.palmgren_f1", 0.0, 1e3, ""),
    // [housing]
    b("housing.mass_kg", 1e-6, 1e9, "kg"),
    // [contact]
    b("contact.rotor_race_stiffness_n_per_m10_9", 1e-3, 1e15, "N/m^(10/9)"),
    b("contact.rotor_race_damping_n_s_per_m", 0.0, 1e9, "N·s/m"),
    b("contact.ball_stiffness_n_per_m1_5", 1e-3, 1e15, "N/m^(3/2)"),
    b("contact.ball_damping_n_s_per_m", 0.0, 1e9, "N·s/m"),
    b("contact.damping_depth_mm", 1e-9, 1e3, "mm"),
    b("contact.friction_static", 0.0, 100.0, ""),
    b("contact.friction_dynamic", 0.0, 100.0, ""),
    b("contact.stribeck_static_m_s", 1e-9, 1e6, "m/s"),
    b("contact.stribeck_dynamic_m_s", 1e-9, 1e6, "m/s"),
    // [amb]
    b("amb.ki_n_per_a", 1e-6, 1e9, "N/A"),
    b("amb.ks_n_per_m", 0.0, 1e12, "N/m"),
    b("amb.amp_gain_a_per_v", 1e-9, 1e9, "A/V"),
    b("amb.sensor_gain_v_per_m", 1e-3, 1e12, "V/m"),
    b("amb.nominal_gap_mm", 1e-6, 1e3, "mm"),
    b("amb.magnet_force_limit_n", 1e-6, 1e9, "N"),
    b("amb.bus_voltage_v", 1e-6, 1e6, "V"),
    b("amb.coil_inductance_mh", 1e-9, 1e9, "mH"),
    b("amb.coil_resistance_ohm", 0.0, 1e9, "Ω"),
    b("amb.current_loop_hz", 1e-3, 1e9, "Hz"),
    b("amb.back_emf_v_s_per_m", 0.0, 1e9, "V·s/m"),
    o("amb.axis_angle_deg", -90.0, 90.0, "°", Own::Range),
    // [controller]: a timeout of at least a microsecond (0 where the key takes it: none).
    o("controller.rate_hz", super::MIN_RATE_HZ, super::MAX_RATE_HZ, "Hz", Own::Range),
    o("controller.stiffness_n_per_m", 1e-6, super::MAX_STIFFNESS_N_PER_M, "N/m", Own::Hi),
    b("controller.damping_ratio", 0.0, 1e3, ""),
    b("controller.current_limit_a", 1e-9, 1e6, "A"),
    o("controller.reply_timeout_ms", 1e-3, 3.6e6, "ms", Own::Hi),
    o("controller.reconnect_timeout_ms", 0.0, 3.6e6, "ms", Own::Range),
    o("controller.connect_timeout_ms", 1e-3, 3.6e6, "ms", Own::Hi),
    o("controller.lockstep_timeout_ms", 1e-3, 3.6e6, "ms", Own::Hi),
    o("controller.spin_us", 0.0, 1e6, "µs", Own::Range),
    o("controller.max_miss_fraction", 0.0, 1.0, "", Own::Range),
    o("controller.max_invalid_fraction", 0.0, 1.0, "", Own::Range),
    o("controller.max_overrun_fraction", 0.0, 1.0, "", Own::Range),
    // [integrator]: a tolerance below 1e-16 (relative) or 1e-20 (absolute, SI) is below what
    // a double resolves; above 1 it controls nothing.
    b("integrator.rtol", 1e-16, 1.0, ""),
    b("integrator.atol", 1e-20, 1.0, ""),
    b("integrator.atol_position_m", 1e-20, 1.0, "m"),
    b("integrator.atol_velocity_m_s", 1e-20, 1.0, "m/s"),
    b("integrator.atol_angle_rad", 1e-20, 1.0, "rad"),
    b("integrator.atol_angular_speed_rad_s", 1e-20, 1.0, "rad/s"),
    b("integrator.radius_guard_mm", 1e-6, 1e3, "mm"),
    // [initial]: an offset within a metre (a test starts a rotor 1 m off centre to see a
    // divergence at t = 0 reported) and a slope within a radian.
    b("initial.rotor_x_um", -1e6, 1e6, "µm"),
    b("initial.rotor_y_um", -1e6, 1e6, "µm"),
    b("initial.slope_x_urad", -1e6, 1e6, "µrad"),
    b("initial.slope_y_urad", -1e6, 1e6, "µrad"),
    // [sensor]
    b("sensor.noise_v_rms", 0.0, 1e6, "V"),
    b("sensor.adc_range_v", 1e-9, 1e6, "V"),
    b("sensor.bandwidth_hz", 0.0, 1e9, "Hz"),
    b("sensor.range_um", 0.0, 1e6, "µm"),
    // [output]: a row at least every 11.6 days (the longest run).
    o("output.rate_hz", 1e-6, super::MAX_OUTPUT_RATE_HZ, "Hz", Own::Hi),
    o("output.live_rate_hz", 1e-6, super::MAX_OUTPUT_RATE_HZ, "Hz", Own::Hi),
];

/// The range of `key` (`table.key`), if it is a numeric key of the table.
pub fn bound(key: &str) -> Option<&'static Bound> {
    BOUNDS.iter().find(|b| b.key == key)
}

/// Checks every numeric key the scene writes against its range ([`BOUNDS`]), a two-plane
/// scene's plane tables (`[amb.a]`, …) with their table's ranges. Leaves to the key's own
/// check what it refuses with its own message: NaN, ±∞, and a value in `[-hi, 0]` of a key that
/// must not be negative.
pub(super) fn check(raw: &RawScene) -> Result<(), ConfigError> {
    // The scene as the file's tables: one walk over every key, whatever its struct.
    let Ok(toml::Value::Table(scene)) = toml::Value::try_from(raw) else { return Ok(()) };
    for (table, keys) in &scene {
        let Some(keys) = keys.as_table() else { continue };
        for (key, value) in keys {
            match value {
                toml::Value::Table(plane) if matches!(key.as_str(), "a" | "b") => {
                    for (leaf, value) in plane {
                        within(&format!("{table}.{key}.{leaf}"), &format!("{table}.{leaf}"), value)?;
                    }
                }
                value => within(&format!("{table}.{key}"), &format!("{table}.{key}"), value)?,
            }
        }
    }
    Ok(())
}

/// `value` of `key` (spelled so in messages) within the range of `of`, if it has one.
fn within(key: &str, of: &str, value: &toml::Value) -> Result<(), ConfigError> {
    let (Some(bound), Some(v)) = (bound(of), value.as_float().or(value.as_integer().map(|i| i as f64))) else {
        return Ok(());
    };
    let Bound { lo, hi, unit, own, .. } = *bound;
    // What the key's own check refuses with its own words: not a number, an infinity, a value
    // at or below zero (within the range's size) of a key that must not be negative.
    let own_sign = !v.is_finite() || (lo >= 0.0 && v <= 0.0 && v >= -hi);
    let own = own == Own::Range || (own == Own::Hi && v > hi) || own_sign;
    if own || (lo..=hi).contains(&v) {
        return Ok(());
    }
    Err(range(key, v, unit, format!("must be between {} and {} {unit}", shown(lo), shown(hi)).trim_end()))
}

/// A bound as messages write it: `0`, `0.001`, `1e6`.
fn shown(v: f64) -> String {
    if v == 0.0 || (1.0..1e4).contains(&v.abs()) {
        v.to_string()
    } else {
        format!("{v:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every key of the table is a key of the scene format, once.
    #[test]
    fn every_bound_names_a_key_of_the_format_once() {
        let mut keys: Vec<String> =
            RawScene::tables().iter().flat_map(|(t, ks)| ks.iter().map(move |k| format!("{t}.{k}"))).collect();
        keys.sort();
        for (i, b) in BOUNDS.iter().enumerate() {
            assert!(keys.binary_search(&b.key.to_string()).is_ok(), "{} is not a scene key", b.key);
            assert!(BOUNDS[..i].iter().all(|o| o.key != b.key), "{} twice", b.key);
            assert!(b.lo < b.hi && b.lo.is_finite() && b.hi.is_finite(), "{}", b.key);
        }
    }

    #[test]
    fn a_refusal_names_key_value_unit_and_range() {
        let mut raw = RawScene::default();
        raw.rotor.mass_kg = 1e300;
        assert_eq!(check(&raw).unwrap_err().to_string(), "rotor.mass_kg = 1e300 kg: must be between 1e-6 and 1e6 kg");
        raw.rotor.mass_kg = 1e-300;
        assert_eq!(check(&raw).unwrap_err().to_string(), "rotor.mass_kg = 1e-300 kg: must be between 1e-6 and 1e6 kg");
        // A wrong sign is the key's own check's (`positive`): not refused here.
        raw.rotor.mass_kg = -1.0;
        assert!(check(&raw).is_ok());
        raw.rotor.mass_kg = -1e300;
        assert!(check(&raw).is_err());
        raw.rotor.mass_kg = 11.5;
        raw.initial.rotor_x_um = -2e6;
        assert_eq!(
            check(&raw).unwrap_err().to_string(),
            "initial.rotor_x_um = -2000000 µm: must be between -1e6 and 1e6 µm"
        );
    }
}
