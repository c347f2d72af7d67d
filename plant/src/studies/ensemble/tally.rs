//! The tally of an ensemble's counted members: how many ended in each mode, the recovered
//! share with its Wilson 95 % interval, and the recovery times. A point of `plant ensemble` or
//! `plant sweep` ([`super::point::PointStats`]) and a rung of `plant assess`'s shock ladder
//! both report it; this is the public way to it from outside the ensemble.

use crate::ensemble::member::MemberResult;
use crate::ensemble::stats::{quantile, wilson};
use crate::grid::Mode;
use serde::Serialize;

/// Counts and recovery statistics of a set of counted members (serialised flat into the
/// structure that holds it, as [`Tally::serialize_fields`] writes it).
#[derive(Clone, Debug, PartialEq)]
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
    /// The recovered share with its Wilson 95 % interval (`p_recovered`, `p_lo`, `p_hi`).
    pub share: Share,
    /// The recovery times of the recovered members (`recovery_median_s`, `recovery_p90_s`).
    pub recovery: Recovery,
}

/// A share of members with its Wilson 95 % interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Share {
    /// The share (0 without members).
    pub value: f64,
    /// The interval's lower end.
    pub lo: f64,
    /// Its upper end.
    pub hi: f64,
}

impl Share {
    /// `k` of `n` members, with the Wilson interval of [`wilson`].
    pub fn of(k: usize, n: usize) -> Self {
        let [lo, hi] = wilson(k, n);
        Self { value: if n > 0 { k as f64 / n as f64 } else { 0.0 }, lo, hi }
    }
}

/// Recovery times of the recovered members (s); `None` without any.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Recovery {
    /// The median.
    pub median_s: Option<f64>,
    /// The 90th percentile.
    pub p90_s: Option<f64>,
}

impl Serialize for Tally {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut st = serializer.serialize_struct("Tally", 10)?;
        self.serialize_fields(&mut st)?;
        st.end()
    }
}

impl Tally {
    /// Writes the tally's fields into a structure being serialised, in their order, with their
    /// names of old (`p_recovered`, `p_lo`, …). Written out because `#[serde(flatten)]` turns
    /// the holder into a map, which the `csv` crate cannot write (`ensemble.csv` holds a point's
    /// statistics with its tally inline).
    pub(crate) fn serialize_fields<S: serde::ser::SerializeStruct>(&self, st: &mut S) -> Result<(), S::Error> {
        st.serialize_field("members", &self.members)?;
        st.serialize_field("recovered", &self.recovered)?;
        st.serialize_field("dry_whirl", &self.dry_whirl)?;
        st.serialize_field("rebound", &self.rebound)?;
        st.serialize_field("diverged", &self.diverged)?;
        st.serialize_field("p_recovered", &self.share.value)?;
        st.serialize_field("p_lo", &self.share.lo)?;
        st.serialize_field("p_hi", &self.share.hi)?;
        st.serialize_field("recovery_median_s", &self.recovery.median_s)?;
        st.serialize_field("recovery_p90_s", &self.recovery.p90_s)
    }
}

/// The tally of `members` (their counted runs: the verification's where one was run).
pub fn tally(members: &[&MemberResult]) -> Tally {
    let n = members.len();
    let count = |mode: Mode| members.iter().filter(|m| m.counted().mode == mode).count();
    let recovered = count(Mode::Recovered);
    let times: Vec<f64> =
        members.iter().filter(|m| m.counted().mode == Mode::Recovered).filter_map(|m| m.counted().recovery_s).collect();
    Tally {
        members: n,
        recovered,
        dry_whirl: count(Mode::DryWhirl),
        rebound: count(Mode::Rebound),
        diverged: count(Mode::Diverged),
        share: Share::of(recovered, n),
        recovery: Recovery { median_s: quantile(&times, 0.5), p90_s: quantile(&times, 0.9) },
    }
}

/// How many counted members were verified at the reference setting, and of those, how many
/// changed mode there (serialised flat into the structure that holds it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Verification {
    /// Members re-run at the reference setting.
    pub verified: usize,
    /// Verified members whose mode changed (numerically sensitive).
    pub numerically_sensitive: usize,
}

/// The verification of `members`.
pub fn verified(members: &[&MemberResult]) -> Verification {
    Verification {
        verified: members.iter().filter(|m| m.verified.is_some()).count(),
        numerically_sensitive: members.iter().filter(|m| m.sensitive()).count(),
    }
}
