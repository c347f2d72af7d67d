//! Non-finite commands: a law (in this process or in the controller
//! process) that answers a sample with a NaN or an infinite current does not
//! control. The run loop holds the last valid command for such a tick,
//! counts it, says the first one, and judges the run against its budget:
//! more than `controller.max_invalid_burst` non-finite commands in a row
//! (default 10), or a share of the ticks above
//! `controller.max_invalid_fraction` (default 1 %, judged from 1000 ticks on
//! and over the whole run at its end), ends the run with status
//! `invalid_commands` (exit 8). A controller that never controlled cannot
//! `complete`.
//!
//! ```
//! use plant_sim::invalid::InvalidCommands;
//! let mut check = InvalidCommands::new([0.0, 0.5], 2, 1.0);
//! let s = |k: u64| controller::Sample { seq: k, t_s: k as f64 * 5e-5, ..Default::default() };
//! assert_eq!(check.check([0.1, 0.6], &s(0)).unwrap().command, [0.1, 0.6]);
//! let held = check.check([f64::NAN, 0.7], &s(1)).unwrap();
//! assert_eq!((held.command, held.first), ([0.1, 0.6], true)); // the last valid command, held
//! assert!(check.check([f64::NAN; 2], &s(2)).is_ok());          // two in a row: within the budget
//! let e = check.check([f64::INFINITY, 0.0], &s(3)).unwrap_err();
//! assert!(e.contains("3 samples in a row") && e.contains("controller.max_invalid_burst = 2"), "{e}");
//! ```

use controller::{RotorSample, Sample};

/// A sample's number and time, where a burst is said to begin and end.
pub trait Stamped {
    /// `(seq, t_s)`.
    fn stamp(&self) -> (u64, f64);
}

impl Stamped for Sample {
    fn stamp(&self) -> (u64, f64) {
        (self.seq, self.t_s)
    }
}

impl Stamped for RotorSample {
    fn stamp(&self) -> (u64, f64) {
        (self.seq, self.t_s)
    }
}

/// Ticks with a command due before the share of non-finite ones is judged during the run.
pub const MIN_TICKS: u64 = 1000;

/// What to apply for a tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Checked<const N: usize = 2> {
    /// The law's command, or the last valid one held in place of a non-finite one.
    pub command: [f64; N],
    /// This is the run's first non-finite command (say it).
    pub first: bool,
}

/// The non-finite commands of a run, against its budget.
#[derive(Clone, Debug)]
pub struct InvalidCommands<const N: usize = 2> {
    max_burst: u64,
    max_fraction: f64,
    held: [f64; N],
    ticks: u64,
    count: u64,
    burst: u64,
    /// Sample and time where the current burst began.
    burst_from: (u64, f64),
}

impl<const N: usize> InvalidCommands<N> {
    /// A run whose command before any law output is `initial` (the bias), with the budget
    /// `controller.max_invalid_burst` and `controller.max_invalid_fraction`.
    pub fn new(initial: [f64; N], max_burst: u64, max_fraction: f64) -> Self {
        Self { max_burst, max_fraction, held: initial, ticks: 0, count: 0, burst: 0, burst_from: (0, 0.0) }
    }

    /// `controller.max_invalid_burst`: the most non-finite commands in a row.
    pub fn max_burst(&self) -> u64 {
        self.max_burst
    }

    /// Non-finite commands so far.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// Takes the law's (saturated) command for `sample`: what to apply, or why the run must
    /// end (past the budget).
    pub fn check(&mut self, command: [f64; N], sample: &impl Stamped) -> Result<Checked<N>, String> {
        let (seq, t_s) = sample.stamp();
        self.ticks += 1;
        if command.iter().all(|i| i.is_finite()) {
            self.held = command;
            self.burst = 0;
            return Ok(Checked { command, first: false });
        }
        self.count += 1;
        if self.burst == 0 {
            self.burst_from = (seq, t_s);
        }
        self.burst += 1;
        if self.burst > self.max_burst {
            let (k, t) = self.burst_from;
            return Err(format!(
                "the controller's commands were non-finite for {} samples in a row, from sample {k} (t = {t} s) to \
                 sample {} (t = {} s, {command:?} A): more than controller.max_invalid_burst = {}",
                self.burst, seq, t_s, self.max_burst
            ));
        }
        if self.ticks >= MIN_TICKS {
            if let Some(why) = self.over_fraction() {
                return Err(format!("{why} (by sample {seq}, t = {t_s} s)"));
            }
        }
        Ok(Checked { command: self.held, first: self.count == 1 })
    }

    /// At the run's end: `Some(why)` if the share of non-finite commands over the whole run
    /// is past the budget.
    pub fn at_end(&self) -> Option<String> {
        self.over_fraction()
    }

    fn over_fraction(&self) -> Option<String> {
        let share = self.count as f64 / self.ticks.max(1) as f64;
        (share > self.max_fraction).then(|| {
            format!(
                "{} of {} controller commands were non-finite ({:.3} %): more than controller.max_invalid_fraction = {}",
                self.count,
                self.ticks,
                100.0 * share,
                self.max_fraction
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(k: u64) -> Sample {
        Sample { seq: k, t_s: k as f64 * 1e-3, ..Default::default() }
    }

    #[test]
    fn scattered_non_finite_commands_are_judged_by_their_share() {
        let mut c = InvalidCommands::new([0.0; 2], 10, 0.01);
        // One in 50: 2 %, past 1 %, said once the share is judged (from 1000 ticks).
        let mut ended = None;
        for k in 0..2000 {
            let cmd = if k % 50 == 7 { [f64::NAN, 0.0] } else { [1.0, 0.0] };
            match c.check(cmd, &s(k)) {
                Ok(checked) => assert!(checked.command[0].is_finite()),
                Err(why) => {
                    ended = Some((k, why));
                    break;
                }
            }
        }
        let (k, why) = ended.expect("past the share");
        assert_eq!(k, 1007, "judged from the 1000th tick on, at the next non-finite one");
        assert!(why.contains("21 of 1008 controller commands") && why.contains("max_invalid_fraction = 0.01"), "{why}");
        // Over a short run, at its end.
        let mut short = InvalidCommands::new([0.0; 2], 10, 0.01);
        for k in 0..20 {
            short.check(if k == 3 { [f64::NAN; 2] } else { [0.0; 2] }, &s(k)).unwrap();
        }
        assert!(short.at_end().is_some_and(|w| w.contains("1 of 20")));
        assert_eq!(InvalidCommands::new([0.0; 2], 10, 1.0).at_end(), None);
    }

    #[test]
    fn a_burst_within_the_budget_holds_the_last_valid_command() {
        let mut c = InvalidCommands::new([0.0, 0.5], 3, 1.0);
        c.check([0.2, 0.3], &s(0)).unwrap();
        for k in 1..=3 {
            let h = c.check([f64::NEG_INFINITY, 0.0], &s(k)).unwrap();
            assert_eq!((h.command, h.first), ([0.2, 0.3], k == 1));
        }
        assert_eq!(c.check([0.4, 0.4], &s(4)).unwrap().command, [0.4, 0.4]);
        assert!(c.check([f64::NAN; 2], &s(5)).is_ok(), "a new burst starts from zero");
        assert_eq!(c.count(), 4);
    }
}
