//! The figures of a run taken row by row ([`FiguresBuilder`]): the maxima, the
//! recovery and the first contact that `summary.json` reports, in memory that
//! does not grow with the run. After a divergence the maxima are over the rows
//! before the failure (the row at the failure holds the state that failed).

use crate::analysis::AnalysisSpec;
use crate::config::Scene;
use crate::trace::{Row, Trace};

/// The analysis setting of a scene: Poincaré section at spin phase 0, periodicity tolerance 1e-3 r_0
/// (r_0 of plane A, for a two-plane rotor).
pub fn analysis_spec(scene: &Scene) -> AnalysisSpec {
    plane_analysis_spec(scene, 0)
}

/// [`analysis_spec`] of bearing plane `i` (its own air gap).
pub fn plane_analysis_spec(scene: &Scene, i: usize) -> AnalysisSpec {
    let p = scene.plane(i);
    AnalysisSpec { gap: p.contact.gap, speed: p.speed, phase: 0.0, tolerance: 1e-3 }
}

/// The summary's figures of a whole run, taken row by row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Figures {
    /// Largest rotor radius (m); `None` when no row counts (a failure at the first row).
    pub max_radius_m: Option<f64>,
    /// Largest contact force (N); `None` when no row counts.
    pub max_contact_force_n: Option<f64>,
    /// Largest race speed (rpm); `None` when no row counts.
    pub max_race_speed_rpm: Option<f64>,
    /// From the first shock's start to the last row in contact (s): `summary.json`'s `recovery_s`.
    pub recovery_s: Option<f64>,
    /// Time of the first row with rotor – race contact (s), if any.
    pub first_contact_s: Option<f64>,
    /// Rows.
    pub rows: u64,
    /// Rows with a positive contact force.
    pub contact_rows: u64,
}

impl Figures {
    /// Share of the rows in contact (0 without rows).
    pub fn contact_share(&self) -> f64 {
        if self.rows == 0 {
            0.0
        } else {
            self.contact_rows as f64 / self.rows as f64
        }
    }
}

/// Takes [`Figures`] as the rows come. The maxima lag one row behind, so that
/// the row of a failure can be left out at the end.
#[derive(Clone, Debug)]
pub struct FiguresBuilder {
    shock_start: f64,
    max_radius: f64,
    max_force: f64,
    max_rpm: f64,
    /// The last row's time and its radius, force and race speed (rpm), not yet in the maxima.
    pending: Option<[f64; 4]>,
    last_contact: Option<f64>,
    first_contact: Option<f64>,
    last_row_in_contact: bool,
    rows: u64,
    contact_rows: u64,
    /// Rows taken into the maxima.
    counted: u64,
}

impl FiguresBuilder {
    /// Figures with recovery counted from `shock_start` (s).
    pub fn new(shock_start: f64) -> Self {
        Self {
            shock_start,
            max_radius: 0.0,
            max_force: 0.0,
            max_rpm: 0.0,
            pending: None,
            last_contact: None,
            first_contact: None,
            last_row_in_contact: false,
            rows: 0,
            contact_rows: 0,
            counted: 0,
        }
    }

    /// The next row.
    pub fn push(&mut self, r: &Row) {
        self.commit();
        let (t, force) = (r.t_s, r.loads.contact_force_n);
        let rpm = r.loads.race_speed_rad_s.abs() * 60.0 / std::f64::consts::TAU;
        self.pending = Some([t, r.motion.dx_m.hypot(r.motion.dy_m), force, rpm]);
        self.rows += 1;
        self.contact_rows += u64::from(force > 0.0);
        if force > 0.0 && self.first_contact.is_none() {
            self.first_contact = Some(t);
        }
        self.last_row_in_contact = t >= self.shock_start && force > 0.0;
        if self.last_row_in_contact {
            self.last_contact = Some(t);
        }
    }

    fn commit(&mut self) {
        if let Some([_, radius, force, rpm]) = self.pending.take() {
            let keep = |m: &mut f64, v: f64| {
                if v.is_finite() {
                    *m = m.max(v);
                }
            };
            keep(&mut self.max_radius, radius);
            keep(&mut self.max_force, force);
            keep(&mut self.max_rpm, rpm);
            self.counted += 1;
        }
    }

    /// The figures; rows at or after `failure_time` (s) are left out of the maxima.
    pub fn finish(mut self, failure_time: Option<f64>) -> Figures {
        if self.pending.is_some_and(|p| failure_time.is_none_or(|tf| p[0] < tf)) {
            self.commit();
        }
        let counted = |m: f64| (self.counted > 0).then_some(m);
        Figures {
            max_radius_m: counted(self.max_radius),
            max_contact_force_n: counted(self.max_force),
            max_race_speed_rpm: counted(self.max_rpm),
            // From the shock's start to the last row in contact: 0 if none, `None` if the last
            // row is in contact (the rotor never left).
            recovery_s: match self.last_contact {
                None => Some(0.0),
                Some(_) if self.last_row_in_contact => None,
                Some(t) => Some(t - self.shock_start),
            },
            first_contact_s: self.first_contact,
            rows: self.rows,
            contact_rows: self.contact_rows,
        }
    }
}

/// Time from `start` (s) to the last trace sample with a positive contact force: 0 if there
/// is none after `start`, `None` if the last sample is in contact (the rotor never left).
pub fn recovery_time(trace: &Trace, start: f64) -> Option<f64> {
    let mut f = FiguresBuilder::new(start);
    trace.rows().for_each(|r| f.push(&r));
    f.finish(None).recovery_s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(t: f64, dx: f64, force: f64) -> Row {
        let mut r = Row { t_s: t, ..Row::default() };
        r.motion.dx_m = dx;
        r.loads.contact_force_n = force;
        r
    }

    #[test]
    fn maxima_leave_out_the_row_of_the_failure() {
        let mut f = FiguresBuilder::new(0.0);
        for r in [row(0.0, 1e-6, 0.0), row(1e-4, 628e-6, 10.0), row(2e-4, 793e-6, 2e5)] {
            f.push(&r);
        }
        let diverged = f.clone().finish(Some(2e-4));
        assert_eq!((diverged.max_radius_m, diverged.max_contact_force_n), (Some(628e-6), Some(10.0)));
        let completed = f.finish(None);
        assert_eq!((completed.max_radius_m, completed.max_contact_force_n), (Some(793e-6), Some(2e5)));
    }

    /// Issue 21 item 7: a run that failed at its first row reported `max_radius_m = 0.0`, a
    /// radius it never had: without a row before the failure the maxima are `None` (null).
    #[test]
    fn maxima_over_no_row_are_none() {
        let mut f = FiguresBuilder::new(0.0);
        f.push(&row(0.0, f64::NAN, f64::NAN));
        let failed = f.finish(Some(0.0));
        assert_eq!((failed.max_radius_m, failed.max_contact_force_n, failed.max_race_speed_rpm), (None, None, None));
        assert_eq!(FiguresBuilder::new(0.0).finish(None).max_radius_m, None);
    }

    #[test]
    fn recovery_is_from_the_shock_to_the_last_contact() {
        let mut tr = Trace::default();
        for (t, force) in [(0.0, 1.0), (0.1, 0.0), (0.2, 5.0), (0.3, 0.0), (0.4, 0.0)] {
            tr.push_row(&row(t, 0.0, force));
        }
        // Contact before the shock does not count.
        assert_eq!(recovery_time(&tr, 0.05), Some(0.2 - 0.05));
        assert_eq!(recovery_time(&tr, 0.25), Some(0.0));
        tr.push_row(&row(0.5, 0.0, 1.0));
        assert_eq!(recovery_time(&tr, 0.05), None);
    }
}
