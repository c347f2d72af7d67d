//! `rotor.ross_axes`: a ROSS file's `sensors_axis_rotation` made the planes' axis angles
//! (issue 38 item 2). With `"apply"`, after [`super::ross_ambs::apply`] has made the file's
//! `MagneticBearingElement`s the planes' AMBs, each element's rotation is written into its
//! plane's `[amb.a]` or `[amb.b]` as `axis_angle_deg`: the rest of the validation (and the
//! resolved `scene.toml`) sees it as if the scene had written it.

use super::*;
use plant_physics::flex::ross_amb::UsedAmb;

/// `rotor.ross_axes`'s value as the scene writes it.
pub(super) fn name(choice: RossAxes) -> &'static str {
    match choice {
        RossAxes::Apply => "\"apply\"",
        RossAxes::Ignore => "\"ignore\"",
    }
}

/// Each used element's axis rotation written into its plane's `amb.axis_angle_deg` with
/// `rotor.ross_axes = "apply"`, and recorded as applied in `used`; refused where the scene gives
/// the angle itself or has no file's AMBs to take it from.
pub(super) fn apply(raw: &mut RawScene, used: &mut [UsedAmb]) -> Result<(), ConfigError> {
    // A rigid rotor's key struct refuses the key.
    let Some(choice) = raw.rotor.flexible().and_then(|r| r.ross_axes) else { return Ok(()) };
    let key = "rotor.ross_axes";
    if used.is_empty() {
        return Err(range(
            key,
            name(choice),
            "",
            "says what to do with the axis rotation of a ROSS file's MagneticBearingElements, and this scene does \
             not make them its AMBs (rotor.ross_ambs = \"use\" or \"constants\"): remove it",
        ));
    }
    if choice == RossAxes::Ignore {
        return Ok(());
    }
    if raw.controller.gravity_bias && raw.controller.mode != ControlMode::Continuous {
        return Err(range(
            key,
            name(choice),
            "",
            "turns the planes' axes by the file's sensors_axis_rotation, and with controller.gravity_bias = true a \
             sampled or co-simulated law adds the weight's current on its own y axis, which is then not vertical \
             (the wire carries no angle): set controller.gravity_bias = false (ROSS has no bias: the PID's integral \
             carries the weight), or rotor.ross_axes = \"ignore\"",
        ));
    }
    if let Some(deg) = raw.amb.axis_angle_deg {
        return Err(range(
            "amb.axis_angle_deg",
            deg,
            "°",
            "and rotor.ross_axes = \"apply\" both give the planes' axes: remove one",
        ));
    }
    for u in used.iter_mut() {
        let (letter, table) = match u.plane {
            "A" => ("a", &mut raw.amb.a),
            _ => ("b", &mut raw.amb.b),
        };
        let table = table.get_or_insert_with(toml::Table::new);
        if let Some(v) = table.get("axis_angle_deg") {
            return Err(range(
                &format!("amb.{letter}.axis_angle_deg"),
                v,
                "°",
                "and rotor.ross_axes = \"apply\" both give the plane's axes: remove one",
            ));
        }
        let Some(deg) = u.axis_rotation_deg_not_applied.take() else { continue };
        table.insert("axis_angle_deg".into(), toml::Value::Float(deg));
        u.axis_rotation_deg = Some(deg);
    }
    Ok(())
}
