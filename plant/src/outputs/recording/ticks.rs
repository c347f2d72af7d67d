//! The loop's ticks as topics (issue 42 item 1: "the sensor samples and commands of the loop"):
//! in a sampled or co-simulated run (`controller.mode` `sampled`, `lockstep`, `realtime`), at
//! each controller tick, `/loop/sample`, what the law read (the sample a co-simulation sends
//! its controller), and `/loop/command`, the coil current references applied over the tick
//! (a co-simulation's: the reply received, after the delay line and the saturation). A
//! continuous run has no ticks, so no such topics. Pure: a tick in, messages out.

use super::topics::CDR_LE;
use crate::config::{ControlMode, Scene};
use controller::{RotorSample, ROTOR_AXES};
use std::fmt::Write as _;

/// The sample's topic.
pub const SAMPLE_TOPIC: &str = "/loop/sample";
/// The command's topic.
pub const COMMAND_TOPIC: &str = "/loop/command";

/// The axes' names in the wire's order (x_A, y_A, x_B, y_B).
const AXES: [&str; ROTOR_AXES] = ["xa", "ya", "xb", "yb"];

/// The loop's topics of a run: (topic, schema name, schema text), sample then command; none
/// for a continuous run.
pub fn topics(scene: &Scene) -> Vec<(&'static str, &'static str, String)> {
    if scene.controller.mode == ControlMode::Continuous {
        return Vec::new();
    }
    let axes = 2 * scene.planes();
    let mut sample = String::from(
        "# plant.LoopSample: what the control law read at a controller tick (the sample a co-simulation sends), issue 42.\n\
         float64 t_s  # t_s (s): the tick's simulated time\n\
         uint64 seq  # seq (1): the tick's index k\n",
    );
    let mut command = String::from(
        "# plant.LoopCommand: the coil current references applied over a controller tick (a co-simulation's reply, delayed and saturated), issue 42.\n\
         float64 t_s  # t_s (s): the tick's simulated time\n\
         uint64 seq  # seq (1): the tick's index k\n",
    );
    for axis in &AXES[..axes] {
        let _ = writeln!(
            sample,
            "float64 sensor_{axis}_v  # sensor_{axis}_v (V): the position sensor's voltage, axis {axis}"
        );
        let _ =
            writeln!(command, "float64 command_{axis}_a  # command_{axis}_a (A): the current reference, axis {axis}");
    }
    sample.push_str("float64 speed_rad_s  # speed_rad_s (rad/s): the rotor's spin speed (keyphasor)\n");
    sample.push_str("float64 angle_rad  # angle_rad (rad): the rotor's angle in [0, 2 pi) (keyphasor)\n");
    vec![(SAMPLE_TOPIC, "plant.LoopSample", sample), (COMMAND_TOPIC, "plant.LoopCommand", command)]
}

/// The two messages of a tick of a run with `axes` axes (2 or 4), into `sample` and `command`
/// (cleared first): CDR, little-endian, every field 8 bytes (so 8-aligned after the header).
pub fn messages(
    s: &RotorSample,
    applied: &[f64; ROTOR_AXES],
    axes: usize,
    sample: &mut Vec<u8>,
    command: &mut Vec<u8>,
) {
    for out in [&mut *sample, &mut *command] {
        out.clear();
        out.extend_from_slice(&CDR_LE);
        out.extend_from_slice(&s.t_s.to_le_bytes());
        out.extend_from_slice(&s.seq.to_le_bytes());
    }
    for (v, i) in s.sensor_v.iter().zip(applied).take(axes) {
        sample.extend_from_slice(&v.to_le_bytes());
        command.extend_from_slice(&i.to_le_bytes());
    }
    sample.extend_from_slice(&s.speed_rad_s.to_le_bytes());
    sample.extend_from_slice(&s.angle_rad.to_le_bytes());
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ticks_messages_are_its_numbers_after_the_cdr_header() {
        let s = RotorSample {
            seq: 7,
            t_s: 3.5e-4,
            axes: 2,
            sensor_v: [0.25, -0.5, 9.0, 9.0],
            speed_rad_s: 1000.0,
            angle_rad: 1.5,
        };
        let (mut a, mut b) = (Vec::new(), Vec::new());
        messages(&s, &[1.0, -2.0, 9.0, 9.0], 2, &mut a, &mut b);
        let mut want = vec![0u8, 1, 0, 0];
        want.extend_from_slice(&3.5e-4f64.to_le_bytes());
        want.extend_from_slice(&7u64.to_le_bytes());
        let mut sample = want.clone();
        for v in [0.25f64, -0.5, 1000.0, 1.5] {
            sample.extend_from_slice(&v.to_le_bytes());
        }
        let mut command = want;
        for v in [1.0f64, -2.0] {
            command.extend_from_slice(&v.to_le_bytes());
        }
        assert_eq!(a, sample);
        assert_eq!(b, command);
    }
}
