//! The checks before a plant starts from a saved state ([`check_start`]): the snapshot against
//! the scene, field by field, the plant's part and the digital loop's.

use crate::config::Scene;
use crate::run::PlantError;
use crate::snapshot::{Snapshot, SnapshotError};
use crate::stepper::{Command, Plant};

/// Whether `scene`'s plant can start from `snapshot` ([`Plant::restore`] into a fresh one): the
/// check made before anything starts or is written.
///
/// In order: the format and the scene's fingerprint (another scene named as such), the seal
/// recomputed from this scene and the snapshot's fields ([`Snapshot::check_seal`]), then each
/// field against the scene and the physics (the plant's restore, the digital loop's part here).
pub fn check_start(scene: &Scene, snapshot: &Snapshot) -> Result<(), PlantError> {
    let mut plant = Plant::new(scene, &Command::Continuous(None))?;
    snapshot.check_against(plant.fingerprint())?;
    snapshot.check_seal(plant.fingerprint())?;
    check_digital(scene, snapshot)?;
    plant.restore(snapshot)?;
    Ok(())
}

/// The digital loop's part of `snapshot` against `scene`: commands within the amplifiers'
/// limits (they are saturated before they enter the delay line), and the samples the law read
/// last those of the ticks before the snapshot's, in order, on the controller's grid.
fn check_digital(scene: &Scene, snapshot: &Snapshot) -> Result<(), SnapshotError> {
    let Some(d) = &snapshot.digital else { return Ok(()) };
    let limits = scene.rotor_design().current_limits();
    for (k, c) in d.in_flight.iter().enumerate() {
        for (a, (&i, &limit)) in c.iter().zip(&limits).enumerate() {
            if i.is_nan() || i.abs() > limit {
                return Err(SnapshotError::field(
                    format!("digital.in_flight[{k}][{a}]"),
                    format!("{i} A"),
                    format!("within the amplifier's current limit, ±{limit} A"),
                ));
            }
        }
    }
    if d.recent.len() > crate::digital::RECENT {
        return Err(SnapshotError::field(
            "digital.recent",
            format!("{} samples", d.recent.len()),
            format!("at most {}", crate::digital::RECENT),
        ));
    }
    let period = scene.controller.period;
    let n = d.recent.len() as u64;
    let planes = scene.rotor_design().planes().len() as u32;
    for (k, r) in d.recent.iter().enumerate() {
        let field = |name: &str| format!("digital.recent[{k}].{name}");
        // The last sample read is that of the tick before the snapshot's.
        let seq = (snapshot.tick + k as u64).checked_sub(n);
        if Some(r.seq) != seq {
            return Err(SnapshotError::field(
                field("seq"),
                r.seq,
                format!("the ticks before the snapshot's tick {} in order, here {seq:?}", snapshot.tick),
            ));
        }
        if (r.t_s - r.seq as f64 * period).abs() > 1e-9 * period.max(r.t_s.abs()) {
            return Err(SnapshotError::field(
                field("t_s"),
                format!("{} s", r.t_s),
                format!("tick {} of {period} s", r.seq),
            ));
        }
        if r.axes != 2 * planes {
            return Err(SnapshotError::field(field("axes"), r.axes, format!("{} ({planes} planes)", 2 * planes)));
        }
        if !(0.0..std::f64::consts::TAU).contains(&r.angle_rad) {
            return Err(SnapshotError::field(
                field("angle_rad"),
                format!("{} rad", r.angle_rad),
                "the keyphasor's angle in [0, 2π)",
            ));
        }
    }
    Ok(())
}
