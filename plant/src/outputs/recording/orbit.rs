//! The orbit at each bearing with its clearance circle, as a topic a viewer's x-y plot draws
//! (issue 42 item 3, the layout's orbit panels): `/plane_a/orbit` (and `/plane_b/orbit`), every
//! 1/[`RATE_HZ`] s of simulated time, holding the rotor's last [`WINDOW_S`] of rows' positions
//! relative to the housing (`dx_m`, `dy_m` of the rows) and the bearing's clearance circle.
//!
//! Why a topic of its own: Lichtblick's and Foxglove's Plot panel draws y against x only with
//! one x path for all its series, pairing the series' values with the x values by their index;
//! a circle needs x values of its own. So one message carries both polylines over one x array:
//! `x_m` is the window's x then the circle's, `orbit_y_m` the window's y then NaN,
//! `clearance_y_m` NaN then the circle's y; a NaN is a gap in the panel's line. The panel's
//! "x-axis: path (current)" mode (`currentCustom`) draws the latest message: a scope's orbit
//! display that follows the playback or the live run. Pure: rows in, messages out.

use super::topics::CDR_LE;
use crate::config::Scene;
use crate::trace::Record;
use std::collections::VecDeque;

/// The simulated time an orbit message spans (s): a few turns of a rotor at speed.
pub const WINDOW_S: f64 = 0.02;
/// Orbit messages per simulated second.
pub const RATE_HZ: f64 = 50.0;
/// Most points of the window in a message: its rows (20 ms of rows: 400 at the default 20 kHz
/// output) are thinned to this (every 2nd of those 400).
pub const MAX_POINTS: usize = 200;
/// Points of the clearance circle: 72 segments, the first point repeated to close it.
pub const CIRCLE_POINTS: usize = 73;

/// The schema's name (`plant_msgs/msg/Orbit` in the file).
pub const SCHEMA: &str = "plant.Orbit";

/// The orbit's schema, a ROS 2 message definition (units in the comments).
pub const SCHEMA_TEXT: &str = "\
# plant.Orbit: the rotor's orbit at a bearing over its last 20 ms relative to the housing, with the bearing's clearance circle, for an x-y plot (issue 42).
float64 t_s  # t_s (s): simulated time of the newest point
float64 clearance_m  # clearance_m (m): the bearing's radial clearance, the circle's radius
float64[] x_m  # x_m (m): the orbit's x (trace.csv column dx_m, oldest first), then the circle's x
float64[] orbit_y_m  # orbit_y_m (m): the orbit's y (trace.csv column dy_m), then NaN (a gap) for the circle's points
float64[] clearance_y_m  # clearance_y_m (m): NaN for the orbit's points, then the circle's y
";

/// One bearing plane's window.
#[derive(Clone, Debug)]
struct Window {
    topic: String,
    clearance_m: f64,
    points: VecDeque<(f64, f64)>,
}

/// The orbit windows of a run, one per bearing plane.
#[derive(Clone, Debug)]
pub struct Orbits {
    planes: Vec<Window>,
    /// Rows a window holds.
    rows: usize,
    /// Every `stride`-th row of the window goes in a message.
    stride: usize,
    rate_hz: f64,
    last_period: Option<f64>,
    last_t: f64,
}

impl Orbits {
    /// The windows of a run of `scene`, a message every 1/`rate_hz` s of simulated time.
    pub fn new(scene: &Scene, rate_hz: f64) -> Self {
        let rows = ((WINDOW_S / scene.output_interval).round() as usize).max(2);
        let stride = rows.div_ceil(MAX_POINTS);
        let planes = (0..scene.planes())
            .map(|i| Window {
                topic: format!("/plane_{}/orbit", ["a", "b"][i.min(1)]),
                clearance_m: scene.plane(i).contact.gap,
                points: VecDeque::with_capacity(rows),
            })
            .collect();
        Self { planes, rows, stride, rate_hz, last_period: None, last_t: 0.0 }
    }

    /// The topics' names, in plane order.
    pub fn topics(&self) -> impl Iterator<Item = &str> {
        self.planes.iter().map(|w| w.topic.as_str())
    }

    /// Takes a row; true if it opens a period of the orbit's rate (its messages are due): the
    /// first row at or after each multiple of 1/rate.
    pub fn row(&mut self, r: &Record) -> bool {
        for (i, w) in self.planes.iter_mut().enumerate() {
            if w.points.len() == self.rows {
                w.points.pop_front();
            }
            let m = r.plane(i).motion;
            w.points.push_back((m.dx_m, m.dy_m));
        }
        self.last_t = r.t_s();
        let k = period(self.last_t, self.rate_hz);
        let due = self.last_period.is_none_or(|last| k > last);
        if due {
            self.last_period = Some(k);
        }
        due
    }

    /// Plane `i`'s message at the last row, into `out` (cleared first): CDR, little-endian.
    pub fn message(&self, i: usize, out: &mut Vec<u8>) {
        let w = &self.planes[i];
        // The newest row always, then every `stride`-th before it; oldest first.
        let n = w.points.len();
        let first = (n - 1) % self.stride;
        let orbit: Vec<(f64, f64)> = w.points.iter().skip(first).step_by(self.stride).copied().collect();
        let circle: Vec<(f64, f64)> = (0..CIRCLE_POINTS)
            .map(|k| {
                let a = std::f64::consts::TAU * (k % (CIRCLE_POINTS - 1)) as f64 / (CIRCLE_POINTS - 1) as f64;
                (w.clearance_m * a.cos(), w.clearance_m * a.sin())
            })
            .collect();
        out.clear();
        out.extend_from_slice(&CDR_LE);
        out.extend_from_slice(&self.last_t.to_le_bytes());
        out.extend_from_slice(&w.clearance_m.to_le_bytes());
        let x = orbit.iter().chain(&circle).map(|p| p.0);
        let orbit_y = orbit.iter().map(|p| p.1).chain(circle.iter().map(|_| f64::NAN));
        let clearance_y = orbit.iter().map(|_| f64::NAN).chain(circle.iter().map(|p| p.1));
        let len = orbit.len() + circle.len();
        sequence(out, len, x);
        sequence(out, len, orbit_y);
        sequence(out, len, clearance_y);
    }
}

/// A CDR `float64[]`: its length (`uint32`, 4-aligned), then the doubles (8-aligned). The
/// alignment counts from the end of the 4-byte encapsulation header.
fn sequence(out: &mut Vec<u8>, len: usize, values: impl Iterator<Item = f64>) {
    align(out, 4);
    out.extend_from_slice(&u32::try_from(len).unwrap_or(u32::MAX).to_le_bytes());
    if len > 0 {
        align(out, 8);
    }
    for v in values {
        out.extend_from_slice(&v.to_le_bytes());
    }
}

fn align(out: &mut Vec<u8>, to: usize) {
    while !(out.len() - CDR_LE.len()).is_multiple_of(to) {
        out.push(0);
    }
}

/// The live period a row at `t_s` falls in at `rate_hz`: the row is sent if it is the first
/// of its period, i.e. the first row at or after each multiple of 1/`rate_hz`. The 1e-9
/// keeps a row whose time is a multiple of the period, up to rounding, in that period.
pub fn period(t_s: f64, rate_hz: f64) -> f64 {
    (t_s * rate_hz + 1e-9).floor()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::Row;

    fn orbits(rows: usize, stride: usize, gap: f64) -> Orbits {
        let planes = vec![Window { topic: "/plane_a/orbit".into(), clearance_m: gap, points: VecDeque::new() }];
        Orbits { planes, rows, stride, rate_hz: 1000.0, last_period: None, last_t: 0.0 }
    }

    fn row(t: f64, x: f64, y: f64) -> Record {
        let mut r = Row { t_s: t, ..Row::default() };
        r.motion.dx_m = x;
        r.motion.dy_m = y;
        Record::planar(r)
    }

    /// Decodes a message by CDR's rules, written here from the layout (not the writer).
    fn decode(bytes: &[u8]) -> (f64, f64, Vec<Vec<f64>>) {
        let f = |at: usize| f64::from_le_bytes(bytes[at..at + 8].try_into().unwrap());
        let (t, c) = (f(4), f(12));
        // After the header (4 bytes) and two doubles: offset 16 from the body's start, 4-aligned.
        let mut at = 20;
        let mut arrays = Vec::new();
        for _ in 0..3 {
            while (at - 4) % 4 != 0 {
                at += 1;
            }
            let n = u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
            at += 4;
            while (at - 4) % 8 != 0 {
                at += 1;
            }
            arrays.push((0..n).map(|k| f(at + 8 * k)).collect());
            at += 8 * n;
        }
        assert_eq!(at, bytes.len());
        (t, c, arrays)
    }

    #[test]
    fn a_message_holds_the_thinned_window_then_the_circle_with_gaps() {
        // A window of 5 rows, every 2nd in a message: of rows 0..7 the last 5 (2..6), of which
        // 6, 4, 2 (the newest always).
        let mut o = orbits(5, 2, 1e-4);
        let due: Vec<bool> = (0..7).map(|k| o.row(&row(k as f64 * 5e-4, k as f64, -(k as f64)))).collect();
        // 1 kHz: rows at 0, 0.5, 1, …, 3 ms open a period at 0, 1, 2, 3 ms.
        assert_eq!(due, [true, false, true, false, true, false, true]);
        let mut bytes = Vec::new();
        o.message(0, &mut bytes);
        let (t, c, arrays) = decode(&bytes);
        assert_eq!((t, c), (6.0 * 5e-4, 1e-4));
        let n = 3 + CIRCLE_POINTS;
        assert!(arrays.iter().all(|a| a.len() == n));
        assert_eq!(arrays[0][..3], [2.0, 4.0, 6.0]);
        assert_eq!(arrays[1][..3], [-2.0, -4.0, -6.0]);
        assert!(arrays[1][3..].iter().all(|v| v.is_nan()));
        assert!(arrays[2][..3].iter().all(|v| v.is_nan()));
        // The circle: radius 1e-4 at every point, from (r, 0) a quarter turn every 18 points,
        // closed.
        for k in 0..CIRCLE_POINTS {
            let (x, y) = (arrays[0][3 + k], arrays[2][3 + k]);
            assert!((x.hypot(y) - 1e-4).abs() < 1e-18, "point {k}: {x}, {y}");
        }
        assert_eq!((arrays[0][3], arrays[2][3]), (1e-4, 0.0));
        assert!((arrays[0][3 + 18]).abs() < 1e-18 && (arrays[2][3 + 18] - 1e-4).abs() < 1e-18);
        assert_eq!((arrays[0][3 + 72], arrays[2][3 + 72]), (1e-4, 0.0));
    }
}
