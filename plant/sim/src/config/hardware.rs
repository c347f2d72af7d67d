//! The scene's parts of the loop between the wire and the physics (docs/MODEL.md §12): each
//! plane's amplifier and the sensor's front end, as the scene declares them. The model that
//! runs them is [`crate::hardware::Wired`].

use crate::sensor::FrontEnd;
use plant_physics::amplifier::{Amplifier, Bridge};

/// The scene's hardware between wire and physics.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct Hardware {
    /// Each bearing plane's amplifiers (both axes alike); `None`: an ideal current source.
    /// With [`Hardware::unipolar`] the plane's, each magnet's amplifier and coil.
    pub amplifiers: [Option<Amplifier>; 2],
    /// Each plane's unipolar drive (`amb.amplifier_topology = "unipolar"`); `None`: bipolar.
    pub unipolar: [Option<Unipolar>; 2],
    /// The sensor's front end (shared by all axes).
    pub front_end: FrontEnd,
}

impl Hardware {
    /// Whether any part is on (the model is then [`crate::hardware::Wired`]).
    pub fn is_on(&self) -> bool {
        self.amplified() || self.front_end.is_on()
    }

    /// Whether a plane has an amplifier (the trace then has the coil columns).
    pub fn amplified(&self) -> bool {
        self.amplifiers.iter().any(Option::is_some)
    }

    /// Whether a plane drives its magnets with unipolar amplifiers (the trace then has the
    /// magnets' columns too, and the model more states: [`crate::hardware::EXTRA_UNIPOLAR`]).
    pub fn is_unipolar(&self) -> bool {
        self.unipolar.iter().any(Option::is_some)
    }
}

/// A plane's unipolar drive (docs/MODEL.md §12.3): each of an axis's two magnets has its own
/// coil and amplifier (the plane's [`Amplifier`]: the same `V_dc`, `L`, `R`, loop and `k_b`),
/// its reference `i_0 + i` (the + side) or `i_0 − i` (the − side).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Unipolar {
    /// The nonlinear law's bias current i_0 (A).
    pub bias: f64,
    /// The voltages the bridge can apply.
    pub bridge: Bridge,
}
