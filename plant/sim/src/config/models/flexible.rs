//! The flexible shaft on two bearing planes (`rotor.model = "flexible"`): its `[rotor]` keys and
//! their defaults, and what the model says of itself.

use super::{Build, BuildContext, RawRotor, RotorKeys, RotorModel, RotorParams, Share, TwoPlaneKeys};
use crate::config::checks::{non_negative, positive, range};
use crate::config::scene_table::scene_table;
use crate::config::ConfigError;
use crate::machine::mechanics::{Mechanics, Signal};
use crate::machine::{mid_span_weight, FlexibleLinear, Linearised};
use crate::model::Params;
use plant_physics::flex::linear::OpenLoop;
use plant_physics::flex::machine as flexible;
use plant_physics::flex::ross::UsedBearing;
use plant_physics::flex::ross_amb::UsedAmb;
use plant_physics::flex::{self, machine, Reduction};
use plant_physics::two_plane;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::sync::Arc;

/// Cutoff when none is given (Hz).
const CUTOFF_HZ: f64 = 2000.0;
/// Modal damping ratio when none is given.
const MODAL_DAMPING: f64 = 0.005;

/// `rotor.ross_axes`: what the scene does with the ROSS file's AMB axis rotation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RossAxes {
    /// Each element's `sensors_axis_rotation` turns its plane's axes (`amb.axis_angle_deg`).
    Apply,
    /// The plant's axes stay at 0° (the default).
    Ignore,
}

scene_table! {
/// `[rotor]`'s own keys of the flexible rotor, each `None` unless given. Its mass, inertias and
/// geometry are its shaft's: the shared `mass_kg` and `polar_inertia_kg_m2` are replaced by them.
pub struct FlexibleKeys {
    /// The shaft as a table of elements, materials and disks (`[rotor.shaft]`,
    /// `plant_physics::flex::table`); this or `ross_file`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shaft: Option<plant_physics::flex::table::ShaftTable> = None,
    /// A rotor saved by ROSS's `Rotor.save()` (path from the scene's folder); this or `shaft`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ross_file: Option<String> = None,
    /// With `ross_file`: what to do with the file's plain bearings at the AMB nodes (the
    /// engineer's model of the AMBs): `ignore` (the scene's AMBs replace them) or `parallel`
    /// (kept as springs beside the AMBs); none: such a file is refused.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ross_bearings: Option<plant_physics::flex::ross::AtAmbs> = None,
    /// With `ross_file`: what to do with the file's `MagneticBearingElement`s: `use` (each its
    /// plane's AMB, its PID the law `ross_pid`), `constants` (each its plane's AMB, the scene's
    /// `[controller]` the law) or `refuse`; none: such a file is refused with the constants each
    /// element stands for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ross_ambs: Option<plant_physics::flex::ross::RossAmbs> = None,
    /// With `ross_ambs`: what to do with each `MagneticBearingElement`'s
    /// `sensors_axis_rotation`: `apply` (its plane's `amb.axis_angle_deg`) or `ignore` (the
    /// plant's axes at 0°, as without the key).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ross_axes: Option<RossAxes> = None,
    /// The node of AMB A (on the −z side of the centre of mass).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub amb_a_node: Option<usize> = None,
    /// The node of AMB B (on the +z side of the centre of mass).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub amb_b_node: Option<usize> = None,
    /// The node of plane A's displacement sensor; none: `amb_a_node` (collocated).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sensor_a_node: Option<usize> = None,
    /// The node of plane B's displacement sensor; none: `amb_b_node`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sensor_b_node: Option<usize> = None,
    /// The node of touchdown bearing A; none: `amb_a_node`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub touchdown_a_node: Option<usize> = None,
    /// The node of touchdown bearing B; none: `amb_b_node`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub touchdown_b_node: Option<usize> = None,
    /// Keep the shaft's modes below this frequency (Hz); none: 2000.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cutoff_hz: Option<f64> = None,
    /// Modal damping ratio ζ of every bending mode; none: 0.005.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub modal_damping: Option<f64> = None,
}
}

impl RawRotor {
    /// The flexible rotor's own keys, if the scene's rotor is flexible (a ROSS file's AMBs and axes
    /// are written into them before validation, `validate/ross_ambs.rs`).
    pub fn flexible(&self) -> Option<&FlexibleKeys> {
        match &self.model {
            RotorKeys::Flexible(keys) => Some(keys),
            _ => None,
        }
    }

    /// The same, mutable.
    pub fn flexible_mut(&mut self) -> Option<&mut FlexibleKeys> {
        match &mut self.model {
            RotorKeys::Flexible(keys) => Some(keys),
            _ => None,
        }
    }
}

impl RotorParams for flexible::Params {
    fn model(&self) -> RotorModel {
        RotorModel::Flexible
    }

    fn planes(&self) -> usize {
        self.machine.planes.len()
    }

    /// The reduced shaft's [`OpenLoop::state_space`]: its retained modes, damping and
    /// gyroscopics at the speed.
    fn mechanics(&self, omega: f64) -> Mechanics {
        let ss = OpenLoop::of(self).state_space(omega);
        let r = ss.a.nrows() / 2;
        let states = (1..=r)
            .map(|k| Signal::new(format!("eta_{k}"), "m*kg^0.5", format!("reduced coordinate {k} (mass-normalised)")))
            .chain(
                (1..=r).map(|k| {
                    Signal::new(format!("etadot_{k}"), "m*kg^0.5/s", format!("rate of reduced coordinate {k}"))
                }),
            )
            .collect();
        let what = format!(
            "flexible shaft reduced to {} coordinates (its retained modes and static corrections), damping and \
             gyroscopics at the speed, each plane's AMB k_s and k_i at its node, the sensors at theirs",
            self.reduced.size()
        );
        Mechanics { a: ss.a, b: ss.b, sensor: ss.c, actuator: ss.actuator, states, what }
    }

    fn plane(&self, i: usize) -> &Params {
        &self.machine.planes[i].params
    }

    fn plane_mut(&mut self, i: usize) -> &mut Params {
        &mut self.machine.planes[i].params
    }

    fn record_defaults(&self, rotor: &mut RawRotor) {
        record_flexible(rotor, self);
    }

    /// The rigid body of the shaft, its AMBs and sensors at their nodes.
    fn rigid_body(&self) -> Option<&two_plane::Params> {
        Some(&self.machine)
    }

    fn non_collocated_plane(&self) -> Option<usize> {
        self.nodes.iter().position(|n| n.sensor != n.amb)
    }

    fn mid_span_weight(&self) -> Option<f64> {
        Some(mid_span_weight(self))
    }

    fn linearised(&self, gains: &[controller::PdGains]) -> Option<Box<dyn Linearised>> {
        Some(Box::new(FlexibleLinear::new(self, gains)))
    }

    fn file_bearings(&self) -> &[UsedBearing] {
        &self.file_bearings
    }

    fn file_ambs(&self) -> &[UsedAmb] {
        &self.file_ambs
    }

    fn open_loop(&self) -> Option<OpenLoop> {
        Some(OpenLoop::of(self))
    }
}

/// Writes the flexible rotor's defaults into `[rotor]`, and the mass and polar inertia its shaft
/// has (what the scene's `mass_kg` and `polar_inertia_kg_m2` are replaced by), so that the
/// resolved `scene.toml` states them.
fn record_flexible(rotor: &mut RawRotor, params: &flexible::Params) {
    rotor.mass_kg = params.machine.rotor.mass;
    rotor.polar_inertia_kg_m2 = params.machine.rotor.polar_inertia;
    let Some(r) = rotor.flexible_mut() else { return };
    r.sensor_a_node.get_or_insert(params.nodes[0].sensor);
    r.sensor_b_node.get_or_insert(params.nodes[1].sensor);
    r.touchdown_a_node.get_or_insert(params.nodes[0].touchdown);
    r.touchdown_b_node.get_or_insert(params.nodes[1].touchdown);
    r.cutoff_hz.get_or_insert(CUTOFF_HZ);
    r.modal_damping.get_or_insert(MODAL_DAMPING);
}

/// Reduced coordinates the flexible state has room for.
const MAX_BASIS: usize = machine::MAX_MODES;

impl Build for FlexibleKeys {
    type Params = machine::Params;

    fn build(&self, ctx: &dyn BuildContext) -> Result<machine::Params, ConfigError> {
        flexible_params(ctx, self, ctx.whole(), ctx.base_dir())
    }
}

fn flex_error(key: &str, value: &str, e: flex::FlexError) -> ConfigError {
    ConfigError::Range { key: key.to_string(), value: value.to_string(), unit: String::new(), why: e.to_string() }
}

/// The flexible machine of a scene, validated.
fn flexible_params(
    ctx: &dyn BuildContext,
    r: &FlexibleKeys,
    whole: &Share,
    base_dir: &Path,
) -> Result<machine::Params, ConfigError> {
    let (shaft, file) = shaft_of(r, base_dir)?;
    shaft.validate().map_err(|e| flex_error("rotor.shaft", "the shaft", e))?;
    let nodes = shaft.node_count();
    let (amb, sensor, touchdown) = nodes_of(r, nodes)?;
    let body = shaft.rigid_body();
    let z: Vec<f64> = shaft.node_positions().iter().map(|p| p - body.centre).collect();
    const SIDES: &str = "AMB A lies on the −z side of the rotor's centre of mass and AMB B on the +z side: the \
                         centre of mass is between the AMBs";
    if z[amb[0]] >= 0.0 {
        return Err(range(
            "rotor.amb_a_node",
            amb[0],
            "",
            &format!("is {:.1} mm from the centre of mass: {SIDES}", z[amb[0]] * 1e3),
        ));
    }
    if z[amb[1]] <= 0.0 {
        return Err(range(
            "rotor.amb_b_node",
            amb[1],
            "",
            &format!("is {:.1} mm from the centre of mass: {SIDES}", z[amb[1]] * 1e3),
        ));
    }
    let (shaft, file_bearings) = match file {
        None => (shaft, Vec::new()),
        Some((name, read)) => {
            let (rotor, used) = read
                .bearings_with_ambs(amb, r.ross_bearings)
                .map_err(|why| range("rotor.ross_bearings", "none", "", &format!("rotor.ross_file = {name}: {why}")))?;
            rotor.validate().map_err(|e| flex_error("rotor.ross_file", name, e))?;
            (rotor, used)
        }
    };
    let reduced = reduce(r, &shaft, amb, touchdown)?;
    // The rigid two-plane rotor with the shaft's mass and inertia, its bearings at the AMB nodes
    // and its sensors at the sensor nodes: each plane's bearing (load share, design) as there.
    let mm = |n: usize| Some(z[n] * 1e3);
    let as_rigid = TwoPlaneKeys {
        transverse_inertia_kg_m2: Some(body.transverse_inertia),
        bearing_a_mm: mm(amb[0]),
        bearing_b_mm: mm(amb[1]),
        sensor_a_mm: mm(sensor[0]),
        sensor_b_mm: mm(sensor[1]),
        end_a_mm: Some(z[0] * 1e3),
        end_b_mm: Some(z[nodes - 1] * 1e3),
        ..TwoPlaneKeys::default()
    };
    let share = Share { mass: body.mass, inertia: body.polar_inertia, ..*whole };
    let machine = super::two_plane::two_plane_params(ctx, &as_rigid, &share)?;
    let nodes = [0, 1].map(|i| machine::PlaneNodes { amb: amb[i], sensor: sensor[i], touchdown: touchdown[i] });
    // The rates' matrix at the rated speed, formed once: a held spin stays there (a free one
    // forms its terms at each evaluation, as before; the result is the same to the bit).
    let reduced = reduced.hold_speed(machine.rotor.speed);
    Ok(machine::Params {
        machine,
        nodes,
        reduced: Arc::new(reduced),
        shaft: Arc::new(shaft),
        z,
        file_bearings,
        file_ambs: Vec::new(),
    })
}

/// A ROSS file's name as the scene gives it, and the file as read.
type FileRead<'a> = (&'a str, flex::ross::RossFile);

/// The shaft of a flexible rotor: `rotor.shaft`'s table, or `rotor.ross_file`'s rotor with the
/// file as read (its bearings are placed once the AMB nodes are known).
fn shaft_of<'a>(r: &'a FlexibleKeys, base_dir: &Path) -> Result<(flex::Rotor, Option<FileRead<'a>>), ConfigError> {
    Ok(match (&r.shaft, &r.ross_file) {
        (Some(_), Some(f)) => {
            return Err(range("rotor.ross_file", f, "", "a flexible rotor has either rotor.shaft or rotor.ross_file"))
        }
        (None, None) => {
            return Err(range(
                "rotor.model",
                "\"flexible\"",
                "",
                "a flexible rotor needs its shaft: a [rotor.shaft] table or rotor.ross_file (neither is given)",
            ))
        }
        (Some(table), None) => {
            if let Some(b) = r.ross_bearings {
                return Err(range(
                    "rotor.ross_bearings",
                    at_ambs_name(b),
                    "",
                    "says what to do with a ROSS file's bearings, and this scene has no rotor.ross_file: remove it",
                ));
            }
            if let Some(b) = r.ross_ambs {
                return Err(range(
                    "rotor.ross_ambs",
                    ross_ambs_name(b),
                    "",
                    "says what to do with a ROSS file's MagneticBearingElements, and this scene has no \
                     rotor.ross_file: remove it",
                ));
            }
            (table.rotor().map_err(|e| flex_error("rotor.shaft", "the table", e))?, None)
        }
        (None, Some(file)) => {
            let path = base_dir.join(file);
            let text = shock_table::input::read_text(&path, shock_table::input::MAX_TOML_BYTES)
                .map_err(|e| range("rotor.ross_file", file, "", &format!("cannot read {}: {e}", path.display())))?;
            // The shaft and disks first: the AMB nodes are checked on them, then the file's
            // bearings are placed as the AMB nodes and rotor.ross_bearings say.
            // With rotor.ross_ambs = "use" or "constants" the file's AMB elements are already the
            // planes' AMBs (`super::ross_ambs::apply`); otherwise they are refused.
            let parse = match r.ross_ambs {
                Some(flex::ross::RossAmbs::Use | flex::ross::RossAmbs::Constants) => flex::ross::parse_file_with_ambs,
                _ => flex::ross::parse_file,
            };
            let read = parse(&text, file).map_err(|e| flex_error("rotor.ross_file", file, e))?;
            (read.rotor.clone(), Some((file.as_str(), read)))
        }
    })
}

/// A node on each plane, A's and B's.
type PlaneNodes = [usize; 2];

/// The nodes of each plane's AMB, sensor and touchdown bearing (the sensor's and the touchdown
/// bearing's the AMB's unless given), each on a shaft of `nodes` nodes.
fn nodes_of(r: &FlexibleKeys, nodes: usize) -> Result<(PlaneNodes, PlaneNodes, PlaneNodes), ConfigError> {
    let node = |key: &str, value: Option<usize>, default: Option<usize>| -> Result<usize, ConfigError> {
        let Some(n) = value.or(default) else {
            return Err(range(key, "none", "", "a flexible rotor needs the node of each AMB"));
        };
        if n >= nodes {
            return Err(range(key, n, "", &format!("is out of range: the shaft has nodes 0 to {}", nodes - 1)));
        }
        Ok(n)
    };
    let amb = [node("rotor.amb_a_node", r.amb_a_node, None)?, node("rotor.amb_b_node", r.amb_b_node, None)?];
    let sensor = [
        node("rotor.sensor_a_node", r.sensor_a_node, Some(amb[0]))?,
        node("rotor.sensor_b_node", r.sensor_b_node, Some(amb[1]))?,
    ];
    let touchdown = [
        node("rotor.touchdown_a_node", r.touchdown_a_node, Some(amb[0]))?,
        node("rotor.touchdown_b_node", r.touchdown_b_node, Some(amb[1]))?,
    ];
    Ok((amb, sensor, touchdown))
}

/// The shaft reduced to its modes below `rotor.cutoff_hz` with the static correction at the
/// force nodes (the AMBs' and the touchdown bearings'), `rotor.modal_damping` on every bending
/// mode; within the room the flexible state has.
fn reduce(
    r: &FlexibleKeys,
    shaft: &flex::Rotor,
    amb: PlaneNodes,
    touchdown: PlaneNodes,
) -> Result<flex::Reduced, ConfigError> {
    let cutoff = positive("rotor.cutoff_hz", r.cutoff_hz.unwrap_or(CUTOFF_HZ), "Hz")?;
    let zeta = non_negative("rotor.modal_damping", r.modal_damping.unwrap_or(MODAL_DAMPING), "")?;
    if zeta >= 1.0 {
        return Err(range("rotor.modal_damping", zeta, "", "must be below 1 (a damping ratio)"));
    }
    let spec = Reduction {
        cutoff_hz: cutoff,
        force_nodes: vec![amb[0], amb[1], touchdown[0], touchdown[1]],
        static_correction: true,
        gyroscopic_correction: false,
        modal_damping: zeta,
    };
    let reduced = flex::Reduced::new(shaft, &spec).map_err(|e| match e {
        flex::FlexError::CutoffBelowRigidModes { .. } | flex::FlexError::TooManyModes { .. } => {
            flex_error("rotor.cutoff_hz", &format!("{cutoff} Hz"), e)
        }
        // The free rotor's static correction is solved with the shift (2π f_c)²: a cutoff far
        // below the first bending mode leaves it too small to solve with. The cutoff is at fault.
        flex::FlexError::SingularStiffness => {
            let first = flex::reduce::undamped_frequencies_hz(shaft)
                .ok()
                .and_then(|f| f.get(flex::reduce::RIGID_MODES).copied());
            let first = first.map_or(String::new(), |f| format!(" (the shaft's first bending mode is at {f:.1} Hz)"));
            range(
                "rotor.cutoff_hz",
                cutoff,
                "Hz",
                &format!(
                    "is too low: it keeps only the rigid-body modes, and the static correction cannot be \
                     solved that far below the bending modes{first}; keep at least the first bending mode, or use \
                     the rigid two-plane rotor"
                ),
            )
        }
        e => flex_error("rotor.shaft", "the shaft", e),
    })?;
    if reduced.size() > MAX_BASIS {
        return Err(range(
            "rotor.cutoff_hz",
            cutoff,
            "Hz",
            &format!(
                "keeps {} modes and static corrections, more than the {MAX_BASIS} the flexible state has room for: \
                 lower the cutoff",
                reduced.size()
            ),
        ));
    }
    Ok(reduced)
}

/// `rotor.ross_ambs`'s value as the scene writes it.
pub(in crate::config) fn ross_ambs_name(choice: flex::ross::RossAmbs) -> &'static str {
    match choice {
        flex::ross::RossAmbs::Refuse => "\"refuse\"",
        flex::ross::RossAmbs::Use => "\"use\"",
        flex::ross::RossAmbs::Constants => "\"constants\"",
    }
}

/// `rotor.ross_bearings`'s value as the scene writes it.
fn at_ambs_name(b: flex::ross::AtAmbs) -> &'static str {
    match b {
        flex::ross::AtAmbs::Ignore => "\"ignore\"",
        flex::ross::AtAmbs::Parallel => "\"parallel\"",
    }
}

/// The line the run starts with when a ROSS file's bearings add stiffness to the shaft besides
/// the scene's AMBs (supports and seals away from the AMBs, or bearings at the AMB nodes kept in
/// parallel): which, where and how stiff; `None` when none does.
pub(in crate::config) fn file_bearings_note(rotor: &RawRotor, params: &machine::Params) -> Option<String> {
    use flex::ross::BearingUse;
    let kept: Vec<String> = params
        .file_bearings
        .iter()
        .filter(|b| b.used != BearingUse::Ignored)
        .map(|b| {
            let k = b.stiffness_n_per_m;
            let how = if b.used == BearingUse::Parallel { "in parallel with the AMB" } else { "added" };
            format!("\"{}\" at node {} (k_xx = {:e} N/m, k_yy = {:e} N/m) {how}", b.element, b.node, k[0][0], k[1][1])
        })
        .collect();
    if kept.is_empty() {
        return None;
    }
    let file = rotor.flexible().and_then(|r| r.ross_file.as_deref()).unwrap_or("the ROSS file");
    Some(format!(
        "rotor.ross_file = {file}: the file's bearings act on the shaft besides the scene's AMBs: {} \
         (summary.json model.ross_bearings)",
        kept.join(", ")
    ))
}
