//! The scene's rotor: one value whose variant is the rotor model (`rotor.model`).
//!
//! This is the scene's side of the rotor seam: the variant is the model, and what the rest of the
//! plant asks of a rotor goes through one dispatch ([`Rotor::params`]) to the model's
//! [`RotorParams`] (its capabilities as methods with defaults, `config/models/`); the model's
//! dynamics (its state, tolerances, per-plane state, failure state, trace record) are answered
//! by the model itself through [`crate::machine::Machine`].
//! docs/ARCHITECTURE.md ("Adding a rotor model") lists what a new model touches.

pub use super::models::{FailureState, Rotor, RotorParams};
use super::models::{RawRotor, RotorModel};
use crate::model::Params;

impl Rotor {
    /// Writes the model's defaults into the `[rotor]` table it was built from (as the user would have
    /// written them, in the file's units), so that the resolved `scene.toml` states them.
    pub(super) fn record_defaults(&self, rotor: &mut RawRotor) {
        self.params().record_defaults(rotor);
    }

    /// The model's name as `rotor.model` writes it.
    pub fn model(&self) -> RotorModel {
        self.params().model()
    }

    /// The rotor bends between its bearings (the flexible rotor): its trace has the rotor at
    /// mid-span (`mid_dx_m`, `mid_dy_m`); a rigid rotor's mid-span is the mean of its planes'.
    pub fn bends(&self) -> bool {
        self.mid_span_weight().is_some()
    }

    /// A bending rotor's mid-span node's place between its touchdown nodes, 0 at A's and 1 at
    /// B's (its trace's `mid_dx_m`, `mid_dy_m`); `None` for the rigid rotors, which have no
    /// mid-span columns.
    pub fn mid_span_weight(&self) -> Option<f64> {
        self.params().mid_span_weight()
    }

    /// The rigid two-plane rotor of a bending rotor's rigid body: the mass, centre of mass,
    /// `I_t`, `I_p` and unbalance the flexible model computed from the shaft's elements, its
    /// planes (bearings, AMBs, sensors) at the nodes' stations; `None` for the rigid rotors.
    pub fn rigid_twin(&self) -> Option<Rotor> {
        let p = self.params();
        p.mid_span_weight().and(p.rigid_body()).map(|m| Rotor::TwoPlane(m.clone()))
    }

    /// Bearing planes: each with its AMB, sensor and touchdown bearing.
    pub fn planes(&self) -> usize {
        self.params().planes()
    }

    /// Plane `i`'s bearing: its touchdown bearing, AMB, loop constants and its share of the
    /// rotor (the planar model's whole parameters). Panics if `i` is not a plane.
    pub fn plane(&self, i: usize) -> &Params {
        self.params().plane(i)
    }

    /// Plane `i`'s bearing, mutable (a sweep or a test that moves one plane's value).
    pub fn plane_mut(&mut self, i: usize) -> &mut Params {
        self.params_mut().plane_mut(i)
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
        self.params().non_collocated_plane()
    }

    /// The `initial.*` overrides that put the rotor `offset_um` (µm) off on axis `axis` (x, y per
    /// plane, in order) at its sensor: the planar model's x or y; on a rotor with two planes, a
    /// translation and a slope that move the axis' own plane's sensor by `offset_um` and leave
    /// the other plane's sensor where it was (both modes, translation and tilt, start to move;
    /// the flexible rotor's offsets are a rigid motion of the shaft on top of its start at rest).
    pub fn sensor_offset(&self, axis: usize, offset_um: f64) -> Vec<String> {
        let xy = ["x", "y"][axis % 2];
        let Some(machine) = self.params().rigid_body() else {
            return vec![format!("initial.rotor_{xy}_um={offset_um:?}")];
        };
        let (own, other) = (machine.planes[axis / 2].sensor, machine.planes[1 - axis / 2].sensor);
        // x(z) = x₀ + a z: offset_um at z = own, 0 at z = other (µm, µrad for z in m).
        let slope = offset_um / (own - other);
        vec![format!("initial.rotor_{xy}_um={:?}", -slope * other), format!("initial.slope_{xy}_urad={slope:?}")]
    }

    /// Whether the rotor tilts (its trace and analysis have the tilt's columns and figures).
    pub fn tilts(&self) -> bool {
        self.params().rigid_body().is_some()
    }

    /// The whole rotor's geometry as a law sees it (`None` for the planar model, which has
    /// one plane and no tilt).
    pub fn geometry(&self) -> Option<controller::Geometry> {
        let m = self.params().rigid_body()?;
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

    /// The rotor linearised about the centre on the continuous PD `gains` of each plane, for its
    /// whirl modes (`plant campbell`): the two-plane rotor's four, the flexible rotor's with its
    /// bending modes; `None` for the planar model (one plane: no whirl modes to tell apart).
    pub fn linearised(&self, gains: &[controller::PdGains]) -> Option<Box<dyn crate::machine::Linearised>> {
        self.params().linearised(gains)
    }

    /// The open loop from the AMB currents to the sensor displacements of all axes, where the
    /// closed form of `plant assess` needs it whole (`plant_physics::flex::linear`): the flexible
    /// rotor's. The planar model's axis and the two-plane rotor's planes have their closed forms
    /// in `assess::closed_form`.
    pub fn open_loop(&self) -> Option<plant_physics::flex::linear::OpenLoop> {
        self.params().open_loop()
    }
}
