//! The scene's rotor: one value whose variant is the rotor model (`rotor.model`).
//!
//! This is the scene's side of the rotor seam. A `match` on [`Rotor`] is exhaustive, so a
//! new rotor model is pointed to by the build wherever the scene must say something of it;
//! everything else about a model (its state, tolerances, per-plane state, failure state, trace
//! record) is answered by the model itself through [`crate::machine::Machine`].
//! docs/ARCHITECTURE.md ("Adding a rotor model") lists what a new model touches.

use super::raw::RawScene;
use super::validate::bearing::{bearing, Keys, Share};
use super::validate::flexible_keys::{flexible_params, record_flexible, refuse_flexible_keys};
use super::validate::two_plane_keys::{record_two_plane, refuse_two_plane_keys, two_plane_params};
use super::{ConfigError, RotorModel};
use crate::model::Params;
use plant_physics::flex::machine as flexible;
use plant_physics::two_plane;
use std::path::Path;

/// The rotor of a scene, validated (SI).
#[derive(Clone, Debug)]
// One value per scene, built once and read by reference: its size does not matter.
#[allow(clippy::large_enum_variant)]
pub enum Rotor {
    /// One bearing plane (the study's model, `rotor.model = "planar"`): its parameters.
    Planar(Params),
    /// The whole rigid rotor on two bearing planes, A and B (`rotor.model = "two_plane"`).
    TwoPlane(two_plane::Params),
    /// A flexible shaft on two bearing planes, A and B (`rotor.model = "flexible"`).
    Flexible(flexible::Params),
}

impl Rotor {
    /// The rotor model `rotor.model` names, built from the raw scene (its keys validated, each
    /// error naming the key, value and unit): its bearing planes from `[touchdown]`,
    /// `[contact]` and `[amb]` with `whole`, the rotor's values from `[rotor]`. The keys of the
    /// other models are refused by name. `base_dir` resolves a model's files.
    pub(super) fn from_raw(raw: &RawScene, whole: &Share, base_dir: &Path) -> Result<Self, ConfigError> {
        Ok(match raw.rotor.model {
            RotorModel::Planar => {
                refuse_two_plane_keys(raw)?;
                refuse_flexible_keys(raw)?;
                let keys = Keys { plane: None };
                Rotor::Planar(bearing(&raw.touchdown, &raw.contact, &raw.amb, &raw.controller, &keys, whole)?)
            }
            RotorModel::TwoPlane => {
                refuse_flexible_keys(raw)?;
                Rotor::TwoPlane(two_plane_params(raw, whole)?)
            }
            RotorModel::Flexible => Rotor::Flexible(flexible_params(raw, whole, base_dir)?),
        })
    }

    /// Writes the model's defaults into the raw scene it was built from (as the user would have
    /// written them, in the file's units), so that the resolved `scene.toml` states them.
    pub(super) fn record_defaults(&self, raw: &mut RawScene) {
        match self {
            Rotor::Planar(_) => {}
            Rotor::TwoPlane(_) => record_two_plane(raw),
            Rotor::Flexible(f) => record_flexible(raw, f),
        }
    }

    /// The model's name as `rotor.model` writes it.
    pub fn model(&self) -> RotorModel {
        match self {
            Rotor::Planar(_) => RotorModel::Planar,
            Rotor::TwoPlane(_) => RotorModel::TwoPlane,
            Rotor::Flexible(_) => RotorModel::Flexible,
        }
    }

    /// The rotor bends between its bearings (the flexible rotor): its trace has the rotor at
    /// mid-span (`mid_dx_m`, `mid_dy_m`); a rigid rotor's mid-span is the mean of its planes'.
    pub fn bends(&self) -> bool {
        matches!(self, Rotor::Flexible(_))
    }

    /// A bending rotor's mid-span node's place between its touchdown nodes, 0 at A's and 1 at
    /// B's (its trace's `mid_dx_m`, `mid_dy_m`); `None` for the rigid rotors, which have no
    /// mid-span columns.
    pub fn mid_span_weight(&self) -> Option<f64> {
        match self {
            Rotor::Flexible(p) => Some(crate::machine::mid_span_weight(p)),
            _ => None,
        }
    }

    /// The rigid two-plane rotor of a flexible rotor's rigid body: the mass, centre of mass,
    /// `I_t`, `I_p` and unbalance the flexible model computed from the shaft's elements, its
    /// planes (bearings, AMBs, sensors) at the nodes' stations; `None` for the rigid rotors.
    pub fn rigid_twin(&self) -> Option<Rotor> {
        match self {
            Rotor::Flexible(f) => Some(Rotor::TwoPlane(f.machine.clone())),
            _ => None,
        }
    }

    /// Bearing planes: each with its AMB, sensor and touchdown bearing.
    pub fn planes(&self) -> usize {
        match self {
            Rotor::Planar(_) => 1,
            Rotor::TwoPlane(m) => m.planes.len(),
            Rotor::Flexible(f) => f.machine.planes.len(),
        }
    }

    /// Plane `i`'s bearing: its touchdown bearing, AMB, loop constants and its share of the
    /// rotor (the planar model's whole parameters). Panics if `i` is not a plane.
    pub fn plane(&self, i: usize) -> &Params {
        match self {
            Rotor::Planar(p) => {
                assert_eq!(i, 0, "the planar rotor has one bearing plane");
                p
            }
            Rotor::TwoPlane(m) => &m.planes[i].params,
            Rotor::Flexible(f) => &f.machine.planes[i].params,
        }
    }

    /// Plane `i`'s bearing, mutable (a sweep or a test that moves one plane's value).
    pub fn plane_mut(&mut self, i: usize) -> &mut Params {
        match self {
            Rotor::Planar(p) => {
                assert_eq!(i, 0, "the planar rotor has one bearing plane");
                p
            }
            Rotor::TwoPlane(m) => &mut m.planes[i].params,
            Rotor::Flexible(f) => &mut f.machine.planes[i].params,
        }
    }

    /// Every plane's bearing, in order.
    pub fn bearings(&self) -> impl Iterator<Item = &Params> {
        (0..self.planes()).map(|i| self.plane(i))
    }

    /// The rotor's rated spin speed (rad/s); every plane's share carries it.
    pub fn speed(&self) -> f64 {
        self.plane(0).speed
    }

    /// The first plane whose sensor is not at its bearing (the sensor reads the rotor
    /// elsewhere than where the AMB and the touchdown bearing act); `None` when collocated.
    pub fn non_collocated_plane(&self) -> Option<usize> {
        match self {
            Rotor::Planar(_) => None,
            Rotor::TwoPlane(m) => m.planes.iter().position(|p| p.sensor != p.station),
            Rotor::Flexible(f) => f.nodes.iter().position(|n| n.sensor != n.amb),
        }
    }

    /// The `initial.*` overrides that put the rotor `offset_um` (µm) off on axis `axis` (x, y per
    /// plane, in order) at its sensor: the planar model's x or y; on the two-plane rotor, a
    /// translation and a slope that move the axis' own plane's sensor by `offset_um` and leave
    /// the other plane's sensor where it was (both modes, translation and tilt, start to move).
    pub fn sensor_offset(&self, axis: usize, offset_um: f64) -> Vec<String> {
        let xy = ["x", "y"][axis % 2];
        let machine = match self {
            Rotor::Planar(_) => return vec![format!("initial.rotor_{xy}_um={offset_um:?}")],
            Rotor::TwoPlane(m) => m,
            // The rigid motion that moves the sensor node: the flexible rotor's offsets are a rigid
            // motion of the shaft on top of its start at rest.
            Rotor::Flexible(f) => &f.machine,
        };
        let (own, other) = (machine.planes[axis / 2].sensor, machine.planes[1 - axis / 2].sensor);
        // x(z) = x₀ + a z: offset_um at z = own, 0 at z = other (µm, µrad for z in m).
        let slope = offset_um / (own - other);
        vec![format!("initial.rotor_{xy}_um={:?}", -slope * other), format!("initial.slope_{xy}_urad={slope:?}")]
    }

    /// Whether the rotor tilts (its trace and analysis have the tilt's columns and figures).
    pub fn tilts(&self) -> bool {
        match self {
            Rotor::Planar(_) => false,
            Rotor::TwoPlane(_) | Rotor::Flexible(_) => true,
        }
    }

    /// The whole rotor's geometry as a law sees it (`None` for the planar model, which has
    /// one plane and no tilt).
    pub fn geometry(&self) -> Option<controller::Geometry> {
        let m = match self {
            Rotor::Planar(_) => return None,
            Rotor::TwoPlane(m) => m,
            // The rigid body of the shaft, its AMBs and sensors at their nodes.
            Rotor::Flexible(f) => &f.machine,
        };
        let [a, b] = &m.planes;
        Some(controller::Geometry {
            mass_kg: m.rotor.mass,
            transverse_inertia_kg_m2: m.rotor.transverse_inertia,
            polar_inertia_kg_m2: m.rotor.polar_inertia,
            rated_speed_rad_s: m.rotor.speed,
            bearing_z_m: [a.station, b.station],
            sensor_z_m: [a.sensor, b.sensor],
        })
    }

    /// Absolute tolerances per state component of the model, laid out from those of
    /// positions (m), velocities (m/s), angles (rad) and angular speeds (rad/s)
    /// ([`crate::machine::Machine::atol`]).
    pub fn atol(&self, groups: [f64; 4]) -> Vec<f64> {
        use crate::machine::Machine;
        match self {
            Rotor::Planar(_) => crate::model::Model::atol(groups).to_vec(),
            Rotor::TwoPlane(_) => two_plane::Model::atol(groups).to_vec(),
            Rotor::Flexible(_) => flexible::Model::atol(groups).to_vec(),
        }
    }

    /// The failing state of a run that stopped at time `t` in state `y` (the model's part of
    /// the state first, the hardware's after it); `None` if `y` holds less than the model's
    /// state.
    pub fn failure(&self, t: f64, y: &[f64]) -> Option<crate::machine::FailureState> {
        use crate::machine::Machine;
        match self {
            Rotor::Planar(_) => crate::model::Model::failure(t, y.get(..crate::model::N)?.try_into().ok()?),
            Rotor::TwoPlane(_) => two_plane::Model::failure(t, y.get(..two_plane::N)?.try_into().ok()?),
            Rotor::Flexible(_) => flexible::Model::failure(t, y.get(..flexible::N)?.try_into().ok()?),
        }
        .into()
    }
}

impl Rotor {
    /// The rotor linearised about the centre on the continuous PD `gains` of each plane, for its
    /// whirl modes (`plant campbell`): the two-plane rotor's four, the flexible rotor's with its
    /// bending modes; `None` for the planar model (one plane: no whirl modes to tell apart).
    pub fn linearised(&self, gains: &[controller::PdGains]) -> Option<Box<dyn crate::machine::Linearised>> {
        match self {
            Rotor::Planar(_) => None,
            Rotor::TwoPlane(m) => Some(Box::new(two_plane::linear::LinearRotor::from_gains(m, &[gains[0], gains[1]]))),
            Rotor::Flexible(f) => Some(Box::new(crate::machine::FlexibleLinear::new(f, gains))),
        }
    }

    /// The open loop from the AMB currents to the sensor displacements of all axes, where the
    /// closed form of `plant assess` needs it whole (`plant_physics::flex::linear`): the flexible
    /// rotor's. The planar model's axis and the two-plane rotor's planes have their closed forms
    /// in `assess::closed_form`.
    pub fn open_loop(&self) -> Option<plant_physics::flex::linear::OpenLoop> {
        match self {
            Rotor::Planar(_) | Rotor::TwoPlane(_) => None,
            Rotor::Flexible(f) => Some(plant_physics::flex::linear::OpenLoop::of(f)),
        }
    }
}

impl RotorModel {
    /// The name `rotor.model` gives it.
    pub fn name(self) -> &'static str {
        match self {
            RotorModel::Planar => "planar",
            RotorModel::TwoPlane => "two_plane",
            RotorModel::Flexible => "flexible",
        }
    }
}
