//! The tally of an ensemble's counted members: how many ended in each mode, the recovered
//! share with its Wilson 95 % interval, and the recovery times. A point of `plant ensemble` or
//! `plant sweep` ([`super::point::PointStats`]) and a rung of `plant assess`'s shock ladder
//! both report it; this is the public way to it from outside the ensemble.

use crate::ensemble::member::MemberResult;
use crate::ensemble::stats::{quantile, wilson};
use crate::grid::Mode;
use serde::Serialize;

/// Counts and recovery statistics of a set of counted members (serialised flat into the
/// structure that holds it).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Tally {
    /// Members counted.
    pub members: usize,
    /// Members recovered.
    pub recovered: usize,
    /// Members in dry whirl.
    pub dry_whirl: usize,
    /// Members rebounding.
    pub rebound: usize,
    /// Members whose run diverged (also at the reference setting).
    pub diverged: usize,
    /// Recovered share (0 without members).
    pub p_recovered: f64,
    /// Wilson 95 % interval of the recovered share, lower end.
    pub p_lo: f64,
    /// Wilson 95 % interval of the recovered share, upper end.
    pub p_hi: f64,
    /// Median recovery time of the recovered members (s).
    pub recovery_median_s: Option<f64>,
    /// 90th percentile of the recovery times of the recovered members (s).
    pub recovery_p90_s: Option<f64>,
}

impl Tally {
    /// Writes the tally's fields into a structure being serialised, in their order. Written out
    /// because `#[serde(flatten)]` turns the holder into a map, which the `csv` crate cannot
    /// write (`ensemble.csv` holds a point's statistics with its tally inline).
    pub(crate) fn serialize_fields<S: serde::ser::SerializeStruct>(&self, st: &mut S) -> Result<(), S::Error> {
        st.serialize_field("members", &self.members)?;
        st.serialize_field("recovered", &self.recovered)?;
        st.serialize_field("dry_whirl", &self.dry_whirl)?;
        st.serialize_field("rebound", &self.rebound)?;
        st.serialize_field("diverged", &self.diverged)?;
        st.serialize_field("p_recovered", &self.p_recovered)?;
        st.serialize_field("p_lo", &self.p_lo)?;
        st.serialize_field("p_hi", &self.p_hi)?;
        st.serialize_field("recovery_median_s", &self.recovery_median_s)?;
        st.serialize_field("recovery_p90_s", &self.recovery_p90_s)
    }
}

/// The tally of `members` (their counted runs: the verification's where one was run).
pub fn tally(members: &[&MemberResult]) -> Tally {
    let n = members.len();
    let count = |mode: Mode| members.iter().filter(|m| m.counted().mode == mode).count();
    let recovered = count(Mode::Recovered);
    let [p_lo, p_hi] = wilson(recovered, n);
    let times: Vec<f64> =
        members.iter().filter(|m| m.counted().mode == Mode::Recovered).filter_map(|m| m.counted().recovery_s).collect();
    Tally {
        members: n,
        recovered,
        dry_whirl: count(Mode::DryWhirl),
        rebound: count(Mode::Rebound),
        diverged: count(Mode::Diverged),
        p_recovered: if n > 0 { recovered as f64 / n as f64 } else { 0.0 },
        p_lo,
        p_hi,
        recovery_median_s: quantile(&times, 0.5),
        recovery_p90_s: quantile(&times, 0.9),
    }
}

/// Members re-run at the reference setting, and of those, members whose mode changed there.
pub fn verified(members: &[&MemberResult]) -> (usize, usize) {
    (members.iter().filter(|m| m.verified.is_some()).count(), members.iter().filter(|m| m.sensitive()).count())
}
