//! The topics besides the rows' ([`super::topics`]): each plane's orbit window
//! ([`super::orbit`]) and the loop's ticks ([`super::ticks`]), named and with their schemas in
//! the one order `run.mcap` and the live view add them (after the rows' topics and `/events`).

use super::{orbit, ticks};
use crate::config::Scene;

/// A topic besides the rows': its name, its schema's name (ROS 2) and its schema's text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Extra {
    /// The topic.
    pub topic: String,
    /// The schema's name, `plant_msgs/msg/…`.
    pub schema_name: String,
    /// The schema, a ROS 2 message definition.
    pub schema: String,
}

/// The run's topics besides the rows': the orbit of each plane (`/plane_a/orbit`, …), then, in a
/// sampled or co-simulated run, `/loop/sample` and `/loop/command`.
pub fn extras(scene: &Scene) -> Vec<Extra> {
    let orbits = orbit::Orbits::new(scene, orbit::RATE_HZ);
    let mut out: Vec<Extra> = orbits
        .topics()
        .map(|t| Extra {
            topic: t.to_string(),
            schema_name: ros2_name(orbit::SCHEMA),
            schema: orbit::SCHEMA_TEXT.to_string(),
        })
        .collect();
    for (topic, schema, text) in ticks::topics(scene) {
        out.push(Extra { topic: topic.to_string(), schema_name: ros2_name(schema), schema: text });
    }
    out
}

/// A ROS 2 type name for a schema: `plant.Rotor` → `plant_msgs/msg/Rotor`.
pub fn ros2_name(schema: &str) -> String {
    match schema.split_once('.') {
        Some((package, name)) => format!("{package}_msgs/msg/{name}"),
        None => schema.to_string(),
    }
}
