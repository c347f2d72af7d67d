//! `rotor.model = "two_plane"`: the rotor's geometry and each plane's bearing, the per-plane
//! tables, and the per-plane tables refused in a planar scene.

use super::*;
use crate::config::models::two_plane::{BEARING_A_MM, BEARING_B_MM, END_A_MM, END_B_MM, TRANSVERSE_INERTIA_KG_M2};
use crate::config::models::TwoPlaneKeys;
use plant_physics::two_plane;

impl crate::config::models::Build<Context<'_>> for TwoPlaneKeys {
    type Params = two_plane::Params;

    fn build(&self, ctx: &Context) -> Result<two_plane::Params, ConfigError> {
        two_plane_params(ctx.raw, self, ctx.whole)
    }
}

/// A two-plane rotor's per-plane tables (`[touchdown.a]`, …) and initial slopes given in a planar
/// scene, refused by name: each would be silently ignored otherwise. (Its `[rotor]` keys are
/// refused by the planar model's key struct.)
pub(in crate::config) fn refuse_plane_tables(raw: &RawScene) -> Result<(), ConfigError> {
    const WHY: &str = "is a key of the two-plane rotor and this scene is planar (rotor.model = \"planar\"): set \
                       rotor.model = \"two_plane\" or remove the key";
    let slopes =
        [("initial.slope_x_urad", raw.initial.slope_x_urad), ("initial.slope_y_urad", raw.initial.slope_y_urad)];
    if let Some((key, value)) = slopes.iter().find_map(|(k, v)| v.map(|v| (*k, v))) {
        return Err(range(key, value, "µrad", WHY));
    }
    let tables = [
        ("touchdown", &raw.touchdown.a, &raw.touchdown.b),
        ("contact", &raw.contact.a, &raw.contact.b),
        ("amb", &raw.amb.a, &raw.amb.b),
    ];
    for (table, a, b) in tables {
        for (plane, own) in [("a", a), ("b", b)] {
            if let Some(own) = own {
                return Err(ConfigError::Range {
                    key: format!("{table}.{plane}"),
                    value: format!("a table of {} key(s)", own.len()),
                    unit: String::new(),
                    why: format!(
                        "per-plane tables ([{table}.a], [{table}.b]) are for the two-plane rotor and this scene is \
                         planar (rotor.model = \"planar\"): set rotor.model = \"two_plane\" or write the keys in [{table}]"
                    ),
                });
            }
        }
    }
    Ok(())
}

/// A per-plane table: the shared table `shared` (`[touchdown]`) with plane `plane`'s own keys
/// (`[touchdown.b]`) set over it, read as the same table.
pub(super) fn plane_table<T: serde::Serialize + serde::de::DeserializeOwned>(
    shared: &T,
    own: Option<&toml::Table>,
    name: &str,
) -> Result<T, ConfigError> {
    let parse = |message: String| ConfigError::Parse { path: name.to_string(), message };
    let mut table = toml::Table::try_from(shared).map_err(|e| parse(e.to_string()))?;
    table.remove("a");
    table.remove("b");
    if let Some(own) = own {
        if let Some(nested) = ["a", "b"].into_iter().find(|k| own.contains_key(*k)) {
            return Err(parse(format!("a plane's table holds keys, not another plane's table (`{nested}`)")));
        }
        for (key, value) in own {
            table.insert(key.clone(), value.clone());
        }
    }
    toml::Value::Table(table).try_into::<T>().map_err(|e| parse(e.to_string()))
}

/// The two-plane rotor of a scene (`rotor.model = "two_plane"`), validated: its geometry and
/// inertia from `[rotor]`, each plane's bearing from the shared tables and its own.
pub(in crate::config) fn two_plane_params(
    raw: &RawScene,
    r: &TwoPlaneKeys,
    whole: &Share,
) -> Result<two_plane::Params, ConfigError> {
    let mm = |key: &str, value: f64| finite(key, value, "mm");
    let za = mm("rotor.bearing_a_mm", r.bearing_a_mm.unwrap_or(BEARING_A_MM))?;
    let zb = mm("rotor.bearing_b_mm", r.bearing_b_mm.unwrap_or(BEARING_B_MM))?;
    const SIDES: &str = "bearing A lies on the −z side of the centre of mass (the origin of z) and bearing B on \
                         the +z side: the centre of mass is between the bearings";
    if za >= 0.0 {
        return Err(range("rotor.bearing_a_mm", za, "mm", &format!("must be < 0: {SIDES}")));
    }
    if zb <= 0.0 {
        return Err(range("rotor.bearing_b_mm", zb, "mm", &format!("must be > 0: {SIDES}")));
    }
    let ea = mm("rotor.end_a_mm", r.end_a_mm.unwrap_or(END_A_MM))?;
    let eb = mm("rotor.end_b_mm", r.end_b_mm.unwrap_or(END_B_MM))?;
    if ea > za {
        return Err(range(
            "rotor.end_a_mm",
            ea,
            "mm",
            &format!("must be <= rotor.bearing_a_mm = {za} mm: the bearing sits on the rotor"),
        ));
    }
    if eb < zb {
        return Err(range(
            "rotor.end_b_mm",
            eb,
            "mm",
            &format!("must be >= rotor.bearing_b_mm = {zb} mm: the bearing sits on the rotor"),
        ));
    }
    let sensor = |key: &str, value: f64| -> Result<f64, ConfigError> {
        let v = mm(key, value)?;
        if !(ea..=eb).contains(&v) {
            return Err(range(
                key,
                v,
                "mm",
                &format!("must lie on the rotor, between rotor.end_a_mm = {ea} mm and rotor.end_b_mm = {eb} mm"),
            ));
        }
        Ok(v)
    };
    let sa = sensor("rotor.sensor_a_mm", r.sensor_a_mm.unwrap_or(za))?;
    let sb = sensor("rotor.sensor_b_mm", r.sensor_b_mm.unwrap_or(zb))?;
    let transverse = positive(
        "rotor.transverse_inertia_kg_m2",
        r.transverse_inertia_kg_m2.unwrap_or(TRANSVERSE_INERTIA_KG_M2),
        "kg·m²",
    )?;
    let couple = non_negative("rotor.couple_unbalance_urad", r.couple_unbalance_urad.unwrap_or(0.0), "µrad")? * 1e-6;
    let couple_phase =
        finite("rotor.couple_unbalance_phase_deg", r.couple_unbalance_phase_deg.unwrap_or(0.0), "deg")?.to_radians();
    let stations = [za * 1e-3, zb * 1e-3];
    let sensors = [sa * 1e-3, sb * 1e-3];
    let plane = |i: usize| -> Result<two_plane::Plane, ConfigError> {
        let letter = ["a", "b"][i];
        let pick = |a: &Option<toml::Table>, b: &Option<toml::Table>| if i == 0 { a.clone() } else { b.clone() };
        let own = [
            pick(&raw.touchdown.a, &raw.touchdown.b),
            pick(&raw.contact.a, &raw.contact.b),
            pick(&raw.amb.a, &raw.amb.b),
        ];
        let td = plane_table(&raw.touchdown, own[0].as_ref(), &format!("touchdown.{letter}"))?;
        let ct = plane_table(&raw.contact, own[1].as_ref(), &format!("contact.{letter}"))?;
        let amb = plane_table(&raw.amb, own[2].as_ref(), &format!("amb.{letter}"))?;
        let mass = two_plane::load_share(whole.mass, stations, i);
        let fraction = mass / whole.mass;
        let spin = match whole.spin {
            Spin::Held => Spin::Held,
            Spin::Free { drive_gain, torque_limit } => {
                Spin::Free { drive_gain: drive_gain * fraction, torque_limit: torque_limit * fraction }
            }
        };
        let share = Share { mass, inertia: whole.inertia * fraction, spin, ..*whole };
        let keys = Keys { plane: Some((letter, [own[0].as_ref(), own[1].as_ref(), own[2].as_ref()])) };
        let params = bearing(&td, &ct, &amb, &raw.controller, &keys, &share)?;
        Ok(two_plane::Plane { station: stations[i], sensor: sensors[i], params })
    };
    Ok(two_plane::Params {
        gravity: whole.gravity,
        rotor: two_plane::Rotor {
            mass: whole.mass,
            transverse_inertia: transverse,
            polar_inertia: whole.inertia,
            eccentricity: whole.eccentricity,
            couple,
            couple_phase,
            speed: whole.speed,
            spin: whole.spin,
        },
        planes: [plane(0)?, plane(1)?],
    })
}
