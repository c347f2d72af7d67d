//! The rotor models: their one list ([`rotor_models!`]: `rotor.model`'s names, each model's key
//! struct, parameters and state), and what each model says of itself, the [`RotorParams`] trait,
//! one implementation per model in its file (`planar.rs`, `two_plane.rs`, `flexible.rs`) beside
//! its `[rotor]` keys, their defaults and their builder ([`Build`], with what the scene's
//! validation gives, [`BuildContext`]). [`Rotor`] dispatches to it once ([`Rotor::params`]); a
//! capability one model has and the others do not (bending, a linear open loop, whirl modes) is
//! a method with a default, so a new model says only what it has. `[rotor]` as written is
//! [`RawRotor`] (`table.rs`): the shared keys and the model's key struct, which refuses every key
//! that is not its own.

pub(in crate::config) mod flexible;
mod planar;
mod table;
mod two_plane;

pub use flexible::FlexibleKeys;
pub use flexible::RossAxes;
pub use planar::PlanarKeys;
pub use table::{RawRotor, RotorShared, SpinChoice};
pub use two_plane::TwoPlaneKeys;

use super::ConfigError;
use crate::machine::{Builds, FailureOf, Linearised, Machine, Mechanics};
use crate::model::Params;
use plant_physics::flex::linear::OpenLoop;
use plant_physics::flex::ross::UsedBearing;
use plant_physics::flex::ross_amb::UsedAmb;
use plant_physics::two_plane as rigid;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The one list of rotor models, handed to the macro `$then`: each model once, with its doc, its
/// variant, `rotor.model`'s name for it, the model in words and what a rotor of it is (for
/// messages), its key struct (`[rotor]`'s own keys, in its file of `config/models/`), its
/// validated parameters and its state (`[f64; N]`; the model that the parameters build is in its
/// file of `machine/`, [`Builds`]). Expanded here ([`declare_models`]: [`RotorModel`],
/// [`RotorKeys`], [`Rotor`], [`FailureState`] and their dispatch on the model) and by
/// `stepper::with_machine` (the model built and stepped): a new model is a line here, and the
/// compiler points to what it must give (its key struct's [`Build`], its parameters'
/// [`RotorParams`] and [`Builds`]).
macro_rules! rotor_models {
    ($then:ident) => {
        $then! {
            /// One bearing plane (the study's model): x, y, the race of one touchdown bearing.
            Planar = "planar", "the planar rotor", "rigid, on one bearing plane":
                PlanarKeys => plant_physics::model::Params, [f64; plant_physics::model::N];
            /// The whole rigid rotor on two bearing planes, A and B: translation and tilt, four axes.
            TwoPlane = "two_plane", "the two-plane rotor", "rigid, on two bearing planes":
                TwoPlaneKeys => plant_physics::two_plane::Params, [f64; plant_physics::two_plane::N];
            /// A flexible shaft (finite elements reduced to its modes) on two bearing planes, A and B.
            Flexible = "flexible", "the flexible rotor", "flexible, its geometry and inertia those of its shaft":
                FlexibleKeys => plant_physics::flex::machine::Params, [f64; plant_physics::flex::machine::N];
        }
    };
}
pub(crate) use rotor_models;

/// Declares, from the list of models ([`rotor_models`]), [`RotorModel`] (the names),
/// [`RotorKeys`] (the tagged part of `[rotor]`: the model's key struct), [`Rotor`] (the scene's
/// validated rotor), [`FailureState`] (a run's failing state) and the one dispatch of each on
/// the model.
macro_rules! declare_models {
    ($(
        $(#[$doc:meta])*
        $variant:ident = $name:literal, $what:literal, $is:literal: $keys:ident => $params:ty, [f64; $n:path];
    )+) => {
        /// `rotor.model`: the rotor model (the tag of `[rotor]`; `planar` when absent).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
        pub enum RotorModel {
            $( $(#[$doc])* #[serde(rename = $name)] $variant, )+
        }

        impl RotorModel {
            /// Every model, in the list's order.
            pub const ALL: &'static [RotorModel] = &[$(RotorModel::$variant),+];

            /// The name `rotor.model` gives it.
            pub fn name(self) -> &'static str {
                match self { $(RotorModel::$variant => $name,)+ }
            }

            /// The model in words, for messages ("the flexible rotor").
            pub fn what(self) -> &'static str {
                match self { $(RotorModel::$variant => $what,)+ }
            }

            /// What a rotor of the model is, for messages ("rigid, on one bearing plane").
            pub fn is(self) -> &'static str {
                match self { $(RotorModel::$variant => $is,)+ }
            }

            /// The model's own `[rotor]` keys (its key struct's), in declaration order.
            pub fn own_keys(self) -> &'static [&'static str] {
                match self { $(RotorModel::$variant => $keys::KEYS,)+ }
            }

            /// The model's own keys, each at its default.
            pub fn default_keys(self) -> RotorKeys {
                match self { $(RotorModel::$variant => RotorKeys::$variant($keys::default()),)+ }
            }
        }

        /// `[rotor]`'s tagged part: the model `rotor.model` names, holding its own keys (its key
        /// struct refuses every other key).
        #[derive(Clone, Debug, Serialize)]
        #[serde(untagged)]
        pub enum RotorKeys {
            $( $(#[$doc])* $variant($keys), )+
        }

        impl RotorKeys {
            /// The model these keys are of.
            pub fn model(&self) -> RotorModel {
                match self { $(RotorKeys::$variant(_) => RotorModel::$variant,)+ }
            }

            /// `model`'s keys read from `table` (no shared key, no `model`): the key struct
            /// refuses a key that is not its own.
            fn from_table(model: RotorModel, table: toml::Table) -> Result<RotorKeys, toml::de::Error> {
                let table = toml::Value::Table(table);
                Ok(match model { $(RotorModel::$variant => RotorKeys::$variant(table.try_into()?),)+ })
            }

            /// The model's parameters built from its keys with what the scene's validation gives
            /// (`ctx`, [`Build`]).
            pub(crate) fn build(&self, ctx: &dyn BuildContext) -> Result<Rotor, ConfigError> {
                Ok(match self { $(RotorKeys::$variant(k) => Rotor::$variant(k.build(ctx)?),)+ })
            }
        }

        /// The rotor of a scene, validated (SI): the model's parameters.
        #[derive(Clone, Debug)]
        // One value per scene, built once and read by reference: its size does not matter.
        #[allow(clippy::large_enum_variant)]
        pub enum Rotor {
            $( $(#[$doc])* $variant($params), )+
        }

        impl Rotor {
            /// The model's parameters, as the rest of the plant asks of them: the one dispatch on
            /// the model ([`RotorParams`], one implementation per model in `config/models/`).
            pub fn params(&self) -> &dyn RotorParams {
                match self { $(Rotor::$variant(p) => p,)+ }
            }

            /// The same, mutable.
            pub fn params_mut(&mut self) -> &mut dyn RotorParams {
                match self { $(Rotor::$variant(p) => p,)+ }
            }

            /// Absolute tolerances per state component of the model, laid out from those of
            /// positions (m), velocities (m/s), angles (rad) and angular speeds (rad/s)
            /// ([`Machine::atol`]).
            pub fn atol(&self, groups: [f64; 4]) -> Vec<f64> {
                match self {
                    $(Rotor::$variant(_) => <<$params as Builds<{ $n }>>::Machine as Machine<{ $n }>>::atol(groups).to_vec(),)+
                }
            }

            /// The failing state of a run that stopped at time `t` in state `y` (the model's part
            /// of the state first, the hardware's after it); `None` if `y` holds less than the
            /// model's state.
            pub fn failure(&self, t: f64, y: &[f64]) -> Option<FailureState> {
                Some(match self {
                    $(Rotor::$variant(_) => FailureState::$variant(
                        <<$params as Builds<{ $n }>>::Machine as Machine<{ $n }>>::failure(t, y.get(..$n)?.try_into().ok()?),
                    ),)+
                })
            }
        }

        /// The state a diverged run failed in (`failure_state` in `summary.json`), as its rotor
        /// model lays it out ([`Machine::failure`], its struct in the model's file of
        /// `machine/`); non-finite values are written as `null`.
        #[derive(Clone, Debug, PartialEq, Serialize)]
        #[serde(untagged)]
        pub enum FailureState {
            $( $(#[$doc])* $variant(FailureOf<$params, { $n }>), )+
        }
    };
}

rotor_models!(declare_models);

/// `planar` when `[rotor]` has no `model`.
impl Default for RotorModel {
    fn default() -> Self {
        RotorModel::Planar
    }
}

impl Default for RotorKeys {
    fn default() -> Self {
        RotorModel::default().default_keys()
    }
}

/// A model's key struct built into the model's parameters (in the model's file, beside its
/// keys), with what the scene's validation gives it ([`BuildContext`]).
pub(crate) trait Build {
    /// The model's validated parameters.
    type Params;

    /// The model's parameters, each error naming the key, value and unit.
    fn build(&self, ctx: &dyn BuildContext) -> Result<Self::Params, ConfigError>;
}

/// What a model's builder ([`Build`]) asks of the scene being validated: the shared `[rotor]`
/// keys, the scene's folder and its bearing planes, each from the bearing tables (`[touchdown]`,
/// `[contact]`, `[amb]`), validated as for every model. Implemented by `config::validate`, which
/// reads the whole scene: this module holds `[rotor]`, which the scene's file format holds, and
/// imports neither.
pub(crate) trait BuildContext {
    /// The shared `[rotor]` keys, validated: the whole rotor.
    fn whole(&self) -> &Share;

    /// The scene's folder (a model's files are named from it).
    fn base_dir(&self) -> &Path;

    /// A model's one bearing plane, from the shared tables with the rotor's `share`; a
    /// two-plane rotor's per-plane tables and initial slopes are refused by name (each would be
    /// ignored otherwise).
    fn single_plane(&self, share: &Share) -> Result<Params, ConfigError>;

    /// Bearing plane `i` (0 is A, 1 is B): the shared tables with the plane's own
    /// (`[touchdown.a]`, …) set over them, with the plane's `share` of the rotor.
    fn plane(&self, i: usize, share: &Share) -> Result<Params, ConfigError>;
}

/// The rotor's values a bearing plane's planar parameters take: for the planar model the
/// rotor's own, for a plane of the two-plane rotor its share ([`plant_physics::two_plane::Plane`]).
pub(crate) struct Share {
    /// Gravity (m/s²).
    pub(crate) gravity: f64,
    /// Mass (kg).
    pub(crate) mass: f64,
    /// Eccentricity of the static unbalance (m).
    pub(crate) eccentricity: f64,
    /// Polar moment of inertia (kg·m²).
    pub(crate) inertia: f64,
    /// Radius at the touchdown bearing (m).
    pub(crate) radius: f64,
    /// Spin speed (rad/s).
    pub(crate) speed: f64,
    /// Spin: held or driven.
    pub(crate) spin: crate::model::Spin,
}

/// A rotor model's parameters, as the scene and the rest of the plant ask of them.
pub trait RotorParams {
    /// The model's name as `rotor.model` writes it.
    fn model(&self) -> RotorModel;

    /// Bearing planes: each with its AMB, sensor and touchdown bearing.
    fn planes(&self) -> usize;

    /// The rotor's linear mechanics about the centre at spin speed `omega` (rad/s), races
    /// clear, the AMBs linear (`F = k_i i + k_s Δ`): `plant linear`'s first block.
    fn mechanics(&self, omega: f64) -> Mechanics;

    /// Plane `i`'s bearing: its touchdown bearing, AMB, loop constants and its share of the
    /// rotor (the planar model's whole parameters). Panics if `i` is not a plane.
    fn plane(&self, i: usize) -> &Params;

    /// Plane `i`'s bearing, mutable (a sweep or a test that moves one plane's value).
    fn plane_mut(&mut self, i: usize) -> &mut Params;

    /// Writes the model's defaults into the `[rotor]` table it was built from (as the user would have
    /// written them, in the file's units), so that the resolved `scene.toml` states them. The
    /// default: the model has none beyond the scene table's own.
    fn record_defaults(&self, _rotor: &mut RawRotor) {}

    /// The rigid rotor on two bearing planes that the model is, or whose rigid body it bends
    /// about (the flexible rotor's: mass, inertias and unbalance from its elements, its planes
    /// at the nodes' stations); `None` for a model with one plane and no tilt.
    fn rigid_body(&self) -> Option<&rigid::Params> {
        None
    }

    /// The first plane whose sensor is not at its bearing; `None` when collocated.
    fn non_collocated_plane(&self) -> Option<usize> {
        None
    }

    /// A bending rotor's mid-span node's place between its touchdown nodes, 0 at A's and 1 at
    /// B's (its trace's `mid_dx_m`, `mid_dy_m`); `None` for a rotor that does not bend.
    fn mid_span_weight(&self) -> Option<f64> {
        None
    }

    /// The rotor linearised about the centre on the continuous PD `gains` of each plane, for its
    /// whirl modes (`plant campbell`); `None` for a model with no whirl modes to tell apart.
    fn linearised(&self, _gains: &[controller::PdGains]) -> Option<Box<dyn Linearised>> {
        None
    }

    /// A machine file's plain bearings and what became of each (a ROSS file's, `summary.json`'s
    /// `ross_bearings`); none by default.
    fn file_bearings(&self) -> &[UsedBearing] {
        &[]
    }

    /// A machine file's AMB elements made the planes' AMBs (`summary.json`'s `ross_ambs`); none
    /// by default.
    fn file_ambs(&self) -> &[UsedAmb] {
        &[]
    }

    /// The open loop from the AMB currents to the sensor displacements of all axes, where the
    /// closed form of `plant assess` needs it whole; `None` where the closed forms of
    /// `assess::closed_form` serve.
    fn open_loop(&self) -> Option<OpenLoop> {
        None
    }
}
