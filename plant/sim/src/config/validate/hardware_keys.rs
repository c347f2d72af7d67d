//! `amb.amplifier*` and `[sensor]`'s front end: the hardware between the wire and the physics.

use super::bearing::plane_table;
use super::*;

/// The hardware between the wire and the physics (`amb.amplifier` and its keys, per plane;
/// `[sensor]`'s bandwidth, range and runout), validated against the planes' air gaps `gaps` (m),
/// their force laws `laws` (a unipolar amplifier carries the nonlinear law's bias) and the
/// integrator's step (a fixed-step method must resolve the fastest of them).
pub(super) fn hardware(
    raw: &RawScene,
    planes: usize,
    gaps: &[f64],
    laws: &[AmbLaw],
    integrator: &IntegratorSettings,
    period: f64,
) -> Result<crate::config::hardware::Hardware, ConfigError> {
    use crate::sensor::LowPass;
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
    let runout = runout(s, planes, gaps)?;
    Ok(crate::config::hardware::Hardware {
        amplifiers,
        unipolar,
        front_end: crate::sensor::FrontEnd { low_pass, runout, range: (range_um > 0.0).then_some(range_um * 1e-6) },
    })
}

/// `[[sensor.runout]]`'s harmonics, each on an axis of the scene's `planes` and at most the air
/// gap of its plane (`gaps`, m).
fn runout(s: &RawSensor, planes: usize, gaps: &[f64]) -> Result<Vec<crate::sensor::Harmonic>, ConfigError> {
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
        runout.push(crate::sensor::Harmonic { axis, order: h.order, amplitude, phase, kind: h.kind });
    }
    Ok(runout)
}

/// A plane's unipolar drive (`amb.amplifier_topology = "unipolar"`, docs/MODEL.md §12.3): it
/// needs the amplifier on (`amplifier`), the nonlinear law `law` (whose bias each magnet
/// carries), and a bus `v` (V) above the voltage `R i_0` that holds the bias in a coil of
/// resistance `r` (Ω): at or below it the magnets cannot even carry the bias at rest. `key`
/// names a field as the scene wrote it (the plane's own table or the shared one).
pub(super) fn unipolar_drive(
    amb: &RawAmb,
    amplifier: bool,
    law: AmbLaw,
    v: f64,
    r: f64,
    key: &dyn Fn(&str) -> String,
) -> Result<crate::config::hardware::Unipolar, ConfigError> {
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
    Ok(crate::config::hardware::Unipolar { bias: i0, bridge: amb.unipolar_bridge })
}

/// Most runout harmonics in a scene.
pub(super) const MAX_RUNOUT: usize = 64;
/// Highest runout order.
pub(super) const MAX_RUNOUT_ORDER: u32 = 64;
