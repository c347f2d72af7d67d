//! The one mapping from a run's rows to the recording's topics (issue 42): which trace column
//! goes to which topic and field, each topic's schema (a ROS 2 message definition, units in its
//! comments), and a row's message on each topic. `run.mcap` ([`super::mcap_file`]) and any live view take their
//! topics from here, so that a change of the rows (typed rows, new columns) changes this file
//! only.
//!
//! Each topic's message is a ROS 2 message (`ros2msg` schema, CDR encoding, which Foxglove,
//! Lichtblick and PlotJuggler all read) of `float64` fields: `t_s` (the row's time, s) and the
//! topic's fields, named like their `trace.csv` columns (plane B's without the `b_` prefix),
//! each the row's double itself, so a reader gets the trace's numbers bit for bit (NaN
//! included). A binary encoding rather than JSON: formatting each number as text (a first
//! version did) cost 45 % more CPU time than the run without a recording.

use crate::config::Scene;
use crate::trace::{Layout, Record};
use std::fmt::Write as _;

/// The trace's columns of a run of `scene`, in `trace.csv`'s order: the planar ones, plane B's
/// and the tilt's (two-plane), the coils' (amplifiers, 4 per plane), the magnets' (unipolar
/// amplifiers, 8 per plane), the mid-span's (a bending rotor). The same choice as
/// [`crate::trace::TraceWriter::create_with_columns`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Columns {
    layout: Layout,
}

impl Columns {
    /// The columns `trace.csv` has for a run of `scene`.
    pub fn of(scene: &Scene) -> Self {
        let layout = Layout {
            planes: scene.planes(),
            coils: scene.hardware.amplified(),
            magnets: scene.hardware.is_unipolar(),
            mid: scene.rotor.bends(),
        };
        Self { layout }
    }

    /// The columns' names, in order.
    pub fn names(&self) -> Vec<&'static str> {
        self.layout.names()
    }

    /// A row's values of these columns, in order, into `out` (cleared first); what a row does
    /// not hold is NaN, as in `trace.csv`.
    pub fn values(&self, r: &Record, out: &mut Vec<f64>) {
        out.clear();
        self.layout.put(r, &mut |v| out.push(v));
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
    /// The topic's schema, a ROS 2 message definition (`ros2msg`): `t_s` and each field a
    /// `float64`, each commented with its unit and `trace.csv` column.
    pub fn schema_text(&self) -> String {
        let mut text = format!(
            "# {}: one row of trace.csv (issue 42); each field's unit and column in its comment.\n",
            self.schema
        );
        text.push_str("float64 t_s  # t_s (s): simulated time, trace.csv column t_s\n");
        for f in &self.fields {
            let _ =
                writeln!(text, "float64 {}  # {} ({}): trace.csv column {}", f.name, f.name, unit(f.column), f.column);
        }
        if self.radius.is_some() {
            text.push_str("float64 radius_m  # radius_m (m): the rotor's radius, hypot of the x and y fields\n");
        }
        text
    }

    /// The topic's message of one row (`values` as [`Columns::values`] gives them), into `out`
    /// (cleared first): CDR, little-endian (the encapsulation header `00 01 00 00`, then each
    /// `float64` as its 8 bytes, which are 8-aligned after the header). Written by hand rather
    /// than through a CDR crate: a row of doubles is the whole of it, and the doubles go out as
    /// their bits, the trace's numbers exactly (NaN included), with nothing formatted per row.
    pub fn message(&self, values: &[f64], out: &mut Vec<u8>) {
        out.clear();
        out.extend_from_slice(&CDR_LE);
        out.extend_from_slice(&values[0].to_le_bytes());
        for f in &self.fields {
            out.extend_from_slice(&values[f.index].to_le_bytes());
        }
        if let Some((x, y)) = self.radius {
            out.extend_from_slice(&values[x].hypot(values[y]).to_le_bytes());
        }
    }
}

/// The CDR encapsulation header of a little-endian message (`CDR_LE`).
pub const CDR_LE: [u8; 4] = [0, 1, 0, 0];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_column_but_time_goes_to_exactly_one_topic() {
        let all = Columns { layout: Layout { planes: 2, coils: true, magnets: true, mid: true } };
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
    fn a_message_is_the_rows_doubles_after_the_cdr_header() {
        let topic = Topic {
            name: "/x".into(),
            schema: "plant.X",
            fields: vec![
                Field { name: "a".into(), column: "a_m", index: 1 },
                Field { name: "b".into(), column: "b_n", index: 2 },
            ],
            radius: Some((1, 2)),
        };
        let mut out = Vec::new();
        let values = [1.5e-4, 3.0, -4.0];
        topic.message(&values, &mut out);
        let mut want = vec![0u8, 1, 0, 0];
        for v in [1.5e-4f64, 3.0, -4.0, 5.0] {
            want.extend_from_slice(&v.to_le_bytes());
        }
        assert_eq!(out, want);
        let text = topic.schema_text();
        assert!(text.contains("float64 a  # a (m): trace.csv column a_m\n"), "{text}");
        assert!(text.contains("float64 b  # b (N): trace.csv column b_n\n"), "{text}");
        assert!(text.ends_with("float64 radius_m  # radius_m (m): the rotor's radius, hypot of the x and y fields\n"));
    }
}
