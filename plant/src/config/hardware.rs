//! The scene's parts of the loop between the wire and the physics (docs/MODEL.md §12): each
//! plane's amplifier and the sensor's front end, as the scene declares them. The model that
//! runs them is [`crate::hardware::Wired`].

use crate::sensor::FrontEnd;
use plant_physics::amplifier::Amplifier;

/// The scene's hardware between wire and physics.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct Hardware {
    /// Each bearing plane's amplifiers (both axes alike); `None`: an ideal current source.
    pub amplifiers: [Option<Amplifier>; 2],
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
}
