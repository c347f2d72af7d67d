//! The flexible shaft on two bearing planes (`rotor.model = "flexible"`): its `[rotor]` keys and
//! their defaults, and what the model says of itself.

use super::{RawRotor, RotorKeys, RotorModel, RotorParams};
use crate::config::scene_table::scene_table;
use crate::machine::{mid_span_weight, FlexibleLinear, Linearised};
use crate::model::Params;
use plant_physics::flex::linear::OpenLoop;
use plant_physics::flex::machine as flexible;
use plant_physics::flex::ross::UsedBearing;
use plant_physics::flex::ross_amb::UsedAmb;
use plant_physics::two_plane;
use serde::{Deserialize, Serialize};

/// Cutoff when none is given (Hz).
pub(in crate::config) const CUTOFF_HZ: f64 = 2000.0;
/// Modal damping ratio when none is given.
pub(in crate::config) const MODAL_DAMPING: f64 = 0.005;

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
