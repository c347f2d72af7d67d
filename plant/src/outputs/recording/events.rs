//! The run's events as log lines of a recording (`foxglove.Log` on `/events`): each shock's
//! start and each plane's contact onsets as the rows pass them, then, from the summary, the
//! run's status, its motion mode, and a co-simulation's deadline misses and reconnections.
//! Pure: rows and the summary in, events out.

use crate::config::Scene;
use crate::summary::Summary;
use crate::trace::Record;

/// Most contact onsets logged per plane: a rubbing rotor can touch at every other row, and a
/// log is for a reader; the last one logged says that more followed.
pub const MAX_ONSETS: usize = 1000;

/// A `foxglove.Log` level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    /// `INFO` (2).
    Info = 2,
    /// `WARNING` (3).
    Warning = 3,
    /// `ERROR` (4).
    Error = 4,
}

/// One log line at a simulated time.
#[derive(Clone, Debug, PartialEq)]
pub struct Event {
    /// Simulated time (s).
    pub t_s: f64,
    /// Its level.
    pub level: Level,
    /// The text.
    pub message: String,
}

/// The events seen in the rows so far.
#[derive(Clone, Debug)]
pub struct Events {
    /// Shock starts (s), ascending, with their 1-based number.
    shocks: Vec<(f64, usize)>,
    next_shock: usize,
    /// Per plane: in contact at the last row, onsets seen.
    contact: Vec<(bool, usize)>,
    last_t: f64,
}

impl Events {
    /// The events of a run of `scene`.
    pub fn new(scene: &Scene) -> Self {
        let mut shocks: Vec<(f64, usize)> =
            scene.base.shocks.iter().enumerate().map(|(i, s)| (s.start, i + 1)).collect();
        shocks.sort_by(|a, b| a.0.total_cmp(&b.0));
        Self { shocks, next_shock: 0, contact: vec![(false, 0); scene.planes()], last_t: 0.0 }
    }

    /// The events at or before this row, into `out`.
    pub fn row(&mut self, r: &Record, out: &mut Vec<Event>) {
        let t = r.a.t_s;
        self.last_t = t;
        let count = self.shocks.len();
        while let Some(&(start, n)) = self.shocks.get(self.next_shock).filter(|(s, _)| *s <= t) {
            out.push(Event {
                t_s: t,
                level: Level::Info,
                message: format!("shock {n} of {count} starts (t = {start} s)"),
            });
            self.next_shock += 1;
        }
        let planes = self.contact.len();
        for (i, (touching, onsets)) in self.contact.iter_mut().enumerate() {
            let now = r.plane(i).loads.contact_force_n > 0.0;
            if now && !*touching {
                *onsets += 1;
                let plane = if planes == 2 { ["plane A: ", "plane B: "][i] } else { "" };
                if *onsets < MAX_ONSETS {
                    out.push(Event { t_s: t, level: Level::Info, message: format!("{plane}contact onset {onsets}") });
                } else if *onsets == MAX_ONSETS {
                    let message = format!("{plane}contact onset {onsets}; later onsets are not logged");
                    out.push(Event { t_s: t, level: Level::Info, message });
                }
            }
            *touching = now;
        }
    }

    /// The run's end, from its summary, at the last row's time.
    pub fn end(&self, summary: &Summary) -> Vec<Event> {
        let t_s = self.last_t;
        let mut out = Vec::new();
        let status = serde_json::to_value(summary.status).ok().and_then(|v| v.as_str().map(String::from));
        let status = status.unwrap_or_default();
        let (level, message) = match &summary.error {
            Some(e) => (Level::Error, format!("run {status}: {e}")),
            None => (Level::Info, format!("run {status}")),
        };
        out.push(Event { t_s, level, message });
        let mode = |a: &crate::analysis::Analysis| {
            serde_json::to_value(a.post_shock_mode).ok().and_then(|v| v.as_str().map(String::from)).unwrap_or_default()
        };
        let message = match &summary.planes {
            Some(p) => {
                format!("motion after the shock: plane A {}, plane B {}", mode(&p.a.analysis), mode(&p.b.analysis))
            }
            None => format!("motion after the shock: {}", mode(&summary.analysis)),
        };
        out.push(Event { t_s, level: Level::Info, message });
        if let Some(c) = &summary.cosim {
            let level = if c.deadline_misses > 0 { Level::Warning } else { Level::Info };
            let message = format!(
                "{} co-simulation: {} deadline misses ({:.3} %), longest burst {}",
                c.mode,
                c.deadline_misses,
                100.0 * c.deadline_miss_fraction,
                c.longest_miss_burst
            );
            out.push(Event { t_s, level, message });
            if c.sessions > 1 {
                let message = format!("the controller was lost and reconnected {} times", c.sessions - 1);
                out.push(Event { t_s, level: Level::Warning, message });
            }
        }
        out
    }
}

/// The `foxglove.Log` JSON schema (Foxglove's published one, the fields a viewer reads).
pub const LOG_SCHEMA: &str = r#"{"$schema":"http://json-schema.org/draft-07/schema#","title":"foxglove.Log","description":"A log message","type":"object","properties":{"timestamp":{"type":"object","title":"time","properties":{"sec":{"type":"integer","minimum":0},"nsec":{"type":"integer","minimum":0,"maximum":999999999}},"description":"Timestamp of log message (simulated time)"},"level":{"title":"foxglove.LogLevel","description":"Log level: 0 UNKNOWN, 1 DEBUG, 2 INFO, 3 WARNING, 4 ERROR, 5 FATAL","oneOf":[{"title":"UNKNOWN","const":0},{"title":"DEBUG","const":1},{"title":"INFO","const":2},{"title":"WARNING","const":3},{"title":"ERROR","const":4},{"title":"FATAL","const":5}]},"message":{"type":"string","description":"Log message"},"name":{"type":"string","description":"Process or node name"},"file":{"type":"string","description":"Filename"},"line":{"type":"integer","minimum":0,"description":"Line number in the file"}}}"#;

impl Event {
    /// The event as a `foxglove.Log` JSON message; `ns` its time in nanoseconds.
    pub fn to_log_json(&self, ns: u64) -> String {
        serde_json::json!({
            "timestamp": {"sec": ns / 1_000_000_000, "nsec": ns % 1_000_000_000},
            "level": self.level as u8,
            "message": self.message,
            "name": "plant",
            "file": "",
            "line": 0,
        })
        .to_string()
    }
}
