//! The flexible rotor (MODEL.md §13): a finite-element shaft of Timoshenko beam elements with
//! rigid disks, ROSS's formulation ([`shaft`], [`rotor`]), its whirl modes and Campbell diagram
//! ([`modes`]), its reduction to the modes below a cutoff with a static correction at the force
//! nodes and the pure derivative of the reduced state ([`reduce`]), and the two ways a rotor is
//! described: a file saved by ROSS's `Rotor.save()` ([`ross`]) or a table of elements that a
//! scene embeds ([`table`]).
//!
//! [`machine`] is the rotor the plant steps (`rotor.model = "flexible"`): the reduced shaft
//! with two AMBs, two sensors and two touchdown bearings at its nodes.

pub mod initial;
pub mod linear;
pub mod machine;
pub mod modes;
pub mod reduce;
pub mod ross;
pub mod ross_amb;
pub mod rotor;
pub mod shaft;
pub mod table;

pub use modes::{Linear, Mode, Whirl};

/// The most shaft elements a rotor may have (after splits). The model's full matrices are
/// dense, `4 (n + 1)` coordinates square, and its modes come from a dense eigensolver, so
/// building costs O(n³) time and O(n²) memory (`cargo bench -p plant-physics --bench shaft`;
/// docs/results/flexible-rotor.md, "How big a shaft"). A slender rotor's lowest modes converge
/// with a few elements per span; this bound leaves a wide margin over that.
pub const MAX_ELEMENTS: usize = 200;
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
        "the shaft has {count} elements, more than the {limit} this model takes (its full matrices are dense: \
         {limit} elements build in seconds, 20 000 would need 51 GB); merge elements or split them less"
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
    /// A ROSS file that cannot be read.
    #[error("{file}: {message}")]
    Ross {
        /// The file.
        file: String,
        /// What is wrong, naming the element and key.
        message: String,
    },
}
