//! `rotor.ross_ambs`: a ROSS file's `MagneticBearingElement`s made the planes' AMBs (MODEL.md
//! §13.8, issue 38 item 1). Before the scene is validated, each element's constants (`k_i`,
//! `k_s` by ROSS's formulas, `k_amp`, `k_sense`, `g0`) are written into its plane's `[amb.a]` or
//! `[amb.b]`, its nodes into `rotor.amb_*_node` and `rotor.sensor_*_node`, and with `"use"` its
//! PID into `controller.law = "ross_pid"` and `controller.params`: the rest of the validation
//! (and the resolved `scene.toml`) sees them as if the scene had written them.

use super::*;
use crate::config::models::flexible::ross_ambs_name as name;
use plant_physics::flex::ross::{self, RossAmbs};
use plant_physics::flex::ross_amb::{MagneticBearing, UsedAmb};

/// The file's AMB elements written into `raw` as `rotor.ross_ambs` says, and what each plane
/// took (empty without the key, with `"refuse"`, or in a scene that is not flexible: those are
/// refused or left as they were by the rotor's own validation).
pub(super) fn apply(raw: &mut RawScene, base_dir: &Path) -> Result<Vec<UsedAmb>, ConfigError> {
    let Some(r) = raw.rotor.flexible() else { return Ok(Vec::new()) };
    let Some(choice) = r.ross_ambs else { return Ok(Vec::new()) };
    if choice == RossAmbs::Refuse {
        return Ok(Vec::new());
    }
    let (file, elements) = elements_of(raw, base_dir, choice)?;
    let planes = planes_of(raw, &elements, &file, choice)?;
    if choice == RossAmbs::Use {
        check_use(raw, &planes, &file)?;
    }
    let used = write_planes(raw, &planes, &file, choice)?;
    if choice == RossAmbs::Use {
        write_pid(raw, &used)?;
    }
    Ok(used)
}

/// The file of `rotor.ross_file` read, its `MagneticBearingElement`s sorted by node: refused
/// without a file or without an element.
fn elements_of(
    raw: &RawScene,
    base_dir: &Path,
    choice: RossAmbs,
) -> Result<(String, Vec<MagneticBearing>), ConfigError> {
    let key = "rotor.ross_ambs";
    let Some(file) = raw.rotor.flexible().and_then(|r| r.ross_file.clone()) else {
        return Err(range(
            key,
            name(choice),
            "",
            "says what to do with a ROSS file's MagneticBearingElements, and this scene has no rotor.ross_file: \
             remove it",
        ));
    };
    let path = base_dir.join(&file);
    let text = shock_table::input::read_text(&path, shock_table::input::MAX_TOML_BYTES)
        .map_err(|e| range("rotor.ross_file", &file, "", &format!("cannot read {}: {e}", path.display())))?;
    let read = ross::parse_file_with_ambs(&text, &file).map_err(|e| ConfigError::Range {
        key: "rotor.ross_file".into(),
        value: file.clone(),
        unit: String::new(),
        why: e.to_string(),
    })?;
    let mut elements = read.magnetics;
    if elements.is_empty() {
        return Err(range(
            key,
            name(choice),
            "",
            &format!("rotor.ross_file = {file} has no MagneticBearingElement: remove the key"),
        ));
    }
    elements.sort_by_key(|m| m.node);
    Ok((file, elements))
}

/// Each plane's element: at the scene's AMB node, or (with two elements in the file and no node
/// given) the file's, A the lower node; refused where an element is at neither plane.
fn planes_of<'a>(
    raw: &RawScene,
    elements: &'a [MagneticBearing],
    file: &str,
    choice: RossAmbs,
) -> Result<[Option<&'a MagneticBearing>; 2], ConfigError> {
    let key = "rotor.ross_ambs";
    // `apply` runs on a flexible rotor only.
    let scene_nodes = raw.rotor.flexible().map_or([None, None], |r| [r.amb_a_node, r.amb_b_node]);
    let mut planes: [Option<&MagneticBearing>; 2] = [None, None];
    for i in 0..2 {
        planes[i] = match scene_nodes[i] {
            Some(n) => elements.iter().find(|m| m.node == n),
            None if elements.len() == 2 => Some(&elements[i]),
            None => {
                return Err(range(
                    ["rotor.amb_a_node", "rotor.amb_b_node"][i],
                    "none",
                    "",
                    &format!(
                        "rotor.ross_file = {file} has {} MagneticBearingElement(s), not two: give each plane's AMB \
                         node",
                        elements.len()
                    ),
                ))
            }
        };
    }
    let at_planes: Vec<usize> = planes.iter().flatten().map(|m| m.node).collect();
    if let Some(m) = elements.iter().find(|m| !at_planes.contains(&m.node)) {
        return Err(range(
            key,
            name(choice),
            "",
            &format!(
                "rotor.ross_file = {file}: element \"{}\" (node {}) is at none of the AMB nodes (rotor.amb_a_node, \
                 rotor.amb_b_node): this model has one AMB per plane, and would drop it",
                m.element, m.node
            ),
        ));
    }
    Ok(planes)
}

/// With `"use"`: refused where the file's PID cannot be the law (a plane without an element,
/// two PIDs, the continuous mode, another law).
fn check_use(raw: &RawScene, planes: &[Option<&MagneticBearing>; 2], file: &str) -> Result<(), ConfigError> {
    let key = "rotor.ross_ambs";
    if let Some(i) = planes.iter().position(Option::is_none) {
        return Err(range(
            key,
            "\"use\"",
            "",
            &format!(
                "makes the file's PID each plane's law, and plane {} has no MagneticBearingElement in \
                 rotor.ross_file = {file}: rotor.ross_ambs = \"constants\" takes the file's AMB constants with \
                 the scene's [controller]",
                ["A", "B"][i]
            ),
        ));
    }
    let (a, b) = (planes[0].map(|m| m.ross_pid()), planes[1].map(|m| m.ross_pid()));
    if a != b {
        return Err(range(
            key,
            "\"use\"",
            "",
            &format!(
                "rotor.ross_file = {file}: the two MagneticBearingElements' PIDs differ ({a:?} and {b:?}), and \
                 law ross_pid takes one set of gains for both planes: rotor.ross_ambs = \"constants\" with a \
                 [controller] of your own"
            ),
        ));
    }
    if raw.controller.mode == ControlMode::Continuous {
        return Err(range(
            "controller.mode",
            "\"continuous\"",
            "",
            "runs the plant's continuous PD, and rotor.ross_ambs = \"use\" makes the file's PID the law \
             (ross_pid, sampled as ROSS samples it). It cannot run continuously: the continuous mode's law is \
             a PD evaluated inside the derivative on the sensor's reading and its rate, with no state of its \
             own, and ROSS's PID has two per axis (its integral, and its derivative's filter at n_f) that the \
             continuous model's state does not carry. Set controller.mode = \"sampled\" (or lockstep, \
             realtime), or rotor.ross_ambs = \"constants\" for the continuous PD on the file's AMB constants",
        ));
    }
    let law = raw.controller.law.as_str();
    if law != "pd" && law != controller::ross_pid::LAW.name {
        return Err(range(
            "controller.law",
            format!("\"{law}\""),
            "",
            "rotor.ross_ambs = \"use\" makes the file's PID the law (ross_pid): remove controller.law, or \
             rotor.ross_ambs = \"constants\" to run this law on the file's AMB constants",
        ));
    }
    Ok(())
}

/// Each plane's element written into the scene: its nodes into `rotor.amb_*_node` and
/// `rotor.sensor_*_node`, its constants into `[amb.a]` / `[amb.b]`; what each plane took.
fn write_planes(
    raw: &mut RawScene,
    planes: &[Option<&MagneticBearing>; 2],
    file: &str,
    choice: RossAmbs,
) -> Result<Vec<UsedAmb>, ConfigError> {
    let mut used = Vec::new();
    for (i, m) in planes.iter().enumerate() {
        let Some(m) = m else { continue };
        let letter = ["a", "b"][i];
        let Some(r) = raw.rotor.flexible_mut() else { continue };
        let sensor = [&mut r.sensor_a_node, &mut r.sensor_b_node];
        match *sensor[i] {
            Some(s) if s != m.sensor_node => {
                return Err(range(
                    &format!("rotor.sensor_{letter}_node"),
                    s,
                    "",
                    &format!(
                        "rotor.ross_file = {file}: element \"{}\" has its sensor at node {} (sensor_node), and \
                         rotor.ross_ambs takes it: remove the key",
                        m.element, m.sensor_node
                    ),
                ))
            }
            _ => *sensor[i] = Some(m.sensor_node),
        }
        *[&mut r.amb_a_node, &mut r.amb_b_node][i] = Some(m.node);
        let u = m.used(["A", "B"][i], choice == RossAmbs::Use);
        let table = [&mut raw.amb.a, &mut raw.amb.b][i].get_or_insert_with(toml::Table::new);
        for (k, v) in [
            ("ki_n_per_a", u.ki_n_per_a),
            ("ks_n_per_m", u.ks_n_per_m),
            ("amp_gain_a_per_v", u.amp_gain_a_per_v),
            ("sensor_gain_v_per_m", u.sensor_gain_v_per_m),
            ("nominal_gap_mm", u.nominal_gap_mm),
        ] {
            table.insert(k.into(), toml::Value::Float(v));
        }
        used.push(u);
    }
    Ok(used)
}

/// With `"use"`: the file's PID as law `ross_pid` and its `controller.params`.
fn write_pid(raw: &mut RawScene, used: &[UsedAmb]) -> Result<(), ConfigError> {
    let pid = used[0].pid.expect("\"use\" records the PID");
    let mut params = toml::Table::new();
    for (k, v) in [("kp", pid.kp), ("ki_per_s", pid.ki_per_s), ("kd_s", pid.kd_s), ("n_f_rad_s", pid.n_f_rad_s)] {
        params.insert(k.into(), toml::Value::Float(v));
    }
    if !raw.controller.params.is_empty() && raw.controller.params != params {
        return Err(range(
            "controller.params",
            "a table",
            "",
            "rotor.ross_ambs = \"use\" gives law ross_pid the file's PID: remove controller.params, or \
             rotor.ross_ambs = \"constants\" with a [controller] of your own",
        ));
    }
    raw.controller.law = controller::ross_pid::LAW.name.into();
    raw.controller.params = params;
    Ok(())
}

/// The line the run starts with when the file's AMB elements are the planes' AMBs.
pub(super) fn note(raw: &RawScene, used: &[UsedAmb]) -> Option<String> {
    if used.is_empty() {
        return None;
    }
    let file = raw.rotor.flexible().and_then(|r| r.ross_file.as_deref()).unwrap_or("the ROSS file");
    let planes: Vec<String> = used
        .iter()
        .map(|u| {
            let law = match u.pid {
                Some(p) => format!(
                    ", law ross_pid kp = {}, ki = {} 1/s, kd = {} s, n_f = {} rad/s",
                    p.kp, p.ki_per_s, p.kd_s, p.n_f_rad_s
                ),
                None => String::new(),
            };
            format!(
                "plane {} from \"{}\" (node {}, sensor node {}: k_i = {:.6e} N/A, k_s = {:.6e} N/m, A_a = {} A/V, A_s = \
                 {} V/m{law})",
                u.plane, u.element, u.node, u.sensor_node, u.ki_n_per_a, u.ks_n_per_m, u.amp_gain_a_per_v,
                u.sensor_gain_v_per_m
            )
        })
        .collect();
    let from = if used.len() == 2 { "both planes'" } else { "that plane's" };
    let list = |f: fn(&UsedAmb) -> Option<f64>| {
        let all: Vec<String> = used.iter().filter_map(|u| f(u).map(|d| format!("{d:.1}°"))).collect();
        (!all.is_empty()).then(|| all.join(", "))
    };
    let axes = match (list(|u| u.axis_rotation_deg_not_applied), list(|u| u.axis_rotation_deg)) {
        (Some(not), _) => format!("their sensor axes turned by {not} are not applied (the plant's axes are at 0°)"),
        (None, Some(applied)) => {
            format!("their axes turned by {applied} are the planes' (rotor.ross_axes = \"apply\": amb.axis_angle_deg)")
        }
        (None, None) => String::new(),
    };
    Some(format!(
        "rotor.ross_file = {file}: the file's MagneticBearingElements are the AMBs (rotor.ross_ambs): {}; they \
         replace {from} [amb] constants; {axes} (summary.json model.ross_ambs)",
        planes.join("; ")
    ))
}
