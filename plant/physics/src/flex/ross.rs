//! Reading a rotor saved by ROSS's `Rotor.save()` (a TOML file; the format of ROSS 2.x and 3.x,
//! checked against ROSS 2.3.0 and 3.1.0 themselves by `scripts/ross/fixture.sh`).
//!
//! **Versions.** A file of ROSS 2.x or 3.x is read when its tables and keys are the ones this
//! reader knows (those ROSS 2.3 and 3.1 write: 3.1 adds `[parameters]` `alpha, beta,
//! default_damping_ratio` and a bearing's `interpolation`, and writes zeros as floats); a key it
//! does not know is refused by its element and name, so that what a version changes is never
//! read silently. Another major version is refused by its number (the format was never checked
//! against it).
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
//! (point masses, seals, ball or fluid-film bearings saved as their own class, motors), ROSS's
//! `MagneticBearingElement` (saved as a `BearingElement` with `g0, i0, ag, nw, …`: its parameters
//! are read and checked, [`super::ross_amb`], and the element is refused with the constants it
//! stands for by ROSS's formulas; the scene's `[amb]` and `[controller]` give the AMBs), bearings linked to a support node
//! (`n_link`) or with coefficients that vary with frequency (a `frequency` list: refused by
//! name rather than evaluated at one speed, since the run's speed changes in a free spin and
//! a fluid-film bearing's coefficients at one speed are not its behaviour under a shock),
//! shaft elements under axial force or torque, two shaft elements at one node (a layered shaft),
//! and modal damping. The axial coefficients `kzz, czz, mzz` are not read (the model is lateral).
//!
//! **The file's bearings and the scene's AMBs** ([`RossFile::bearings_with_ambs`]): a plain
//! bearing at a node the scene gives an AMB is the engineer's model of that AMB (a spring of
//! the closed loop's stiffness, ROSS's usual way); the scene says whether it is dropped for the
//! AMB ([`AtAmbs::Ignore`]) or kept in parallel with it ([`AtAmbs::Parallel`]), and without that
//! choice the file is refused, naming those bearings. Bearings elsewhere (seals, supports) are
//! added to the shaft.

use super::rotor::{Disk, LinearBearing, Rotor};
use super::shaft::{Material, ShaftElement, ShearMethod};
use super::FlexError;
use std::path::Path;
use toml::{Table, Value};

/// The ROSS major versions whose files this reader takes (checked against 2.3.0 and 3.1.0).
pub const SUPPORTED_MAJORS: &[&str] = &["2", "3"];

/// The keys of `[parameters]` this reader knows (`modal_damping_ratio` is known, and refused).
const PARAMETER_KEYS: &[&str] = &["alpha", "beta", "default_damping_ratio", "modal_damping_ratio"];
/// The keys of a `ShaftElement` table (`material` is its sub-table).
const SHAFT_KEYS: &[&str] = &[
    "L",
    "idl",
    "odl",
    "idr",
    "odr",
    "n",
    "axial_force",
    "torque",
    "shear_effects",
    "rotary_inertia",
    "gyroscopic",
    "shear_method_calc",
    "alpha",
    "beta",
    "material",
    "tag",
    "color",
    "scale_factor",
];
/// The keys of a shaft element's `material` table.
const MATERIAL_KEYS: &[&str] = &["name", "rho", "E", "G_s", "Poisson", "color", "tag"];
/// The keys of a `DiskElement` table.
const DISK_KEYS: &[&str] = &["n", "m", "Id", "Ip", "tag", "color", "scale_factor"];
/// The keys of a plain `BearingElement` table (`n_link` and `frequency` are known, and refused
/// with their reasons).
pub(super) const BEARING_KEYS: &[&str] = &[
    "n",
    "n_link",
    "frequency",
    "kxx",
    "kxy",
    "kyx",
    "kyy",
    "kzz",
    "cxx",
    "cxy",
    "cyx",
    "cyy",
    "czz",
    "mxx",
    "mxy",
    "myx",
    "myy",
    "mzz",
    "interpolation",
    "tag",
    "color",
    "scale_factor",
];
/// The parameters ROSS's `MagneticBearingElement` saves in its `BearingElement` table (2.3 has
/// all but `sensor_node`).
pub(super) const MAGNETIC_KEYS: &[&str] = &[
    "g0",
    "i0",
    "ag",
    "nw",
    "alpha",
    "k_amp",
    "k_sense",
    "kp_pid",
    "kd_pid",
    "ki_pid",
    "n_f",
    "sensors_axis_rotation",
    "sensor_node",
];

/// A plain bearing of the file: its element's table name and its coefficients.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FileBearing {
    /// The element, as the file names its table (`"BearingElement_<tag>"`).
    pub element: String,
    /// Its coefficients at its node.
    pub bearing: LinearBearing,
}

/// A ROSS file as read: the shaft and disks, and the file's plain bearings apart (what is done
/// with them depends on where the scene puts its AMBs: [`RossFile::bearings_with_ambs`]).
#[derive(Clone, Debug, PartialEq)]
pub struct RossFile {
    /// `ross_version` as the file writes it.
    pub version: String,
    /// The rotor without the file's bearings.
    pub rotor: Rotor,
    /// The file's plain bearings, in the file's order.
    pub bearings: Vec<FileBearing>,
    /// The file's `MagneticBearingElement`s, checked, in the file's order (empty from
    /// [`parse_file`], which refuses them; [`parse_file_with_ambs`] keeps them).
    pub magnetics: Vec<super::ross_amb::MagneticBearing>,
}

/// What the scene does with the file's plain bearings at the AMB nodes (`rotor.ross_bearings`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AtAmbs {
    /// They were the engineer's model of the AMBs: the scene's AMBs replace them.
    Ignore,
    /// They are kept as springs in parallel with the scene's AMBs.
    Parallel,
}

/// What the scene does with the file's `MagneticBearingElement`s (`rotor.ross_ambs`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RossAmbs {
    /// Refused with the constants each stands for (the default, as when the key is absent).
    Refuse,
    /// Each becomes its plane's AMB: its constants, gains and sensor node, and its PID as the
    /// plane's law (`ross_pid`).
    Use,
    /// Each becomes its plane's AMB (constants, gains, sensor node); the scene's `[controller]`
    /// gives the law.
    Constants,
}

/// What became of one of the file's bearings.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BearingUse {
    /// Away from the AMBs: added to the shaft.
    Added,
    /// At an AMB node, dropped for the AMB (`rotor.ross_bearings = "ignore"`).
    Ignored,
    /// At an AMB node, kept beside the AMB (`rotor.ross_bearings = "parallel"`).
    Parallel,
}

/// One of the file's bearings and what became of it (the run's record, `summary.json`).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct UsedBearing {
    /// The element, as the file names its table.
    pub element: String,
    /// Its node.
    pub node: usize,
    /// Stiffness `[[k_xx, k_xy], [k_yx, k_yy]]` (N/m).
    pub stiffness_n_per_m: [[f64; 2]; 2],
    /// Damping `[[c_xx, c_xy], [c_yx, c_yy]]` (N·s/m).
    pub damping_n_s_per_m: [[f64; 2]; 2],
    /// What the run does with it.
    #[serde(rename = "use")]
    pub used: BearingUse,
}

impl FileBearing {
    /// `"<element>" at node n (k_xx = …, k_yy = … N/m)`, for messages.
    pub fn describe(&self) -> String {
        let k = self.bearing.stiffness;
        let mut s = format!(
            "\"{}\" at node {} (k_xx = {:e} N/m, k_yy = {:e} N/m",
            self.element, self.bearing.node, k[0][0], k[1][1]
        );
        if k[0][1] != 0.0 || k[1][0] != 0.0 {
            s += &format!(", k_xy = {:e} N/m, k_yx = {:e} N/m", k[0][1], k[1][0]);
        }
        s + ")"
    }
}

impl RossFile {
    /// The rotor with the file's bearings as the scene's AMBs at `amb_nodes` and its choice
    /// `choice` (`rotor.ross_bearings`) have them, and what became of each. Bearings at an AMB
    /// node with no choice: the error names them and lists the choices (the message is the
    /// `Err`'s text, for the caller to put under its key).
    pub fn bearings_with_ambs(
        &self,
        amb_nodes: [usize; 2],
        choice: Option<AtAmbs>,
    ) -> Result<(Rotor, Vec<UsedBearing>), String> {
        let at_amb: Vec<&FileBearing> = self.bearings.iter().filter(|b| amb_nodes.contains(&b.bearing.node)).collect();
        if !at_amb.is_empty() && choice.is_none() {
            let named: Vec<String> = at_amb.iter().map(|b| b.describe()).collect();
            return Err(format!(
                "the file has plain bearings at the AMB nodes {} and {}: {}. They are the engineer's model of the \
                 AMBs and would count the AMBs twice: say what to do with them, rotor.ross_bearings = \"ignore\" \
                 (the scene's AMBs replace them) or \"parallel\" (kept as springs beside the AMBs)",
                amb_nodes[0],
                amb_nodes[1],
                named.join(", ")
            ));
        }
        let mut rotor = self.rotor.clone();
        let mut used = Vec::with_capacity(self.bearings.len());
        for b in &self.bearings {
            let how = match (amb_nodes.contains(&b.bearing.node), choice) {
                (false, _) => BearingUse::Added,
                (true, Some(AtAmbs::Parallel)) => BearingUse::Parallel,
                (true, _) => BearingUse::Ignored,
            };
            if how != BearingUse::Ignored {
                rotor.bearings.push(b.bearing);
            }
            used.push(UsedBearing {
                element: b.element.clone(),
                node: b.bearing.node,
                stiffness_n_per_m: b.bearing.stiffness,
                damping_n_s_per_m: b.bearing.damping,
                used: how,
            });
        }
        Ok((rotor, used))
    }
}

/// Reads the ROSS file at `path`, every bearing of it kept (as ROSS has the rotor).
pub fn read(path: &Path) -> Result<Rotor, FlexError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| FlexError::Ross { file: file.clone(), message: format!("cannot be read: {e}") })?;
    parse(&text, &file)
}

/// Parses the text of a ROSS file (`file` names it in errors), every bearing of it kept (as
/// ROSS has the rotor).
pub fn parse(text: &str, file: &str) -> Result<Rotor, FlexError> {
    let f = parse_file(text, file)?;
    let mut rotor = f.rotor;
    rotor.bearings = f.bearings.into_iter().map(|b| b.bearing).collect();
    rotor.validate().map_err(|e| FlexError::Ross { file: file.to_string(), message: e.to_string() })?;
    Ok(rotor)
}

/// The key of `table` (of `at`) that this reader does not know, refused by name.
pub(super) fn unknown_key(table: &Table, known: &[&str], at: &str, file: &str) -> Result<(), FlexError> {
    match table.keys().find(|k| !known.contains(&k.as_str())) {
        None => Ok(()),
        Some(k) => Err(FlexError::Ross {
            file: file.to_string(),
            message: format!(
                "{at}: key \"{k}\" = {} is not one this reader knows (it reads the keys ROSS 2.3 and 3.1 write: {})",
                short(&table[k]),
                known.join(", ")
            ),
        }),
    }
}

/// A value as a message shows it: a long list by its length, first and last values.
fn short(v: &Value) -> String {
    match v {
        Value::Array(a) if a.len() > 4 => {
            format!("[{}, …, {}] ({} values)", a[0], a[a.len() - 1], a.len())
        }
        v => v.to_string(),
    }
}

/// Parses the text of a ROSS file (`file` names it in errors): the shaft and disks, and the
/// plain bearings apart. A `MagneticBearingElement` is refused with the constants it stands for
/// ([`super::ross_amb::MagneticBearing::refusal`]); [`parse_file_with_ambs`] keeps them.
pub fn parse_file(text: &str, file: &str) -> Result<RossFile, FlexError> {
    let read = parse_file_with_ambs(text, file)?;
    match read.magnetics.first() {
        Some(m) => Err(FlexError::Ross { file: file.to_string(), message: m.refusal() }),
        None => Ok(read),
    }
}

/// [`parse_file`] with the file's `MagneticBearingElement`s read, checked (their nodes and
/// sensor nodes on the shaft) and kept in [`RossFile::magnetics`], for the scene to make them
/// its AMBs (`rotor.ross_ambs`).
pub fn parse_file_with_ambs(text: &str, file: &str) -> Result<RossFile, FlexError> {
    let err = |message: String| FlexError::Ross { file: file.to_string(), message };
    let table: Table = text.parse().map_err(|e| err(format!("is not TOML: {e}")))?;
    let version = match table.get("ross_version") {
        Some(Value::String(v)) => v.clone(),
        Some(other) => return Err(err(format!("ross_version = {other} is not a version string"))),
        None => return Err(err("has no ross_version: not a file saved by ROSS's Rotor.save()".into())),
    };
    let major = version.split('.').next().unwrap_or_default();
    if !SUPPORTED_MAJORS.contains(&major) {
        return Err(err(format!(
            "ross_version = \"{version}\": this reader takes files of ROSS 2.x and 3.x (checked against 2.3 and 3.1; save \
             the rotor again with one of them)"
        )));
    }
    let (mut alpha, mut beta) = (0.0, 0.0);
    if let Some(p) = table.get("parameters") {
        let p = p.as_table().ok_or_else(|| err("[parameters] is not a table".into()))?;
        unknown_key(p, PARAMETER_KEYS, "[parameters]", file)?;
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
    let mut magnetics: Vec<super::ross_amb::MagneticBearing> = Vec::new();
    for (name, value) in &table {
        if name == "ross_version" || name == "parameters" || name.starts_with('_') {
            continue;
        }
        let el = value.as_table().ok_or_else(|| err(format!("\"{name}\" is not a table")))?;
        let class = name.split('_').next().unwrap_or_default();
        let at = format!("element \"{name}\"");
        match class {
            "ShaftElement" => {
                unknown_key(el, SHAFT_KEYS, &at, file)?;
                let (n, shaft) = shaft_element(el, &at, file)?;
                shafts.push((n, name.clone(), shaft));
            }
            "DiskElement" => {
                unknown_key(el, DISK_KEYS, &at, file)?;
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
                if MAGNETIC_KEYS.iter().any(|k| el.contains_key(*k) && *k != "alpha") {
                    // ROSS's AMB element, saved as a BearingElement with its parameters (its
                    // frequency-dependent equivalent coefficients beside them): its parameters
                    // checked here, the element refused once the nodes are known.
                    magnetics.push(super::ross_amb::magnetic(el, name, &at, file)?);
                    continue;
                }
                unknown_key(el, BEARING_KEYS, &at, file)?;
                bearings.push((name.clone(), bearing(el, &at, file)?));
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
    let bearing_at: Vec<(String, usize)> = bearings.iter().map(|(a, b)| (format!("element \"{a}\""), b.node)).collect();
    for (at, n) in disks.iter().map(|(a, d)| (a.clone(), d.node)).chain(bearing_at) {
        if n >= nodes {
            return Err(FlexError::NodeOutOfRange { what: format!("{file}: {at}"), node: n, nodes });
        }
    }
    for m in &magnetics {
        for (key, n) in [("n", m.node), ("sensor_node", m.sensor_node)] {
            if n >= nodes {
                return Err(FlexError::NodeOutOfRange {
                    what: format!("{file}: element \"{}\" {key}", m.element),
                    node: n,
                    nodes,
                });
            }
        }
    }
    let rotor =
        Rotor { elements, disks: disks.into_iter().map(|(_, d)| d).collect(), bearings: Vec::new(), alpha, beta };
    rotor.validate().map_err(|e| err(e.to_string()))?;
    let bearings = bearings.into_iter().map(|(element, bearing)| FileBearing { element, bearing }).collect();
    Ok(RossFile { version, rotor, bearings, magnetics })
}

pub(super) fn as_number(v: &Value) -> Option<f64> {
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

pub(super) fn node(t: &Table, at: &str, file: &str) -> Result<usize, FlexError> {
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
    unknown_key(m, MATERIAL_KEYS, &mat_at, file)?;
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
    if let Some(f) = t.get("frequency").filter(|f| !matches!(f, Value::Array(a) if a.len() <= 1)) {
        return Err(err(format!(
            "{at} (node {n}): frequency = {}: its coefficients vary with frequency, which this model cannot \
             represent (it takes constant coefficients; it does not evaluate them at one speed)",
            short(f)
        )));
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
        if let Some(bad) = values.iter().find(|v| !v.is_finite()) {
            return Err(err(format!(
                "{at} (node {n}): {key} = {} {unit}: {bad} is not a finite coefficient",
                short(&t[key])
            )));
        }
        match values.first() {
            None => Ok(0.0),
            Some(&first) if values.iter().all(|&v| v == first) => Ok(first),
            Some(_) => Err(err(format!(
                "{at} (node {n}): {key} = {} {unit} varies with frequency, which this model cannot represent (it takes \
                 constant coefficients; it does not evaluate them at one speed)",
                short(&t[key])
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
