//! The soak's sink: per-shock figures and the coarse envelope from the output
//! samples, and the files written as the soak goes (`soak.csv`,
//! `envelope.csv`, `rss.csv`), each in whole rows.

use super::monitor::{Envelope, EnvelopeRow, ShockFigures, ShockTracker};
use super::programme::PlannedShock;
use crate::row_file::RowFile;
use crate::run::Sink;
use crate::snapshot::Snapshot;
use crate::trace::Record;
use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

/// The sink: per-shock figures and the envelope, each written as it closes;
/// both files are written out at each shock's end.
pub struct SoakSink<'a> {
    pub(crate) tracker: ShockTracker,
    pub(crate) envelope: Envelope,
    pub(crate) planned: &'a [PlannedShock],
    /// Each bearing plane's clear radius (m): a fraction of its own air gap.
    pub(crate) clear_radius: Vec<f64>,
    pub(crate) figures: Vec<ShockFigures>,
    pub(crate) soak_csv: RowFile,
    pub(crate) envelope_csv: RowFile,
    pub(crate) error: Option<std::io::Error>,
    /// Output rows taken so far (counted from the run's first: a resumed soak starts at its
    /// checkpoint's).
    pub(crate) rows: u64,
    /// Where the checkpoints go.
    pub(crate) checkpoints: Checkpoints,
    /// The live view (`plant soak --live`).
    pub(crate) live: Option<crate::live::LiveSink>,
    /// The recording (`soak.mcap`, `plant soak --mcap`).
    pub(crate) mcap: Option<crate::recording::mcap_file::McapSink>,
}

/// The plant's snapshots at the shocks' starts, handed over by the loop's hooks, and the
/// checkpoints the sink writes from them ([`super::checkpoint`]).
pub(crate) struct Checkpoints {
    /// The soak's folder.
    pub(crate) dir: PathBuf,
    /// The resolved programme ([`super::checkpoint::fingerprint`]).
    pub(crate) programme: serde_json::Value,
    /// Snapshots taken by the loop, not yet written (the loop's hooks push them; the sink,
    /// on the loop's thread or on the row thread of a realtime soak, takes each once it has
    /// every row up to the snapshot's time).
    pub(crate) queue: Arc<Mutex<VecDeque<Snapshot>>>,
    /// The first checkpoint that could not be written.
    pub(crate) error: Option<anyhow::Error>,
}

impl Checkpoints {
    /// The snapshot whose rows the sink has all taken, `rows` of them, if one is queued.
    fn due(&self, rows: u64) -> Option<Snapshot> {
        let mut queue = self.queue.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let mut due = None;
        while queue.front().is_some_and(|s| s.next_output <= rows) {
            due = queue.pop_front().filter(|s| s.next_output == rows);
        }
        due
    }
}

crate::table::text_row! {
    /// A row of `soak.csv`: a shock as planned beside its window's figures.
    pub struct SoakFields {
        /// Shock index (0-based).
        index,
        /// The shock's start (s).
        start_s,
        /// Peak acceleration (g).
        peak_g,
        /// Direction (degrees).
        direction_deg,
        /// Duration (s).
        duration_s,
        /// Recovered (1) or not (0).
        recovered,
        /// Recovery time (s; NaN if not recovered).
        recovery_s,
        /// Largest normal force (N).
        max_contact_force_n,
        /// Time in contact (s).
        contact_time_s,
        /// Transitions into contact.
        contact_episodes,
        /// Largest radius (m).
        max_radius_m,
        /// The window ran to its planned end (1) or not (0).
        complete,
    }
}

/// The fields of a shock's `soak.csv` row (`p` the shock as planned): what a resume compares
/// the file's rows with.
pub(crate) fn shock_row(f: &ShockFigures, p: &PlannedShock) -> Vec<String> {
    SoakFields {
        index: f.index.to_string(),
        start_s: f.start_s.to_string(),
        peak_g: p.peak_g.to_string(),
        direction_deg: p.direction_deg.to_string(),
        duration_s: p.duration_s.to_string(),
        recovered: u8::from(f.recovered).to_string(),
        recovery_s: f.recovery_s.to_string(),
        max_contact_force_n: f.max_contact_force_n.to_string(),
        contact_time_s: f.contact_time_s.to_string(),
        contact_episodes: f.contact_episodes.to_string(),
        max_radius_m: f.max_radius_m.to_string(),
        complete: u8::from(f.complete).to_string(),
    }
    .into_fields()
}

impl SoakSink<'_> {
    fn write_shock(&mut self, f: ShockFigures) {
        let row = shock_row(&f, &self.planned[f.index]);
        let written =
            self.soak_csv.row(&row).and_then(|()| self.soak_csv.flush()).and_then(|()| self.envelope_csv.flush());
        self.keep_error(written);
        self.figures.push(f);
    }

    fn write_bin(&mut self, r: EnvelopeRow) {
        let row = [r.t_s.to_string(), format!("{:e}", r.max_radius_m), format!("{:e}", r.max_contact_force_n)];
        let written = self.envelope_csv.row(&row);
        self.keep_error(written);
    }

    fn keep_error(&mut self, r: std::io::Result<()>) {
        if let Err(e) = r {
            self.error.get_or_insert(e);
        }
    }

    /// Writes the checkpoint of `plant`, the sink's state now.
    fn checkpoint(&mut self, plant: Snapshot) {
        let written = (|| -> anyhow::Result<()> {
            let checkpoint = super::checkpoint::Checkpoint {
                format: super::checkpoint::FORMAT,
                programme: self.checkpoints.programme.clone(),
                plant,
                rows: self.rows,
                tracker: self.tracker.clone(),
                envelope: self.envelope.clone(),
                figures: self.figures.clone(),
                soak_csv_bytes: self.soak_csv.written()?,
                envelope_csv_bytes: self.envelope_csv.written()?,
                seal: String::new(),
            };
            checkpoint.write(&self.checkpoints.dir)
        })();
        if let Err(e) = written {
            self.checkpoints.error.get_or_insert(e);
        }
    }

    /// The checkpoint of the snapshot queued for the rows taken so far, if any.
    fn take_checkpoint(&mut self) {
        if let Some(plant) = self.checkpoints.due(self.rows) {
            self.checkpoint(plant);
        }
    }

    /// Closes the window and the bin in progress, and writes everything out.
    pub fn finish(&mut self) {
        // A soak stopped right after a snapshot: its checkpoint, before the windows close.
        self.take_checkpoint();
        if let Some(r) = self.envelope.finish() {
            self.write_bin(r);
        }
        if let Some(f) = self.tracker.finish() {
            self.write_shock(f);
        }
        let flushed = self.soak_csv.flush().and_then(|()| self.envelope_csv.flush());
        self.keep_error(flushed);
    }
}

impl Sink for SoakSink<'_> {
    fn tick(&mut self, sample: &controller::RotorSample, command: &[f64; controller::ROTOR_AXES]) {
        crate::live::tick(&mut self.mcap, &mut self.live, sample, command);
    }

    fn wants_ticks(&self) -> bool {
        crate::live::wants_ticks(&self.mcap, &self.live)
    }

    fn sample(&mut self, record: &Record) {
        if let Some(l) = &mut self.live {
            l.push(record);
        }
        if let Some(m) = &mut self.mcap {
            m.push(record);
        }
        self.take_checkpoint();
        self.rows += 1;
        // Of a two-plane rotor: the larger radius and contact force of the planes, and clear
        // while each plane is inside its own clear radius.
        let of = |r: &crate::trace::Row| (r.motion.dx_m.hypot(r.motion.dy_m), r.loads.contact_force_n);
        let (mut radius, mut force) = of(&record.a);
        let mut within = radius < self.clear_radius[0];
        if record.planes() == 2 {
            let (rb, fb) = of(&record.plane(1));
            within &= rb < self.clear_radius[1];
            (radius, force) = (radius.max(rb), force.max(fb));
        }
        let t = record.a.t_s;
        if let Some(r) = self.envelope.sample(t, radius, force) {
            self.write_bin(r);
        }
        let mut closed = None;
        self.tracker.sample_with(t, radius, force, within, &mut |f| closed = Some(f));
        if let Some(f) = closed {
            self.write_shock(f);
        }
    }
}

crate::table::text_row! {
    /// A row of `rss.csv` as written: [`RssSample`]'s fields formatted.
    pub struct RssFields {
        /// Simulated time (s).
        t_sim_s,
        /// Wall time since the soak started (s, three decimals).
        wall_s,
        /// The plant's resident memory (KiB; empty: unknown).
        plant_rss_kib,
        /// The controller's resident memory (KiB; empty: unknown).
        controller_rss_kib,
    }
}

/// One row of `rss.csv`.
#[derive(Clone, Copy, Debug)]
pub struct RssSample {
    /// Simulated time (s).
    pub t_s: f64,
    /// Wall time since the soak started (s).
    pub wall_s: f64,
    /// The plant's resident memory (KiB), where `/proc` tells.
    pub plant_kib: Option<u64>,
    /// The controller's resident memory (KiB), while it is known.
    pub controller_kib: Option<u64>,
}

impl RssSample {
    /// The row of `rss.csv` (an unknown size is an empty field).
    pub fn fields(&self) -> Vec<String> {
        let show = |v: Option<u64>| v.map_or(String::new(), |v| v.to_string());
        RssFields {
            t_sim_s: self.t_s.to_string(),
            wall_s: format!("{:.3}", self.wall_s),
            plant_rss_kib: show(self.plant_kib),
            controller_rss_kib: show(self.controller_kib),
        }
        .into_fields()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_row_file_holds_its_header_at_once_and_whole_rows_only() {
        let dir = crate::util::scratch("rowfile");
        let path = dir.join("x.csv");
        let mut f = RowFile::create(&path, &["a", "b"]).unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "a,b\n");
        f.row(["1", "2.5"]).unwrap();
        // Pending until flushed: the file never holds part of a row.
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "a,b\n");
        f.flush().unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "a,b\n1,2.5\n");
        for i in 0..10_000 {
            f.row([i.to_string(), "0.123456789".to_string()]).unwrap();
            let text = std::fs::read_to_string(&path).unwrap();
            assert!(text.ends_with('\n'), "a torn row after {i} rows");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
