//! Online per-shock figures of a soak, from the output samples (rotor radius
//! relative to the housing and rotor–race normal force), in constant memory.
//!
//! Shock `j` owns the window `[s_j, s_{j+1})` (the last one ends with the
//! run). In its window:
//!
//! - **contact**: a sample with normal force `> 0`; `contact_time_s` is the
//!   number of contact samples times the sample interval, `contact_episodes`
//!   the number of transitions into contact, `max_contact_force_n` the
//!   largest sampled force;
//! - **clear**: no contact and radius `< clear_radius`;
//! - **recovered**: the samples from some time `c` to the window's last
//!   sample are all clear, and that last sample is at least `hold` after `c`;
//!   `recovery_s = max(c − s_j, 0)`: from the shock's start to the start of
//!   that final clear stretch (0 when the rotor never left the clear zone).
//!
//! Samples are taken at the output rate, so contacts shorter than one sample
//! interval can be missed and times are resolved to one interval.

use serde::{Deserialize, Serialize};

/// A NaN written as JSON `null` (as `serde_json` writes one) and read back as NaN: the
/// `recovery_s` of a shock not recovered, in `soak.json` and in a soak's checkpoint.
mod nan_as_null {
    pub fn serialize<S: serde::Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        if v.is_nan() {
            s.serialize_none()
        } else {
            s.serialize_f64(*v)
        }
    }

    pub fn deserialize<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Ok(<Option<f64> as serde::Deserialize>::deserialize(d)?.unwrap_or(f64::NAN))
    }
}

/// The figures of one shock's window.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShockFigures {
    /// Shock index (0-based).
    pub index: usize,
    /// Window start: the shock's start (s).
    pub start_s: f64,
    /// Time of the window's last sample (s).
    pub end_s: f64,
    /// Recovered before the window's end (see the module docs).
    pub recovered: bool,
    /// Shock start to the start of the final clear stretch (s); NaN if not recovered.
    #[serde(with = "nan_as_null")]
    pub recovery_s: f64,
    /// Largest rotor–race normal force in the window (N).
    pub max_contact_force_n: f64,
    /// Time in contact (s).
    pub contact_time_s: f64,
    /// Transitions into contact.
    pub contact_episodes: u64,
    /// Largest rotor radius relative to the housing (m).
    pub max_radius_m: f64,
    /// The window ran to its planned end (false: the run stopped inside it).
    pub complete: bool,
}

/// Accumulates [`ShockFigures`] window by window.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ShockTracker {
    starts: Vec<f64>,
    end: f64,
    clear_radius: f64,
    hold: f64,
    dt: f64,
    /// Window in progress (`None` before the first shock).
    current: Option<usize>,
    acc: Acc,
    /// Start of the current clear stretch.
    clear_since: Option<f64>,
    in_contact: bool,
    last_t: f64,
}

#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
struct Acc {
    max_force: f64,
    contact_samples: u64,
    episodes: u64,
    max_radius: f64,
}

impl ShockTracker {
    /// Tracker for shocks starting at `starts` (ascending, s) in a run ending at `end` (s),
    /// sampled every `dt` (s); clear below `clear_radius` (m), recovered after `hold` (s).
    pub fn new(starts: Vec<f64>, end: f64, dt: f64, clear_radius: f64, hold: f64) -> Self {
        Self {
            starts,
            end,
            clear_radius,
            hold,
            dt,
            current: None,
            acc: Acc::default(),
            clear_since: None,
            in_contact: false,
            last_t: 0.0,
        }
    }

    /// One sample at `t` (s): rotor radius (m) and contact normal force (N). Each window that
    /// this sample closes is passed to `closed`.
    pub fn sample(&mut self, t: f64, radius: f64, force: f64, closed: &mut dyn FnMut(ShockFigures)) {
        let clear = radius < self.clear_radius;
        self.sample_with(t, radius, force, clear, closed);
    }

    /// [`ShockTracker::sample`] with the radius test made by the caller: `within` is true when
    /// the rotor is inside its clear radius (each bearing plane inside its own, for a rotor of
    /// two planes with different gaps), and `radius` the largest radius, for the figures.
    pub fn sample_with(&mut self, t: f64, radius: f64, force: f64, within: bool, closed: &mut dyn FnMut(ShockFigures)) {
        // Windows that start at or before t close the previous one.
        loop {
            let next = self.current.map_or(0, |j| j + 1);
            if next >= self.starts.len() || t < self.starts[next] {
                break;
            }
            if let Some(j) = self.current {
                closed(self.close(j, true));
            }
            self.current = Some(next);
            self.acc = Acc::default();
        }
        let contact = force > 0.0;
        if contact && !self.in_contact && self.current.is_some() {
            self.acc.episodes += 1;
        }
        self.in_contact = contact;
        if contact || !within || !radius.is_finite() {
            self.clear_since = None;
        } else if self.clear_since.is_none() {
            self.clear_since = Some(t);
        }
        if self.current.is_some() {
            let a = &mut self.acc;
            a.max_force = a.max_force.max(force);
            a.max_radius = a.max_radius.max(radius);
            a.contact_samples += u64::from(contact);
        }
        self.last_t = t;
    }

    /// Why this tracker, read from a checkpoint, cannot go on as `fresh` (the one the programme
    /// makes) would: a setting that differs, or a window that is not one of the programme's
    /// shocks (an edited checkpoint; `plant soak --resume` refuses it before it touches a file).
    pub fn check_resumable(&self, fresh: &ShockTracker) -> Result<(), String> {
        let same = |a: f64, b: f64| a.to_bits() == b.to_bits();
        let settings = [
            ("end", self.end, fresh.end),
            ("dt", self.dt, fresh.dt),
            ("clear_radius", self.clear_radius, fresh.clear_radius),
            ("hold", self.hold, fresh.hold),
        ];
        if let Some((key, saved, now)) = settings.iter().find(|(_, a, b)| !same(*a, *b)) {
            return Err(format!("tracker.{key} is {saved:?}, the programme's is {now:?}"));
        }
        if self.starts.len() != fresh.starts.len() || !self.starts.iter().zip(&fresh.starts).all(|(a, b)| same(*a, *b))
        {
            return Err(format!(
                "tracker.starts has {} shock starts, not the programme's {} ({:?})",
                self.starts.len(),
                fresh.starts.len(),
                fresh.starts
            ));
        }
        match self.current {
            Some(j) if j >= self.starts.len() => Err(format!(
                "tracker.current = {j}: the programme has {} shocks (0 to {})",
                self.starts.len(),
                self.starts.len().saturating_sub(1)
            )),
            _ if !(self.last_t.is_finite() && self.clear_since.is_none_or(f64::is_finite)) => {
                Err(format!("tracker.last_t = {:?}, clear_since = {:?}: not times", self.last_t, self.clear_since))
            }
            _ => Ok(()),
        }
    }

    /// Why this tracker, read from a checkpoint (already [`ShockTracker::check_resumable`]),
    /// cannot be the one that took `rows` output rows, the last at the plant's time `t_s`,
    /// having closed `closed` windows: each field's value against those (issue 40 item 4).
    pub fn check_at(&self, rows: u64, t_s: f64, closed: usize) -> Result<(), String> {
        let tiny = 1e-9 * self.dt;
        // The last row taken is at the plant's time, or within an output interval before it.
        if !(self.last_t <= t_s + tiny && self.last_t > t_s - self.dt - tiny && rows > 0) {
            return Err(format!(
                "tracker.last_t = {} s: the last output row's time, at most the plant's t_s = {t_s} s and within \
                 an output interval of {} s before it",
                self.last_t, self.dt
            ));
        }
        let current = self.starts.iter().rposition(|&s| s <= self.last_t);
        if self.current != current {
            return Err(format!(
                "tracker.current = {:?}: the last shock started by t = {} s is {current:?}",
                self.current, self.last_t
            ));
        }
        if closed != current.unwrap_or(0) {
            return Err(format!(
                "{closed} closed shocks (figures): the shocks before the current one are {}",
                current.unwrap_or(0)
            ));
        }
        let a = &self.acc;
        for (key, v) in [("max_force", a.max_force), ("max_radius", a.max_radius)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("tracker.acc.{key} = {v}: a maximum, finite and not negative"));
            }
        }
        if a.contact_samples > rows {
            return Err(format!("tracker.acc.contact_samples = {}: at most the {rows} rows taken", a.contact_samples));
        }
        if a.episodes > a.contact_samples {
            return Err(format!(
                "tracker.acc.episodes = {}: at most the contact samples, {} (an episode starts with one)",
                a.episodes, a.contact_samples
            ));
        }
        if let Some(c) = self.clear_since {
            if !(0.0..=self.last_t).contains(&c) {
                return Err(format!("tracker.clear_since = {c} s: a row's time, at most last_t = {} s", self.last_t));
            }
        }
        Ok(())
    }

    /// The time of the last sample taken (s).
    pub fn last_t(&self) -> f64 {
        self.last_t
    }

    /// Closes the window in progress at the end of the run (or where it stopped).
    pub fn finish(&mut self) -> Option<ShockFigures> {
        let j = self.current.take()?;
        let complete = self.last_t >= self.end - 0.5 * self.dt;
        Some(self.close(j, complete))
    }

    fn close(&self, j: usize, complete: bool) -> ShockFigures {
        let start = self.starts[j];
        let recovered_from = self.clear_since.filter(|c| self.last_t - c >= self.hold - 1e-9 * self.hold);
        ShockFigures {
            index: j,
            start_s: start,
            end_s: self.last_t,
            recovered: recovered_from.is_some(),
            recovery_s: recovered_from.map_or(f64::NAN, |c| (c - start).max(0.0)),
            max_contact_force_n: self.acc.max_force,
            contact_time_s: self.acc.contact_samples as f64 * self.dt,
            contact_episodes: self.acc.episodes,
            max_radius_m: self.acc.max_radius,
            complete,
        }
    }
}

/// Per-bin maxima of the radius and the contact force: the coarse trace of a soak.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Envelope {
    bin: f64,
    index: u64,
    max_radius: f64,
    max_force: f64,
    any: bool,
}

crate::table::table_row! {
/// One bin of an [`Envelope`]: its start (s) and maxima; a row of `envelope.csv`
/// (read back by column name).
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize)]
pub struct EnvelopeRow {
    /// Bin start (s).
    pub t_s: f64,
    /// Largest rotor radius (m).
    pub max_radius_m: f64,
    /// Largest contact force (N).
    pub max_contact_force_n: f64,
}
}

impl Envelope {
    /// Bins of `bin` seconds from t = 0.
    pub fn new(bin: f64) -> Self {
        Self { bin, index: 0, max_radius: 0.0, max_force: 0.0, any: false }
    }

    /// Why this envelope, read from a checkpoint, cannot go on as `fresh` would: another bin.
    pub fn check_resumable(&self, fresh: &Envelope) -> Result<(), String> {
        if self.bin.to_bits() == fresh.bin.to_bits() {
            Ok(())
        } else {
            Err(format!("envelope.bin is {:?} s, the soak's is {:?} s", self.bin, fresh.bin))
        }
    }

    /// Why this envelope, read from a checkpoint, cannot be the one whose last sample was at
    /// `last_t` (s): the bin under way is that of `last_t`, its maxima finite and not negative.
    pub fn check_at(&self, last_t: f64) -> Result<(), String> {
        let index = (last_t / self.bin).floor().max(0.0) as u64;
        if self.index != index || !self.any {
            return Err(format!(
                "envelope.index = {}, any = {}: the bin under way at the last row's t = {last_t} s is {index}, with samples",
                self.index, self.any
            ));
        }
        for (key, v) in [("max_radius", self.max_radius), ("max_force", self.max_force)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("envelope.{key} = {v}: a maximum, finite and not negative"));
            }
        }
        Ok(())
    }

    /// The bin width (s).
    pub fn bin(&self) -> f64 {
        self.bin
    }

    /// The bin under way: bins `0..index` are closed.
    pub fn index(&self) -> u64 {
        self.index
    }

    /// One sample; returns the bin it completes, if any.
    pub fn sample(&mut self, t: f64, radius: f64, force: f64) -> Option<EnvelopeRow> {
        let index = (t / self.bin).floor().max(0.0) as u64;
        let done = (index > self.index && self.any).then(|| self.row());
        if index > self.index {
            self.index = index;
            self.any = false;
            self.max_radius = 0.0;
            self.max_force = 0.0;
        }
        self.any = true;
        self.max_radius = self.max_radius.max(radius);
        self.max_force = self.max_force.max(force);
        done
    }

    /// The last, partial bin.
    pub fn finish(&mut self) -> Option<EnvelopeRow> {
        let row = self.any.then(|| self.row());
        self.any = false;
        row
    }

    fn row(&self) -> EnvelopeRow {
        EnvelopeRow {
            t_s: self.index as f64 * self.bin,
            max_radius_m: self.max_radius,
            max_contact_force_n: self.max_force,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Feeds a piecewise signal sampled every `dt`: returns the closed windows.
    fn run(tracker: &mut ShockTracker, dt: f64, end: f64, signal: impl Fn(f64) -> (f64, f64)) -> Vec<ShockFigures> {
        let mut out = Vec::new();
        let n = (end / dt).round() as usize;
        for i in 0..=n {
            let t = i as f64 * dt;
            let (r, f) = signal(t);
            tracker.sample(t, r, f, &mut |w| out.push(w));
        }
        out.extend(tracker.finish());
        out
    }

    #[test]
    fn recovery_contact_time_and_episodes_per_window() {
        let dt = 1e-3;
        // Shock 0 at 1 s: two contacts (1.010–1.019, 1.100–1.109 s), then clear from 1.110 s.
        // Shock 1 at 2 s: contact from 2.5 s to the end: never recovers.
        let signal = |t: f64| {
            let touching = (1.0095..1.0195).contains(&t) || (1.0995..1.1095).contains(&t) || t > 2.4995;
            if touching {
                (150e-6, 100.0 + t)
            } else if (1.0..1.2).contains(&t) {
                (100e-6, 0.0)
            } else {
                (5e-6, 0.0)
            }
        };
        let mut tr = ShockTracker::new(vec![1.0, 2.0], 3.0, dt, 75e-6, 0.2);
        let w = run(&mut tr, dt, 3.0, signal);
        assert_eq!(w.len(), 2);
        let (a, b) = (&w[0], &w[1]);
        assert!(a.recovered && a.complete);
        // Clear (radius < 75 µm, no contact) from 1.200 s: above the radius until then.
        assert!((a.recovery_s - 0.2).abs() < 1e-9, "{a:?}");
        assert_eq!(a.contact_episodes, 2);
        assert!((a.contact_time_s - 0.020).abs() < 1e-9, "{a:?}");
        assert!((a.max_contact_force_n - 101.109).abs() < 1e-6);
        assert!((a.max_radius_m - 150e-6).abs() < 1e-15);
        assert!(!b.recovered && b.recovery_s.is_nan() && b.complete);
        assert_eq!(b.contact_episodes, 1);
        assert!((b.contact_time_s - 0.501).abs() < 1e-9, "{b:?}");
    }

    #[test]
    fn a_clear_stretch_shorter_than_the_hold_is_not_recovery() {
        let dt = 1e-3;
        // Contact until 1.85 s, the next shock at 2.0 s: only 0.15 s clear with a 0.2 s hold.
        let signal = |t: f64| if (1.0..1.85).contains(&t) { (150e-6, 10.0) } else { (1e-6, 0.0) };
        let mut tr = ShockTracker::new(vec![1.0, 2.0], 2.5, dt, 75e-6, 0.2);
        let w = run(&mut tr, dt, 2.5, signal);
        assert!(!w[0].recovered);
        assert!(w[1].recovered && w[1].recovery_s == 0.0 && w[1].contact_time_s == 0.0);
    }

    #[test]
    fn a_run_stopped_inside_a_window_marks_it_incomplete() {
        let mut tr = ShockTracker::new(vec![0.5], 2.0, 1e-3, 75e-6, 0.2);
        let w = run(&mut tr, 1e-3, 1.0, |_| (1e-6, 0.0));
        assert_eq!(w.len(), 1);
        assert!(!w[0].complete && w[0].recovered);
    }

    #[test]
    fn envelope_keeps_bin_maxima() {
        let mut e = Envelope::new(0.01);
        let mut rows = Vec::new();
        for i in 0..25 {
            let t = i as f64 * 1e-3;
            rows.extend(e.sample(t, i as f64, 2.0 * i as f64));
        }
        rows.extend(e.finish());
        assert_eq!(rows.len(), 3);
        assert_eq!(rows[0], EnvelopeRow { t_s: 0.0, max_radius_m: 9.0, max_contact_force_n: 18.0 });
        assert_eq!(rows[2].max_radius_m, 24.0);
    }
}
