//! The statistics of one point of an ensemble from its counted members, and the rule that says
//! when a point has enough members.
//!
//! **Rounds.** Members run in batches of `ensemble.batch`. Round r runs batch r of every point
//! not yet decided by its batches 0 … r−1. A point is decided after a batch when it has
//! `ensemble.members` members, or when its Wilson interval is at most `ensemble.target_width`
//! wide, or when at least `ensemble.agree` members all agree (all recovered, or none). The rule
//! reads only the point's own batches, so the members that count are the same however the
//! members were sharded, threaded or ordered, and points whose probability lies strictly
//! between 0 and 1 get more members.

use crate::analysis::classify::SteadyClass;
use crate::ensemble::member::MemberResult;
use crate::ensemble::spec::EnsembleSpec;
use crate::ensemble::stats::{quantile, wilson};
use crate::ensemble::tally::{tally, Tally, Verification};
use crate::grid::{Mode, Progress};
use crate::status::Status;
use serde::Serialize;
use std::collections::BTreeMap;

/// Which rule decided a point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StoppedBy {
    /// It has `ensemble.members` members.
    Members,
    /// Its interval is at most `ensemble.target_width` wide.
    Width,
    /// At least `ensemble.agree` members all agree.
    Agree,
}

/// Applies the stopping rule to the members present (`present[j]` = recovered?).
pub fn progress(spec: &EnsembleSpec, present: &BTreeMap<usize, bool>) -> Progress<StoppedBy> {
    let mut recovered = 0usize;
    for r in 0..spec.rounds() {
        let batch = spec.batch_members(r);
        let missing: Vec<usize> = batch.clone().filter(|j| !present.contains_key(j)).collect();
        if !missing.is_empty() {
            return Progress::Needs { round: r, missing };
        }
        recovered += batch.clone().filter(|j| present[j]).count();
        let n = batch.end;
        if n >= spec.members {
            return Progress::Decided { counted: n, decision: StoppedBy::Members };
        }
        let [lo, hi] = wilson(recovered, n);
        if spec.target_width > 0.0 && hi - lo <= spec.target_width {
            return Progress::Decided { counted: n, decision: StoppedBy::Width };
        }
        if spec.agree > 0 && n >= spec.agree && (recovered == 0 || recovered == n) {
            return Progress::Decided { counted: n, decision: StoppedBy::Agree };
        }
    }
    Progress::Decided { counted: spec.members, decision: StoppedBy::Members }
}

/// Statistics of a point over its counted members (serialised flat: the tally's fields after
/// `index`, as `ensemble.csv` and `sweep.json` have them).
#[derive(Clone, Debug, PartialEq)]
pub struct PointStats {
    /// Point index.
    pub index: usize,
    /// The counted members' modes and recovery statistics.
    pub tally: Tally,
    /// Largest peak contact force of all members (N).
    pub worst_contact_force_n: f64,
    /// Members re-run at the reference setting, and of those, members whose mode changed.
    pub verification: Verification,
    /// Which rule stopped the point: `members`, `width` or `agree`.
    pub stopped_by: StoppedBy,
    /// The members' most frequent mode, steady class and period k.
    pub typical: Typical,
    /// Mean contact fraction.
    pub contact_fraction: f64,
    /// Median whirl rate (Hz).
    pub whirl_hz: f64,
    /// Largest rotor radius of all members (m).
    pub max_radius_m: f64,
    /// `completed` if every counted run completed, else `diverged`.
    pub status: Status,
}

/// The most frequent outcome of a point's counted members; each `None` without members.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Typical {
    /// The most frequent mode (ties: recovered, dry whirl, rebound, diverged).
    pub post_shock_mode: Option<Mode>,
    /// The most frequent steady class (ties: the first by name).
    pub steady_class: Option<SteadyClass>,
    /// The most frequent period k among members of that class.
    pub period_k: Option<u32>,
}

impl Serialize for PointStats {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut st = serializer.serialize_struct("PointStats", 22)?;
        st.serialize_field("index", &self.index)?;
        self.tally.serialize_fields(&mut st)?;
        st.serialize_field("worst_contact_force_n", &self.worst_contact_force_n)?;
        st.serialize_field("verified", &self.verification.verified)?;
        st.serialize_field("numerically_sensitive", &self.verification.numerically_sensitive)?;
        st.serialize_field("stopped_by", &self.stopped_by)?;
        st.serialize_field("post_shock_mode", &self.typical.post_shock_mode)?;
        st.serialize_field("steady_class", &self.typical.steady_class)?;
        st.serialize_field("period_k", &self.typical.period_k)?;
        st.serialize_field("contact_fraction", &self.contact_fraction)?;
        st.serialize_field("whirl_hz", &self.whirl_hz)?;
        st.serialize_field("max_radius_m", &self.max_radius_m)?;
        st.serialize_field("status", &self.status)?;
        st.end()
    }
}

/// The most frequent item, ties broken by `order` (the first there wins); `None` without items.
fn most_frequent<T: PartialEq + Copy>(items: &[T], order: &[T]) -> Option<T> {
    let count = |o: &T| items.iter().filter(|i| *i == o).count();
    let best = order.iter().map(count).max().filter(|&c| c > 0)?;
    order.iter().copied().find(|o| count(o) == best)
}

/// The most frequent outcome of `members`.
fn typical(members: &[&MemberResult]) -> Typical {
    let modes: Vec<Mode> = members.iter().map(|m| m.counted().mode).collect();
    let classes: Vec<SteadyClass> = members.iter().map(|m| m.counted().steady_class).collect();
    let mut by_name = SteadyClass::ALL;
    by_name.sort_by_key(|c| c.name());
    let class = most_frequent(&classes, &by_name);
    let ks: Vec<u32> = members
        .iter()
        .filter(|m| Some(m.counted().steady_class) == class)
        .filter_map(|m| m.counted().period_k)
        .collect();
    let mut k_order = ks.clone();
    k_order.sort_unstable();
    k_order.dedup();
    Typical {
        post_shock_mode: most_frequent(&modes, &Mode::ALL),
        steady_class: class,
        period_k: most_frequent(&ks, &k_order),
    }
}

/// The statistics of a point's counted members (`members` sorted by index).
pub fn point_stats(index: usize, members: &[&MemberResult], stopped_by: StoppedBy) -> PointStats {
    let n = members.len();
    let t = tally(members);
    let whirl: Vec<f64> = members.iter().map(|m| m.counted().whirl_hz).collect();
    let max = |f: fn(&MemberResult) -> f64| members.iter().map(|m| f(m)).filter(|v| v.is_finite()).fold(0.0, f64::max);
    PointStats {
        index,
        tally: t,
        worst_contact_force_n: max(|m| m.counted().max_contact_force_n),
        verification: super::tally::verified(members),
        stopped_by,
        typical: typical(members),
        contact_fraction: if n > 0 {
            members.iter().map(|m| m.counted().contact_fraction).sum::<f64>() / n as f64
        } else {
            0.0
        },
        whirl_hz: quantile(&whirl, 0.5).unwrap_or(0.0),
        max_radius_m: max(|m| m.counted().max_radius_m),
        status: if members.iter().all(|m| m.counted().status == Status::Completed) {
            Status::Completed
        } else {
            Status::Diverged
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(text: &str) -> EnsembleSpec {
        EnsembleSpec::from_table(&toml::from_str(text).expect("toml")).expect("spec")
    }

    #[test]
    fn a_point_that_agrees_stops_after_its_first_batch() {
        let s = spec("members = 64\nbatch = 16\nagree = 16");
        let all: BTreeMap<usize, bool> = (0..16).map(|j| (j, true)).collect();
        assert_eq!(progress(&s, &all), Progress::Decided { counted: 16, decision: StoppedBy::Agree });
        let mixed: BTreeMap<usize, bool> = (0..16).map(|j| (j, j % 2 == 0)).collect();
        assert_eq!(progress(&s, &mixed), Progress::Needs { round: 1, missing: (16..32).collect() });
    }

    #[test]
    fn width_and_the_maximum_stop_a_point() {
        let s = spec("members = 48\nbatch = 16\ntarget_width = 0.3");
        let half: BTreeMap<usize, bool> = (0..48).map(|j| (j, j % 2 == 0)).collect();
        // 8/16: width 0.44; 16/32: 0.33; 24/48: the maximum.
        assert_eq!(progress(&s, &half), Progress::Decided { counted: 48, decision: StoppedBy::Members });
        let s = spec("members = 64\nbatch = 16\ntarget_width = 0.4");
        assert_eq!(progress(&s, &half), Progress::Decided { counted: 32, decision: StoppedBy::Width });
    }
}
