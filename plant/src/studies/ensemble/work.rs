//! An ensemble as the grid engine's [`Work`]: each point's units are its members, run in rounds
//! of `batch` until the stopping rule decides the point ([`point::progress`]).

use crate::config::{load_scene, ConfigError};
use crate::ensemble::member::{self, MemberResult};
use crate::ensemble::point::{self, StoppedBy};
use crate::ensemble::spec::{EnsembleSpec, MAX_RUNS};
use crate::grid::store::{unit_key, Unit};
use crate::grid::{Grid, Mode, Point, Progress, Work};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// Members drawn around each point of a grid.
pub struct Ensemble {
    /// The validated `[ensemble]` table.
    pub spec: EnsembleSpec,
}

impl Ensemble {
    /// The verification part of a member's key.
    fn verification(&self) -> String {
        let e = &self.spec;
        if e.verify {
            format!("dop853 rtol {:e}, late {}, rebound {}", e.verify_rtol, e.verify_late, e.verify_rebound)
        } else {
            "none".into()
        }
    }
}

impl Work for Ensemble {
    type Result = MemberResult;
    type Decision = StoppedBy;

    fn members(&self) -> Option<usize> {
        Some(self.spec.members)
    }

    fn rounds(&self) -> usize {
        self.spec.rounds()
    }

    fn noun(&self) -> &'static str {
        "members"
    }

    fn what(&self) -> &'static str {
        "ensemble"
    }

    /// The budget of member runs, and no key both swept and drawn.
    fn check(&self, grid: &Grid) -> Result<(), ConfigError> {
        let e = &self.spec;
        let runs = grid.len().saturating_mul(e.members);
        if runs > MAX_RUNS {
            return Err(ConfigError::Range {
                key: "ensemble.members".into(),
                value: format!("{} (× {} points = {runs})", e.members, grid.len()),
                unit: " member runs".into(),
                why: format!("a sweep may run at most {MAX_RUNS} members in all"),
            });
        }
        for a in &grid.axes {
            let clash = e.vary.iter().any(|v| v.key == a.key) || (e.angle && a.key == "rotor.unbalance_phase_deg");
            if clash {
                return Err(ConfigError::Range {
                    key: "ensemble".into(),
                    value: format!("\"{}\"", a.key),
                    unit: String::new(),
                    why: "is both swept and drawn: draw it relatively, or sweep another key".into(),
                });
            }
        }
        Ok(())
    }

    /// The members' scenes with every drawn variable at both ends of its range load, and the
    /// members' integrator setting is stable on them.
    fn check_point(&self, point: &Point) -> Result<(), ConfigError> {
        let e = &self.spec;
        let mut member_sets = point.sets.clone();
        member_sets.extend(member::setting_overrides(&point.scene, e.integrator));
        for draw in e.extremes() {
            let mut s = member_sets.clone();
            s.extend(member::draw_overrides(&point.scene, e, &draw));
            let scene = load_scene(point.path, &s)?;
            if let crate::stability::StepVerdict::Refuse(why) = crate::stability::check(&scene) {
                return Err(ConfigError::Range {
                    key: "ensemble.integrator".into(),
                    value: format!("{:?}", e.integrator),
                    unit: String::new(),
                    why,
                });
            }
        }
        Ok(())
    }

    fn describe(&self, scene: &crate::config::Scene) -> Option<String> {
        Some(member::setting_description(scene, &self.spec))
    }

    fn manifest(&self) -> anyhow::Result<Option<serde_json::Value>> {
        Ok(Some(serde_json::to_value(&self.spec)?))
    }

    fn key(&self, point: &Point, member: Option<usize>) -> anyhow::Result<String> {
        let (member_sets, _, _) = member::member_overrides(point, &self.spec, member.unwrap_or(0));
        let member_scene = load_scene(point.path, &member_sets)?;
        unit_key(&member_scene, Unit { point: point.index, member }, Some(self.verification()))
    }

    fn indices(&self, m: &MemberResult) -> (usize, Option<usize>) {
        (m.point, Some(m.member))
    }

    fn progress(&self, present: &BTreeMap<usize, MemberResult>) -> Progress<StoppedBy> {
        let recovered = present.iter().map(|(j, r)| (*j, r.counted().mode == Mode::Recovered)).collect();
        point::progress(&self.spec, &recovered)
    }

    fn run(&self, point: &Point, member: Option<usize>, stop: &AtomicBool) -> anyhow::Result<Option<MemberResult>> {
        member::run_member(point, &self.spec, member.unwrap_or(0), stop)
    }

    fn merge(&self, grid: &Grid, dir: &Path, points: &[(Vec<&MemberResult>, StoppedBy)]) -> anyhow::Result<String> {
        crate::ensemble::merge::write_ensemble(grid, &self.spec, dir, points)
    }
}
