//! Reading a rotor saved by ROSS's `Rotor.save()` (a TOML file; ROSS 3.1's format, checked
//! against ROSS 3.1.0 itself by `scripts/ross/fixture.sh`).
//!
//! The file holds `ross_version`, a `[parameters]` table (`alpha`, `beta`: the rotor's
//! proportional damping; `modal_damping_ratio` when modal damping is set) and one table per
//! element, named `"<Class>_<tag>"`: `ShaftElement` (`L, idl, odl, idr, odr, n, axial_force,
//! torque, shear_effects, rotary_inertia, gyroscopic, shear_method_calc, alpha, beta` and a
//! `.material` sub-table `rho, E, G_s`), `DiskElement` (`n, m, Id, Ip`) and `BearingElement`
//! (`n` and the coefficient lists `kxx, kxy, kyx, kyy, cxx, …, myy`, one value each for
//! constant coefficients). SI throughout.
//!
//! What this model cannot represent is refused, naming the element: other element classes
//! (point masses, seals, magnetic, ball or fluid-film bearings saved as their own class, motors),
//! bearings linked to a support node (`n_link`) or with coefficients that vary with frequency,
//! shaft elements under axial force or torque, two shaft elements at one node (a layered shaft),
//! and modal damping.

use super::rotor::{Disk, LinearBearing, Rotor};
use super::shaft::{Material, ShaftElement, ShearMethod};
use super::FlexError;
use std::path::Path;
use toml::{Table, Value};

/// The ROSS versions (major.minor) whose files this reader takes.
pub const SUPPORTED_VERSIONS: &[&str] = &["3.1"];

/// Reads the ROSS file at `path`.
pub fn read(path: &Path) -> Result<Rotor, FlexError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| FlexError::Ross { file: file.clone(), message: format!("cannot be read: {e}") })?;
    parse(&text, &file)
}

/// Parses the text of a ROSS file (`file` names it in errors).
pub fn parse(text: &str, file: &str) -> Result<Rotor, FlexError> {
    let err = |message: String| FlexError::Ross { file: file.to_string(), message };
    let table: Table = text.parse().map_err(|e| err(format!("is not TOML: {e}")))?;
    let version = match table.get("ross_version") {
        Some(Value::String(v)) => v.clone(),
        Some(other) => return Err(err(format!("ross_version = {other} is not a version string"))),
        None => return Err(err("has no ross_version: not a file saved by ROSS's Rotor.save()".into())),
    };
    let major_minor: String = version.split('.').take(2).collect::<Vec<_>>().join(".");
    if !SUPPORTED_VERSIONS.contains(&major_minor.as_str()) {
        return Err(err(format!(
            "ross_version = \"{version}\": this reader takes files of ROSS {} (save the rotor again with that version)",
            SUPPORTED_VERSIONS.join(", ")
        )));
    }
    let (mut alpha, mut beta) = (0.0, 0.0);
    if let Some(p) = table.get("parameters") {
        let p = p.as_table().ok_or_else(|| err("[parameters] is not a table".into()))?;
        if let Some(v) = p.get("modal_damping_ratio") {
            return Err(err(format!(
                "[parameters] modal_damping_ratio = {v}: ROSS's modal damping is not represented (give the scene's modal damping ratio instead)"
            )));
        }
        alpha = opt_number(p, "alpha", "[parameters]", file)?.unwrap_or(0.0);
        beta = opt_number(p, "beta", "[parameters]", file)?.unwrap_or(0.0);
    }
    let mut shafts: Vec<(usize, String, ShaftElement)> = Vec::new();
    let mut disks: Vec<(String, Disk)> = Vec::new();
    let mut bearings: Vec<(String, LinearBearing)> = Vec::new();
    for (name, value) in &table {
        if name == "ross_version" || name == "parameters" || name.starts_with('_') {
            continue;
        }
        let el = value.as_table().ok_or_else(|| err(format!("\"{name}\" is not a table")))?;
        let class = name.split('_').next().unwrap_or_default();
        let at = format!("element \"{name}\"");
        match class {
            "ShaftElement" => {
                let (n, shaft) = shaft_element(el, &at, file)?;
                shafts.push((n, name.clone(), shaft));
            }
            "DiskElement" => {
                let n = node(el, &at, file)?;
                let disk = Disk {
                    node: n,
                    mass: number(el, "m", &at, file)?,
                    diametral_inertia: number(el, "Id", &at, file)?,
                    polar_inertia: number(el, "Ip", &at, file)?,
                };
                disks.push((at, disk));
            }
            "BearingElement" => {
                bearings.push((at.clone(), bearing(el, &at, file)?));
            }
            other => {
                return Err(err(format!(
                    "{at} is a {other}, which this model cannot represent (it takes ShaftElement, DiskElement and \
                     BearingElement with constant coefficients)"
                )))
            }
        }
    }
    shafts.sort_by_key(|(n, _, _)| *n);
    for (i, (n, name, _)) in shafts.iter().enumerate() {
        if *n != i {
            let message = if i > 0 && shafts[i - 1].0 == *n {
                format!("elements \"{}\" and \"{name}\" both start at node n = {n}: a layered shaft, which this model cannot represent", shafts[i - 1].1)
            } else {
                format!("element \"{name}\": n = {n}, but the shaft elements must be numbered 0, 1, 2, … without gaps (expected {i})")
            };
            return Err(err(message));
        }
    }
    let elements: Vec<ShaftElement> = shafts.into_iter().map(|(_, _, s)| s).collect();
    if elements.is_empty() {
        return Err(err("has no ShaftElement".into()));
    }
    let nodes = elements.len() + 1;
    for (at, n) in disks.iter().map(|(a, d)| (a, d.node)).chain(bearings.iter().map(|(a, b)| (a, b.node))) {
        if n >= nodes {
            return Err(FlexError::NodeOutOfRange { what: format!("{file}: {at}"), node: n, nodes });
        }
    }
    let rotor = Rotor {
        elements,
        disks: disks.into_iter().map(|(_, d)| d).collect(),
        bearings: bearings.into_iter().map(|(_, b)| b).collect(),
        alpha,
        beta,
    };
    rotor.validate().map_err(|e| err(e.to_string()))?;
    Ok(rotor)
}

fn as_number(v: &Value) -> Option<f64> {
    match v {
        Value::Float(f) => Some(*f),
        Value::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

fn opt_number(t: &Table, key: &str, at: &str, file: &str) -> Result<Option<f64>, FlexError> {
    match t.get(key) {
        None => Ok(None),
        Some(v) => as_number(v).map(Some).ok_or_else(|| FlexError::Ross {
            file: file.into(),
            message: format!("{at}: {key} = {v} is not a number"),
        }),
    }
}

fn number(t: &Table, key: &str, at: &str, file: &str) -> Result<f64, FlexError> {
    opt_number(t, key, at, file)?
        .ok_or_else(|| FlexError::Ross { file: file.into(), message: format!("{at}: {key} is missing") })
}

fn node(t: &Table, at: &str, file: &str) -> Result<usize, FlexError> {
    match t.get("n") {
        Some(Value::Integer(n)) if *n >= 0 => Ok(*n as usize),
        Some(v) => Err(FlexError::Ross { file: file.into(), message: format!("{at}: n = {v} is not a node number") }),
        None => Err(FlexError::Ross { file: file.into(), message: format!("{at}: n (its node) is missing") }),
    }
}

fn flag(t: &Table, key: &str, default: bool, at: &str, file: &str) -> Result<bool, FlexError> {
    match t.get(key) {
        None => Ok(default),
        Some(Value::Boolean(b)) => Ok(*b),
        Some(v) => {
            Err(FlexError::Ross { file: file.into(), message: format!("{at}: {key} = {v} is not true or false") })
        }
    }
}

fn shaft_element(t: &Table, at: &str, file: &str) -> Result<(usize, ShaftElement), FlexError> {
    let err = |message: String| FlexError::Ross { file: file.into(), message };
    let n = node(t, at, file)?;
    for key in ["axial_force", "torque"] {
        let v = opt_number(t, key, at, file)?.unwrap_or(0.0);
        if v != 0.0 {
            let unit = if key == "torque" { "N·m" } else { "N" };
            return Err(err(format!(
                "{at}: {key} = {v} {unit}: a preloaded shaft element, which this model cannot represent"
            )));
        }
    }
    let length = number(t, "L", at, file)?;
    let idl = number(t, "idl", at, file)?;
    let odl = number(t, "odl", at, file)?;
    let idr = opt_number(t, "idr", at, file)?.unwrap_or(idl);
    let odr = opt_number(t, "odr", at, file)?.unwrap_or(odl);
    let positive = |key: &'static str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(err(format!("{at}: {key} = {v} m must be positive")))
        }
    };
    positive("L", length)?;
    positive("odl", odl)?;
    positive("odr", odr)?;
    for (key, inner, outer) in [("idl", idl, odl), ("idr", idr, odr)] {
        if !(inner.is_finite() && inner >= 0.0 && inner < outer) {
            return Err(err(format!(
                "{at}: {key} = {inner} m must be at least 0 and below the outer diameter {outer} m"
            )));
        }
    }
    let mat_at = format!("{at}.material");
    let m = t.get("material").and_then(Value::as_table).ok_or_else(|| err(format!("{mat_at} is missing")))?;
    let rho = opt_number(m, "rho", &mat_at, file)?;
    let e = opt_number(m, "E", &mat_at, file)?;
    let g = opt_number(m, "G_s", &mat_at, file)?;
    let nu = opt_number(m, "Poisson", &mat_at, file)?;
    let density = rho.ok_or_else(|| err(format!("{mat_at}: rho (density, kg/m³) is missing")))?;
    let (modulus, shear_modulus) = match (e, g, nu) {
        (Some(e), Some(g), _) => (e, g),
        (Some(e), None, Some(nu)) => (e, e / (2.0 * (1.0 + nu))),
        (None, Some(g), Some(nu)) => (g * 2.0 * (1.0 + nu), g),
        _ => {
            return Err(err(format!(
                "{mat_at}: needs E (modulus, Pa) and G_s (shear modulus, Pa), or one of them with Poisson"
            )))
        }
    };
    for (key, v, unit) in [("rho", density, "kg/m³"), ("E", modulus, "Pa"), ("G_s", shear_modulus, "Pa")] {
        if !(v.is_finite() && v > 0.0) {
            return Err(err(format!("{mat_at}: {key} = {v} {unit} must be positive")));
        }
    }
    let shear_method = match t.get("shear_method_calc") {
        None => ShearMethod::Cowper,
        Some(Value::String(s)) if s == "cowper" => ShearMethod::Cowper,
        Some(Value::String(s)) if s == "hutchinson" => ShearMethod::Hutchinson,
        Some(v) => return Err(err(format!("{at}: shear_method_calc = {v}: takes \"cowper\" or \"hutchinson\""))),
    };
    Ok((
        n,
        ShaftElement {
            length,
            inner_left: idl,
            outer_left: odl,
            inner_right: idr,
            outer_right: odr,
            material: Material { density, modulus, shear_modulus },
            shear_effects: flag(t, "shear_effects", true, at, file)?,
            rotary_inertia: flag(t, "rotary_inertia", true, at, file)?,
            gyroscopic: flag(t, "gyroscopic", true, at, file)?,
            shear_method,
            alpha: opt_number(t, "alpha", at, file)?.unwrap_or(0.0),
            beta: opt_number(t, "beta", at, file)?.unwrap_or(0.0),
        },
    ))
}

fn bearing(t: &Table, at: &str, file: &str) -> Result<LinearBearing, FlexError> {
    let err = |message: String| FlexError::Ross { file: file.into(), message };
    let n = node(t, at, file)?;
    match t.get("n_link") {
        None => {}
        Some(v) => {
            return Err(err(format!(
                "{at}: n_link = {v}: a bearing linked to a support node, which this model cannot represent"
            )))
        }
    }
    // One coefficient: a single value, or a list of equal values (constant over frequency).
    let coefficient = |key: &str, unit: &str| -> Result<f64, FlexError> {
        let values: Vec<f64> = match t.get(key) {
            None => return Ok(0.0),
            Some(Value::Array(a)) => a
                .iter()
                .map(|v| as_number(v).ok_or_else(|| err(format!("{at}: {key} holds {v}, not a number"))))
                .collect::<Result<_, _>>()?,
            Some(v) => vec![as_number(v).ok_or_else(|| err(format!("{at}: {key} = {v} is not a number")))?],
        };
        match values.first() {
            None => Ok(0.0),
            Some(&first) if values.iter().all(|&v| v == first) && first.is_finite() => Ok(first),
            Some(_) => Err(err(format!(
                "{at}: {key} = {values:?} {unit} varies with frequency, which this model cannot represent (it takes constant coefficients)"
            ))),
        }
    };
    let pair = |prefix: &str, unit: &str| -> Result<[[f64; 2]; 2], FlexError> {
        Ok([
            [coefficient(&format!("{prefix}xx"), unit)?, coefficient(&format!("{prefix}xy"), unit)?],
            [coefficient(&format!("{prefix}yx"), unit)?, coefficient(&format!("{prefix}yy"), unit)?],
        ])
    };
    Ok(LinearBearing { node: n, stiffness: pair("k", "N/m")?, damping: pair("c", "N·s/m")?, mass: pair("m", "kg")? })
}
