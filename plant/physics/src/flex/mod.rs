//! The flexible rotor (MODEL.md §13): a finite-element shaft of Timoshenko beam elements with
//! rigid disks, ROSS's formulation ([`shaft`], [`rotor`]), its whirl modes and Campbell diagram
//! ([`modes`]), its reduction to the modes below a cutoff with a static correction at the force
//! nodes and the pure derivative of the reduced state ([`reduce`]), and the two ways a rotor is
//! described: a file saved by ROSS's `Rotor.save()` ([`ross`]) or a table of elements that a
//! scene embeds ([`table`]).
//!
//! [`machine`] is the rotor the plant steps (`rotor.model = "flexible"`): the reduced shaft
//! with two AMBs, two sensors and two touchdown bearings at its nodes.

pub mod band;
pub mod initial;
pub mod linear;
pub mod machine;
pub mod modes;
pub mod reduce;
mod reduce_band;
pub mod ross;
pub mod ross_amb;
pub mod rotor;
pub mod shaft;
pub mod subspace;
pub mod table;

pub use modes::{Linear, Mode, Whirl};

/// The most shaft elements a rotor may have (after splits). The model is assembled by its band
/// and reduced by subspace iteration on the bands above [`DENSE_ELEMENTS`] ([`band`],
/// [`subspace`]): building costs time and memory in proportion to the element count, a few
/// seconds at this limit (`cargo bench -p plant-physics --bench shaft`;
/// docs/results/flexible-rotor.md, "How big a shaft"). A slender rotor's lowest modes converge
/// with a few elements per span; this bound leaves a wide margin over that and keeps a ROSS
/// file of 20,000 elements from being taken.
pub const MAX_ELEMENTS: usize = 2000;

/// Up to this many elements the model is built with dense matrices and nalgebra's dense
/// eigensolver, as it always was, so that the shipped scenes' figures stay the same to the bit;
/// above it, by the band path (the two agree to 1e-10 on the retained frequencies, tested).
pub const DENSE_ELEMENTS: usize = 200;

/// The most modes below the cutoff the band path computes (the plant's flexible state holds
/// [`machine::MAX_MODES`] basis vectors in all): more is refused by their count, before the
/// iteration, whose cost grows as the square of the modes sought.
pub const BAND_MAX_MODES: usize = 100;

/// Whether `rotor` is built by the dense path ([`DENSE_ELEMENTS`]).
pub fn dense_model(rotor: &Rotor) -> bool {
    rotor.elements.len() <= DENSE_ELEMENTS
}
pub use reduce::{Reduced, Reduction};
pub use rotor::{Disk, LinearBearing, Rotor};
pub use shaft::{Material, ShaftElement};

/// Why a flexible rotor could not be built: each names the element or key, the value and unit.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FlexError {
    /// The shaft has no elements.
    #[error("the shaft has no elements")]
    NoElements,
    /// More shaft elements than the model builds in bounded time and memory.
    #[error(
        "the shaft has {count} elements, more than the {limit} this model takes (building costs time in \
         proportion to the element count: {limit} elements build in seconds); merge elements or split them less"
    )]
    TooManyElements {
        /// The element count (after splits).
        count: usize,
        /// [`MAX_ELEMENTS`].
        limit: usize,
    },
    /// A length, diameter or inertia is zero, negative or not finite.
    #[error("{element}: {key} = {value} {unit} must be positive")]
    NotPositive {
        /// The element.
        element: String,
        /// The key.
        key: &'static str,
        /// Its value.
        value: f64,
        /// Its unit.
        unit: &'static str,
    },
    /// An inner diameter is negative or not below the outer one.
    #[error("{element}: {key} = {value} m must be at least 0 and below the outer diameter {outer} m")]
    InnerDiameter {
        /// The element.
        element: String,
        /// The key.
        key: &'static str,
        /// Its value (m).
        value: f64,
        /// The outer diameter (m).
        outer: f64,
    },
    /// A material property is missing, zero or negative.
    #[error("{element}: material {key} = {value} {unit} must be positive")]
    Material {
        /// The element.
        element: String,
        /// The property.
        key: &'static str,
        /// Its value (NaN when missing).
        value: f64,
        /// Its unit.
        unit: &'static str,
    },
    /// A node number beyond the shaft.
    #[error("{what}: node {node} is out of range (the shaft has nodes 0 to {})", nodes - 1)]
    NodeOutOfRange {
        /// What sits at the node.
        what: String,
        /// The node.
        node: usize,
        /// The shaft's node count.
        nodes: usize,
    },
    /// A value out of its range.
    #[error("{key} = {value} {unit} is out of range")]
    Value {
        /// The key.
        key: &'static str,
        /// Its value.
        value: f64,
        /// Its unit.
        unit: &'static str,
    },
    /// The cutoff leaves out some of the rigid-body modes.
    #[error(
        "cutoff_hz = {cutoff_hz} Hz is below the rigid-body modes: the four lowest modes are at {rigid_hz:.3?} Hz"
    )]
    CutoffBelowRigidModes {
        /// The cutoff (Hz).
        cutoff_hz: f64,
        /// The four lowest modes (Hz).
        rigid_hz: Vec<f64>,
    },
    /// The mass matrix is not positive definite.
    #[error("the rotor's mass matrix is not positive definite (a node without mass?)")]
    MassNotPositive,
    /// The static correction's stiffness is singular.
    #[error("the rotor's stiffness matrix is singular: no static correction")]
    SingularStiffness,
    /// The cutoff keeps more modes of a large shaft than the band path computes.
    #[error(
        "cutoff_hz = {cutoff_hz} Hz keeps {count} modes of the shaft, more than the {limit} a shaft of more than \
         {dense} elements is reduced to: lower the cutoff"
    )]
    TooManyModes {
        /// The cutoff (Hz).
        cutoff_hz: f64,
        /// The modes below it (the Sturm count).
        count: usize,
        /// [`BAND_MAX_MODES`].
        limit: usize,
        /// [`DENSE_ELEMENTS`].
        dense: usize,
    },
    /// The band eigensolver of a large shaft did not converge.
    #[error("the shaft's modes did not converge in {sweeps} sweeps of subspace iteration")]
    NoConvergence {
        /// The sweeps made.
        sweeps: usize,
    },
    /// A ROSS file that cannot be read.
    #[error("{file}: {message}")]
    Ross {
        /// The file.
        file: String,
        /// What is wrong, naming the element and key.
        message: String,
    },
}
