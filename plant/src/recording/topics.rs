//! The one mapping from a run's rows to the recording's topics (issue 42): which trace column
//! goes to which topic and field, each topic's JSON schema (units in its descriptions), and a
//! row's message on each topic. `run.mcap` ([`super::mcap_file`]) and any live view take their
//! topics from here, so that a change of the rows (typed rows, new columns) changes this file
//! only.
//!
//! Each topic's message is a JSON object: `t_s` (the row's time, s) and the topic's fields,
//! named like their `trace.csv` columns (plane B's without the `b_` prefix), with the same
//! numbers: shortest round-trip scientific notation (`{:e}`, as `trace.csv`), so a reader gets
//! the trace's doubles bit for bit; a non-finite value (a failed run's last row) is `null`,
//! which JSON has in place of NaN and infinities.

use crate::config::Scene;
use crate::trace::{
    Record, Trace, TraceB, TraceHw, TraceMagnets, TraceMid, WIDTH_B, WIDTH_HW, WIDTH_MAGNETS, WIDTH_MID,
};
use std::fmt::Write as _;

/// The trace's columns of a run of `scene`, in `trace.csv`'s order: the planar ones, plane B's
/// and the tilt's (two-plane), the coils' (amplifiers, 4 per plane), the magnets' (unipolar
/// amplifiers, 8 per plane), the mid-span's (a bending rotor). The same choice as
/// [`crate::trace::TraceWriter::create_with_columns`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Columns {
    b: usize,
    coils: usize,
    magnets: usize,
    mid: usize,
}

impl Columns {
    /// The columns `trace.csv` has for a run of `scene`.
    pub fn of(scene: &Scene) -> Self {
        let planes = scene.planes();
        Self {
            b: if planes == 2 { WIDTH_B } else { 0 },
            coils: if scene.hardware.amplified() { 4 * planes } else { 0 },
            magnets: if scene.hardware.is_unipolar() { 8 * planes } else { 0 },
            mid: if scene.rotor.bends() { WIDTH_MID } else { 0 },
        }
    }

    /// The columns' names, in order.
    pub fn names(&self) -> Vec<&'static str> {
        Trace::COLUMNS
            .iter()
            .chain(&TraceB::COLUMNS[..self.b])
            .chain(&TraceHw::COLUMNS[..self.coils])
            .chain(&TraceMagnets::COLUMNS[..self.magnets])
            .chain(&TraceMid::COLUMNS[..self.mid])
            .copied()
            .collect()
    }

    /// A row's values of these columns, in order, into `out` (cleared first); what a row does
    /// not hold is NaN, as in `trace.csv`.
    pub fn values(&self, r: &Record, out: &mut Vec<f64>) {
        out.clear();
        let b = r.b.unwrap_or([f64::NAN; WIDTH_B]);
        let hw = r.hw.unwrap_or([f64::NAN; WIDTH_HW]);
        let magnets = r.magnets.unwrap_or([f64::NAN; WIDTH_MAGNETS]);
        let mid = r.mid.unwrap_or([f64::NAN; WIDTH_MID]);
        out.extend_from_slice(&r.a);
        out.extend_from_slice(&b[..self.b]);
        out.extend_from_slice(&hw[..self.coils]);
        out.extend_from_slice(&magnets[..self.magnets]);
        out.extend_from_slice(&mid[..self.mid]);
    }
}

/// One field of a topic: its name in the message and the column it carries.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Field {
    /// Name in the message.
    pub name: String,
    /// The `trace.csv` column it carries.
    pub column: &'static str,
    /// Index of that column in [`Columns::values`].
    pub index: usize,
}

/// One topic of a recording: its name, its schema's name and its fields.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Topic {
    /// The topic (`/plane_a/rotor`, …).
    pub name: String,
    /// The schema's name (`plant.Rotor`, …): the same for both planes' topics of one kind.
    pub schema: &'static str,
    /// The message's fields after `t_s`, in column order.
    pub fields: Vec<Field>,
    /// The rotor's radius `radius_m` = hypot(x, y), last, from these two fields' columns (the
    /// rotor topics and the mid-span's): what the study plots and no column holds.
    pub radius: Option<(usize, usize)>,
}

/// Where a column goes: its topic (relative to the plane for a plane's column), its schema's
/// name, and its field name. `None` for `t_s`, which every message carries.
fn place(column: &str) -> Option<(String, &'static str, String)> {
    if column == "t_s" {
        return None;
    }
    // Plane B's columns are plane A's with the prefix `b_`; the tilt's and mid-span's have none.
    let (plane, name) = match column.strip_prefix("b_") {
        Some(rest) => ("b", rest),
        None => ("a", column),
    };
    let plane_topic = |kind: &str| format!("/plane_{plane}/{kind}");
    let (topic, schema) = match name {
        "dx_m" | "dy_m" | "vx_m_s" | "vy_m_s" => (plane_topic("rotor"), "plant.Rotor"),
        "xb_m" | "yb_m" | "vxb_m_s" | "vyb_m_s" | "race_speed_rad_s" => (plane_topic("race"), "plant.Race"),
        "contact_force_n" | "friction_force_n" | "ball_force_n" => (plane_topic("contact"), "plant.Contact"),
        "rotor_angle_rad" | "rotor_speed_rad_s" => ("/rotor/spin".into(), "plant.Spin"),
        "housing_x_m" | "housing_y_m" => ("/housing".into(), "plant.Housing"),
        n if n.starts_with("slope_") => ("/tilt".into(), "plant.Tilt"),
        n if n.starts_with("mid_") => ("/mid_span".into(), "plant.MidSpan"),
        // The commanded currents, the coils' real currents and voltages, each magnet's.
        _ => (plane_topic("coils"), "plant.Coils"),
    };
    Some((topic, schema, name.to_string()))
}

/// The topics of a recording with these columns, in the order their first column comes.
pub fn topics(columns: &Columns) -> Vec<Topic> {
    let mut topics: Vec<Topic> = Vec::new();
    for (index, column) in columns.names().into_iter().enumerate() {
        let Some((name, schema, field)) = place(column) else { continue };
        let field = Field { name: field, column, index };
        match topics.iter_mut().find(|t| t.name == name) {
            Some(t) => t.fields.push(field),
            None => topics.push(Topic { name, schema, fields: vec![field], radius: None }),
        }
    }
    for t in &mut topics {
        let index = |name: &str| t.fields.iter().find(|f| f.name == name).map(|f| f.index);
        t.radius = match t.schema {
            "plant.Rotor" => index("dx_m").zip(index("dy_m")),
            "plant.MidSpan" => index("mid_dx_m").zip(index("mid_dy_m")),
            _ => None,
        };
    }
    topics
}

/// The unit of a trace column, from its name's suffix (the trace's naming rule).
pub fn unit(column: &str) -> &'static str {
    const SUFFIXES: &[(&str, &str)] = &[
        ("_m_s", "m/s"),
        ("_rad_s", "rad/s"),
        ("_rad", "rad"),
        ("_m", "m"),
        ("_n", "N"),
        ("_a", "A"),
        ("_v", "V"),
        ("_s", "s"),
    ];
    SUFFIXES.iter().find(|(s, _)| column.ends_with(s)).map_or("1", |(_, u)| u)
}

impl Topic {
    /// The topic's JSON schema (draft 07): `t_s` and each field a number (`null` when not
    /// finite), each described with its `trace.csv` column and unit.
    pub fn schema_json(&self) -> String {
        let mut properties = serde_json::Map::new();
        properties.insert(
            "t_s".into(),
            serde_json::json!({"type": "number", "description": "Simulated time (s): trace.csv column t_s."}),
        );
        for f in &self.fields {
            let description =
                format!("{} ({}): trace.csv column {}; null when not finite.", f.name, unit(f.column), f.column);
            properties
                .insert(f.name.clone(), serde_json::json!({"type": ["number", "null"], "description": description}));
        }
        let mut required = vec!["t_s".to_string()];
        required.extend(self.fields.iter().map(|f| f.name.clone()));
        if self.radius.is_some() {
            let description = "radius_m (m): the rotor's radius, hypot of the x and y fields; null when not finite.";
            properties
                .insert("radius_m".into(), serde_json::json!({"type": ["number", "null"], "description": description}));
            required.push("radius_m".into());
        }
        serde_json::json!({
            "$schema": "http://json-schema.org/draft-07/schema#",
            "title": self.schema,
            "type": "object",
            "properties": properties,
            "required": required,
        })
        .to_string()
    }

    /// The topic's message of one row (`values` as [`Columns::values`] gives them), into `out`
    /// (cleared first). Written here rather than through serde_json so that each number is
    /// `trace.csv`'s own `{:e}` text, without a map built per row.
    pub fn message(&self, values: &[f64], out: &mut String) {
        out.clear();
        out.push_str("{\"t_s\":");
        number(values[0], out);
        for f in &self.fields {
            out.push_str(",\"");
            out.push_str(&f.name);
            out.push_str("\":");
            number(values[f.index], out);
        }
        if let Some((x, y)) = self.radius {
            out.push_str(",\"radius_m\":");
            number(values[x].hypot(values[y]), out);
        }
        out.push('}');
    }
}

/// A JSON number as `trace.csv` writes it (`{:e}`, valid JSON: `-4.3e-4`, `0e0`), or `null`.
fn number(v: f64, out: &mut String) {
    if v.is_finite() {
        let _ = write!(out, "{v:e}");
    } else {
        out.push_str("null");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_column_but_time_goes_to_exactly_one_topic() {
        let all = Columns { b: WIDTH_B, coils: 8, magnets: 16, mid: WIDTH_MID };
        let topics = topics(&all);
        let mut carried: Vec<&str> = topics.iter().flat_map(|t| t.fields.iter().map(|f| f.column)).collect();
        carried.sort_unstable();
        let mut names = all.names();
        names.retain(|c| *c != "t_s");
        names.sort_unstable();
        assert_eq!(carried, names);
        // Plane B's fields are named like plane A's.
        let a = topics.iter().find(|t| t.name == "/plane_a/rotor").unwrap();
        let b = topics.iter().find(|t| t.name == "/plane_b/rotor").unwrap();
        let names = |t: &Topic| t.fields.iter().map(|f| f.name.clone()).collect::<Vec<_>>();
        assert_eq!(names(a), ["dx_m", "dy_m", "vx_m_s", "vy_m_s"]);
        assert_eq!(names(a), names(b));
        assert_eq!(b.fields[0].column, "b_dx_m");
        assert_eq!(b.radius, Some((b.fields[0].index, b.fields[1].index)));
        let mid = topics.iter().find(|t| t.name == "/mid_span").unwrap();
        assert!(mid.radius.is_some());
        assert!(topics.iter().filter(|t| t.radius.is_some()).count() == 3);
    }

    #[test]
    fn units_follow_the_column_names() {
        assert_eq!(unit("vx_m_s"), "m/s");
        assert_eq!(unit("race_speed_rad_s"), "rad/s");
        assert_eq!(unit("slope_x_rad"), "rad");
        assert_eq!(unit("contact_force_n"), "N");
        assert_eq!(unit("b_iy_a"), "A");
        assert_eq!(unit("vx_coil_v"), "V");
        assert_eq!(unit("t_s"), "s");
    }

    #[test]
    fn a_message_is_json_with_the_trace_numbers() {
        let topic = Topic {
            name: "/x".into(),
            schema: "plant.X",
            fields: vec![
                Field { name: "a".into(), column: "a_m", index: 1 },
                Field { name: "b".into(), column: "b_m", index: 2 },
            ],
            radius: None,
        };
        let mut out = String::new();
        let values = [1.5e-4, 0.1 + 0.2, f64::NAN];
        topic.message(&values, &mut out);
        assert_eq!(out, "{\"t_s\":1.5e-4,\"a\":3.0000000000000004e-1,\"b\":null}");
        let parsed: serde_json::Value = serde_json::from_str(&out).unwrap();
        assert_eq!(parsed["a"].as_f64().unwrap().to_bits(), (0.1f64 + 0.2).to_bits());
    }
}
