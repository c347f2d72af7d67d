//! The shock ladder: the probability of recovery against the shock's peak, each rung an
//! ensemble over the rotor's angle at the shock's arrival (the ensemble machinery's draws,
//! members' setting, verification and Wilson intervals: [`crate::ensemble`]), with the
//! touchdown bearing's duty of every counted member ([`super::duty`]).
//!
//! A rung's shock is the scene's programme scaled so that its first shock peaks at the rung's
//! value (every shock's size field times the same factor). Members run in batches of `batch`;
//! a rung is decided once its Wilson 95 % interval lies wholly above or wholly below `min_p`
//! (0.9), or at `members`: the question each rung answers is whether recovery is at least
//! 90 % likely there. The ladder's answer is the highest peak up to which every rung's lower
//! bound is ≥ `min_p`.
//!
//! **A member ends once its outcome is decided** (`end_when_decided`, the default; [`Decision`]):
//! when the loop's free decay was measured stable (the sensitivity part's probe at speed), the
//! shock programme is over, the rotor has touched neither touchdown bearing for the steady
//! window's length (the last 200 revolutions, over which a full run's mode is read), and the
//! largest radius of its orbit has stopped growing (the last block of 50 revolutions no larger
//! than the one before, or both within 5 % of the air gap). Such a member would be classified
//! `recovered` with the same last contact at the scene's end: a stable loop whose rotor is clear
//! and settling is not driven into the bearing again without a shock, and nothing of the duty
//! accrues without contact. Its steady window is then taken as the full run's (its start
//! `duration − 200 revolutions`), so that the verification of late recoveries decides as before.
//! Every other member (still touching, rebounding, whirling, diverged, or an unstable or unprobed
//! loop) runs to the scene's end.

use super::duty::{Bearing, Duty, DutySink};
use crate::config::{load_scene, Scene};
use crate::ensemble::member::{close_to_decision, figures, member_overrides, verification_overrides, MemberResult};
use crate::ensemble::spec::EnsembleSpec;
use crate::ensemble::stats::{quantile, wilson};
use crate::ensemble::tally::{tally, Tally, Verification};
use crate::grid::{Mode, Point};
use crate::hooks::Hooks;
use crate::run::{run_into, Outcome, RunResult, Sink};
use crate::trace::{Record, Trace};
use rayon::prelude::*;
use serde::Serialize;
use std::cell::Cell;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

/// Settings of the ladder (`[ladder]` of an assessment).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Settings {
    /// The rungs: peaks of the first shock (G), ascending.
    pub peaks_g: Vec<f64>,
    /// Most members per rung.
    pub members: usize,
    /// Members per round.
    pub batch: usize,
    /// Seed of the draws.
    pub seed: u64,
    /// Verify members close to a decision at the reference setting.
    pub verify: bool,
    /// The probability a rung's lower bound must reach.
    pub min_p: f64,
    /// The rung whose duty goes into the verdict (G).
    pub duty_g: f64,
    /// End a member's run once its outcome is decided (module doc); `false`: every member runs
    /// to the scene's end.
    pub end_when_decided: bool,
    /// Perturbed copies of every counted member (`ladder.robustness`, 0: none, the default):
    /// [`LadderRobustness`]. Left out of `report.json` at 0, so that a report without it is
    /// the same as before.
    #[serde(skip_serializing_if = "is_zero")]
    pub robustness: usize,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            peaks_g: vec![1.0, 2.0, 3.0, 5.0, 7.0, 10.0, 15.0, 20.0],
            members: 64,
            batch: 16,
            seed: 1,
            verify: true,
            min_p: 0.9,
            duty_g: 10.0,
            end_when_decided: true,
            robustness: 0,
        }
    }
}

impl Settings {
    /// The fewest members per rung whose Wilson 95 % lower bound can reach `min_p` (all of them
    /// recovered: the lower bound is then n / (n + z²)); `None` when no count can (`min_p` = 1).
    pub fn members_needed(&self) -> Option<usize> {
        members_needed(self.min_p)
    }

    /// Why the ladder's rungs cannot reach `min_p` with `members` per rung (a warning for the
    /// report and the terminal), or `None` when they can.
    pub fn unreachable(&self) -> Option<String> {
        let best = wilson(self.members, self.members)[0];
        if best >= self.min_p {
            return None;
        }
        let needed = match self.members_needed() {
            Some(n) => format!("at least {n} members per rung are needed"),
            None => "no number of members can (lower ladder.min_p below 1)".into(),
        };
        Some(format!(
            "ladder.members = {} cannot reach ladder.min_p = {}: even {} of {} recovered gives a Wilson 95 % \
             lower bound of {best:.3}, so no rung can be called safe; {needed}",
            self.members, self.min_p, self.members, self.members
        ))
    }
}

/// The fewest members `n` with `wilson(n, n)` lower bound ≥ `min_p`; `None` when none up to
/// 10⁶ does (`min_p` at or too near 1).
pub fn members_needed(min_p: f64) -> Option<usize> {
    // The bound n / (n + z²) rises with n: the first n that reaches min_p, found by doubling
    // then bisection on the same `wilson` the rungs are decided with.
    let reaches = |n: usize| wilson(n, n)[0] >= min_p;
    let (mut lo, mut hi) = (0usize, 1usize);
    while !reaches(hi) {
        if hi >= 1 << 20 {
            return None;
        }
        lo = hi;
        hi *= 2;
    }
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if reaches(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

/// The spread of one duty figure over a rung's counted members.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Spread {
    /// Median.
    pub median: Option<f64>,
    /// 90th percentile.
    pub p90: Option<f64>,
    /// Largest.
    pub max: Option<f64>,
}

fn spread(values: &[f64]) -> Spread {
    Spread {
        median: quantile(values, 0.5),
        p90: quantile(values, 0.9),
        max: values.iter().copied().filter(|v| v.is_finite()).reduce(f64::max),
    }
}

/// The duty of a rung: each figure's spread over the counted members.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RungDuty {
    /// Time in contact (s).
    pub contact_time_s: Spread,
    /// Peak rotor – race force (N).
    pub peak_contact_force_n: Spread,
    /// Peak rotor – race pressure (MPa).
    pub peak_race_pressure_mpa: Spread,
    /// Peak load of the most loaded ball (N).
    pub peak_ball_load_n: Spread,
    /// Its pressure (MPa).
    pub peak_ball_pressure_mpa: Spread,
    /// Friction energy (J).
    pub friction_energy_j: Spread,
    /// Race peak speed (rpm).
    pub race_peak_speed_rpm: Spread,
    /// Race peak angular acceleration (rad/s²).
    pub race_peak_accel_rad_s2: Spread,
    /// Ball-load cycles over the threshold.
    pub ball_cycles: Spread,
}

fn rung_duty(d: &[&Duty]) -> RungDuty {
    let v = |f: fn(&Duty) -> Option<f64>| spread(&d.iter().filter_map(|x| f(x)).collect::<Vec<_>>());
    RungDuty {
        contact_time_s: v(|d| Some(d.contact_time_s)),
        peak_contact_force_n: v(|d| Some(d.peak_contact_force_n)),
        peak_race_pressure_mpa: v(|d| Some(d.peak_race_pressure_mpa)),
        peak_ball_load_n: v(|d| d.ball.peak_ball_load_n),
        peak_ball_pressure_mpa: v(|d| d.ball.peak_ball_pressure_mpa),
        friction_energy_j: v(|d| Some(d.friction_energy_j)),
        race_peak_speed_rpm: v(|d| Some(d.race_peak_speed_rpm)),
        race_peak_accel_rad_s2: v(|d| Some(d.race_peak_accel_rad_s2)),
        ball_cycles: v(|d| d.ball_cycles),
    }
}

/// One rung.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Rung {
    /// Peak of the first shock (G).
    pub peak_g: f64,
    /// The counted members' modes and recovery statistics.
    #[serde(flatten)]
    pub tally: Tally,
    /// Members re-run at the reference setting, and of those, members whose mode changed.
    #[serde(flatten)]
    pub verification: Verification,
    /// The rung was decided (false: the ladder was interrupted).
    pub complete: bool,
    /// The duty over the counted members (two-plane rotor: each figure the larger bearing's).
    pub duty: RungDuty,
    /// The two-plane rotor: each touchdown bearing's duty over the counted members, A then B;
    /// empty for the planar model.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub duty_planes: Vec<RungDuty>,
}

/// The ladder's result.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LadderResult {
    /// The rungs, ascending.
    pub rungs: Vec<Rung>,
    /// The highest peak up to which every rung's lower bound reaches `min_p` (G); `None` when
    /// the first rung does not.
    pub safe_up_to_g: Option<f64>,
    /// The members' setting, in words.
    pub member_setting: String,
    /// Members run in all (verification re-runs not counted).
    pub members_run: usize,
    /// Members re-run at the reference setting.
    pub verified: usize,
    /// Members whose counted run ended once its outcome was decided (module doc).
    pub ended_when_decided: usize,
    /// Simulated time of all the members' runs, verification included (s): for co-simulation,
    /// the round trips are this over the controller's period.
    pub simulated_s: f64,
    /// True when interrupted before every rung was decided.
    pub interrupted: bool,
    /// How robust the members' outcomes are (`ladder.robustness` > 0, the ladder complete).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub robustness: Option<LadderRobustness>,
}

/// A counted member some of whose perturbed copies ended in another motion mode.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FragileMember {
    /// The member's index in its rung.
    pub member: usize,
    /// Its rotor angle at the shock's arrival (deg), if drawn.
    pub angle_deg: Option<f64>,
    /// The mode it was counted with.
    pub mode: &'static str,
    /// Its copies' modes, copy 1 first.
    pub copies: Vec<&'static str>,
    /// Recovered in some runs (the member or a copy) and not in others: the rung's count
    /// depends on the branch.
    pub flips_recovery: bool,
}

/// One rung's robustness: its counted members' copies.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RungRobustness {
    /// Peak of the first shock (G).
    pub peak_g: f64,
    /// Counted members.
    pub members: usize,
    /// Members with a copy in another mode.
    pub fragile: usize,
    /// Members recovered in the member's run and in every copy, and the Wilson 95 % lower
    /// bound with that count: the rung's worst case under the perturbation.
    pub recovered_worst: usize,
    /// Its lower bound.
    pub p_lo_worst: f64,
    /// Members recovered in the member's run or in any copy, and its lower bound: the best case.
    pub recovered_best: usize,
    /// Its lower bound.
    pub p_lo_best: f64,
    /// The fragile members.
    pub fragile_members: Vec<FragileMember>,
}

/// The ladder's robustness answer (`ladder.robustness = N`): every counted member repeated `N`
/// times with the perturbations `plant run --robustness` uses ([`crate::robustness::perturbation`]:
/// the unbalance's angle by ±k·10⁻⁹ rad, the rotor's start by ±k pm), at the setting it was
/// counted on (a verified member at the reference setting). A member is fragile when a copy ends
/// in another mode; the highest safe shock survives when the worst case (every member that
/// recovers in some runs but not in others counted as not recovered) gives the same rung.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LadderRobustness {
    /// Perturbed copies per member.
    pub copies: usize,
    /// The perturbation, in words.
    pub perturbation: String,
    /// Fragile members over all rungs.
    pub fragile_members: usize,
    /// Members whose recovery flips among their runs, over all rungs.
    pub flipping_members: usize,
    /// The highest safe shock in the worst case (G).
    pub safe_up_to_g_worst: Option<f64>,
    /// In the best case (every flipping member counted as recovered) (G).
    pub safe_up_to_g_best: Option<f64>,
    /// The ladder's highest safe shock equals the worst case's.
    pub safe_survives: bool,
    /// Per rung.
    pub rungs: Vec<RungRobustness>,
}

impl LadderRobustness {
    /// The answer in words, for the verdict line and the report.
    pub fn words(&self, safe_up_to_g: Option<f64>) -> String {
        let g = |x: Option<f64>| x.map_or("none".to_string(), |g| format!("{g} G"));
        let members: usize = self.rungs.iter().map(|r| r.members).sum();
        let fragile = if self.fragile_members == 0 {
            format!("no member of {members} fragile")
        } else {
            let at: Vec<String> = self
                .rungs
                .iter()
                .filter(|r| r.fragile > 0)
                .map(|r| format!("{} of {} at {} G", r.fragile, r.members, r.peak_g))
                .collect();
            format!(
                "FRAGILE members: {} ({} of them recovering in some runs and not in others)",
                at.join(", "),
                self.flipping_members
            )
        };
        let survives = if self.safe_survives {
            format!("the highest safe shock ({}) survives", g(safe_up_to_g))
        } else {
            format!(
                "the highest safe shock does NOT survive: {} in the worst case, {} in the best (the ladder: {})",
                g(self.safe_up_to_g_worst),
                g(self.safe_up_to_g_best),
                g(safe_up_to_g)
            )
        };
        let copies =
            if self.copies == 1 { "1 perturbed copy".to_string() } else { format!("{} perturbed copies", self.copies) };
        format!("robustness ({copies} per member): {fragile}; {survives}")
    }
}

/// The answer as an HTML paragraph with a table of the fragile members, for the report's ladder
/// section (the text escaped: it holds only numbers and mode names, but the page is HTML).
pub fn robustness_html(r: &LadderRobustness, safe_up_to_g: Option<f64>) -> String {
    let esc = |s: &str| s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;");
    let class = if r.fragile_members == 0 && r.safe_survives { "ok" } else { "bad" };
    let mut h = format!(
        "<p class=\"{class}\">{}. Perturbation: {}; each copy at its member's counted setting.</p>\n",
        esc(&r.words(safe_up_to_g)),
        esc(&r.perturbation)
    );
    if r.fragile_members > 0 {
        h.push_str(
            "<table><tr><th>peak (G)</th><th>member</th><th>angle (deg)</th><th>counted as</th><th>its copies</th>\
             <th>recovered worst / best, lower bound</th></tr>\n",
        );
        for rung in r.rungs.iter().filter(|x| x.fragile > 0) {
            for m in &rung.fragile_members {
                h.push_str(&format!(
                    "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}–{} of {}, [{:.2}, {:.2}]</td></tr>\n",
                    rung.peak_g,
                    m.member,
                    m.angle_deg.map_or("–".into(), |a| format!("{a:.3}")),
                    m.mode,
                    m.copies.join(", "),
                    rung.recovered_worst,
                    rung.recovered_best,
                    rung.members,
                    rung.p_lo_worst,
                    rung.p_lo_best
                ));
            }
        }
        h.push_str("</table>\n");
    }
    h
}

/// One counted member's outcome and its copies' (for [`judge`]).
pub struct MemberCopies {
    /// The member's index in its rung.
    pub member: usize,
    /// Its rotor angle (deg).
    pub angle_deg: Option<f64>,
    /// The mode it was counted with.
    pub mode: Mode,
    /// Its copies' modes.
    pub copies: Vec<Mode>,
}

/// The highest peak up to which every rung is complete and its lower bound reaches `min_p`.
fn safe_up_to(peaks: &[f64], complete: &[bool], p_lo: &[f64], min_p: f64) -> Option<f64> {
    peaks.iter().zip(complete).zip(p_lo).take_while(|((_, c), p)| **c && **p >= min_p).last().map(|((g, _), _)| *g)
}

/// The ladder's robustness from each rung's members and their copies (pure): `rungs[i]` holds
/// rung `i`'s counted members; `complete[i]` whether the rung was decided; `safe_up_to_g` the
/// ladder's own answer.
pub fn judge(
    peaks_g: &[f64],
    complete: &[bool],
    rungs: &[Vec<MemberCopies>],
    min_p: f64,
    copies: usize,
    safe_up_to_g: Option<f64>,
) -> LadderRobustness {
    let mut out = Vec::new();
    for (peak_g, members) in peaks_g.iter().zip(rungs) {
        let recovered = |m: &Mode| *m == Mode::Recovered;
        let worst = members.iter().filter(|m| recovered(&m.mode) && m.copies.iter().all(recovered)).count();
        let best = members.iter().filter(|m| recovered(&m.mode) || m.copies.iter().any(recovered)).count();
        let fragile_members: Vec<FragileMember> = members
            .iter()
            .filter(|m| m.copies.iter().any(|c| *c != m.mode))
            .map(|m| FragileMember {
                member: m.member,
                angle_deg: m.angle_deg,
                mode: m.mode.name(),
                copies: m.copies.iter().map(|c| c.name()).collect(),
                flips_recovery: m.copies.iter().any(|c| recovered(c) != recovered(&m.mode)),
            })
            .collect();
        out.push(RungRobustness {
            peak_g: *peak_g,
            members: members.len(),
            fragile: fragile_members.len(),
            recovered_worst: worst,
            p_lo_worst: wilson(worst, members.len())[0],
            recovered_best: best,
            p_lo_best: wilson(best, members.len())[0],
            fragile_members,
        });
    }
    let lo = |f: fn(&RungRobustness) -> f64| out.iter().map(f).collect::<Vec<_>>();
    let safe_up_to_g_worst = safe_up_to(peaks_g, complete, &lo(|r| r.p_lo_worst), min_p);
    let safe_up_to_g_best = safe_up_to(peaks_g, complete, &lo(|r| r.p_lo_best), min_p);
    LadderRobustness {
        copies,
        perturbation: format!(
            "the unbalance's angle by ±k·{:e} rad and the rotor's initial x by ±k·{:e} m, k = 1 … {}",
            crate::robustness::ANGLE_STEP_RAD,
            crate::robustness::POSITION_STEP_M,
            copies.div_ceil(2)
        ),
        fragile_members: out.iter().map(|r| r.fragile).sum(),
        flipping_members: out.iter().flat_map(|r| &r.fragile_members).filter(|m| m.flips_recovery).count(),
        safe_up_to_g_worst,
        safe_up_to_g_best,
        safe_survives: safe_up_to_g_worst == safe_up_to_g,
        rungs: out,
    }
}

/// A member's controller process was lost (or missed its realtime budget): the ladder stops
/// there, keeping the rungs it has.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct ControllerLost(pub String);

/// A member's controller sent non-finite commands past the scene's budget: the ladder stops
/// there, keeping the rungs it has (such a member says nothing of the controller's recovery).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct NotControlling(pub String);

/// A member's outcome with the duty of its counted run.
struct Counted {
    result: MemberResult,
    duty: Duty,
    /// The counted run ended once decided.
    decided: bool,
    /// Simulated time of the member's runs (s).
    simulated_s: f64,
    /// The overrides of the counted run (the reference setting's for a verified member): its
    /// perturbed copies start from them.
    sets: Vec<String>,
}

/// Revolutions per block of the orbit's envelope in [`Decision`].
const BLOCK_REVOLUTIONS: f64 = 50.0;

/// An orbit whose largest radius stays within this share of the air gap has settled (the
/// unbalance orbit of the study's rotor is about 1.3 % of it).
const SETTLED_RADIUS: f64 = 0.05;

/// Whether a ladder member's outcome is decided before the scene's end (module doc): fed each
/// output sample by [`Watch`], read after each tick by [`MemberHooks`].
pub struct Decision {
    /// When the shock programme is over (s).
    shock_end: f64,
    /// The steady window's length (s).
    window: f64,
    /// One block of the envelope (s).
    block: f64,
    /// Each bearing plane's air gap (m).
    gaps: Vec<f64>,
    /// Last sample with contact at either bearing (s).
    last_contact: Cell<f64>,
    /// The block being filled, and its largest radius (share of the gap).
    current: Cell<(i64, f64)>,
    /// The largest radius of the last two completed blocks, older first.
    completed: Cell<[Option<f64>; 2]>,
    /// Decided: the run may end.
    decided: Cell<bool>,
}

impl Decision {
    /// The decision for a member of `scene`; `None` when the rotor does not spin (no steady
    /// window) or `enabled` is false.
    pub fn new(scene: &Scene, enabled: bool) -> Option<Self> {
        let window = crate::figures::analysis_spec(scene).window_length();
        if !enabled || window.is_nan() || window <= 0.0 {
            return None;
        }
        let gaps = scene.rotor.bearings().map(|p| p.contact.gap).collect();
        Some(Self {
            shock_end: scene.base.breakpoints().last().copied().unwrap_or(0.0),
            window,
            block: window * BLOCK_REVOLUTIONS / crate::analysis::STEADY_REVOLUTIONS,
            gaps,
            last_contact: Cell::new(f64::NEG_INFINITY),
            current: Cell::new((i64::MIN, 0.0)),
            completed: Cell::new([None, None]),
            decided: Cell::new(false),
        })
    }

    /// The start of the steady window of the scene's full run (s): what a decided member's
    /// figures carry (the verification of late recoveries reads it).
    pub fn full_window_start(&self, scene: &Scene) -> f64 {
        (scene.duration - self.window).max(0.0)
    }

    /// One output sample.
    fn sample(&self, record: &Record) {
        let t = record.a.t_s;
        let mut radius: f64 = 0.0;
        for (i, gap) in self.gaps.iter().enumerate().take(record.planes()) {
            let row = record.plane(i);
            if row.loads.contact_force_n > 0.0 {
                self.last_contact.set(t);
            }
            radius = radius.max(row.motion.dx_m.hypot(row.motion.dy_m) / gap);
        }
        let k = (t / self.block).floor() as i64;
        let (index, peak) = self.current.get();
        if k == index {
            self.current.set((index, peak.max(radius)));
            return;
        }
        // A block is complete: its peak joins the last two, and the decision is taken here.
        let mut completed = self.completed.get();
        if index != i64::MIN {
            completed = [completed[1], Some(peak)];
            self.completed.set(completed);
        }
        self.current.set((k, radius));
        let clear_since = self.last_contact.get().max(self.shock_end);
        let settled = match completed {
            [Some(before), Some(last)] => last <= before.max(SETTLED_RADIUS),
            _ => false,
        };
        if t - clear_since >= self.window && settled {
            self.decided.set(true);
        }
    }
}

/// The sink of a member's run: the samples go on to `inner`, and to the decision.
struct Watch<'a> {
    inner: &'a mut dyn Sink,
    decision: Option<&'a Decision>,
}

impl Sink for Watch<'_> {
    fn sample(&mut self, record: &Record) {
        self.inner.sample(record);
        if let Some(d) = self.decision {
            d.sample(record);
        }
    }

    fn planes(&mut self, planes: &dyn crate::run::PlaneStates) {
        self.inner.planes(planes);
    }
}

/// The hooks of a member's run: stopped by the flag (SIGINT/SIGTERM), ended once decided.
struct MemberHooks<'a> {
    stop: &'a AtomicBool,
    decision: Option<&'a Decision>,
}

impl Hooks for MemberHooks<'_> {
    fn cancelled(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    fn finished(&self) -> bool {
        self.decision.is_some_and(|d| d.decided.get())
    }
}

/// The overrides that give rung peak `g` (G) to the scene's programme.
pub fn rung_overrides(scene: &Scene, g: f64) -> anyhow::Result<Vec<String>> {
    let raw = scene.resolved()?;
    let first = raw.shock.first().and_then(shock_table::ShockSpec::size).map(|(_, v)| v);
    let Some(first) = first.filter(|v| *v > 0.0) else {
        anyhow::bail!("the shock ladder needs a scene whose first [[shock]] has a size (peak_g, amplitude_g or scale)");
    };
    let factor = g / first;
    Ok(raw
        .shock
        .iter()
        .enumerate()
        .filter_map(|(k, s)| s.size().map(|(field, v)| format!("shock[{k}].{field}={:?}", v * factor)))
        .collect())
}

/// The figures of a member's run, a decided one's steady window taken as the full run's.
fn figures_of(scene: &Scene, result: &RunResult, decision: &Option<Decision>) -> crate::ensemble::member::Figures {
    let (mut f, _) = figures(scene, result);
    if let Some(d) = decision.as_ref().filter(|d| d.decided.get()) {
        f.steady_window_start_s = d.full_window_start(scene);
    }
    f
}

/// One run of a member's scene with its duty and decision; `None` when interrupted.
fn run_scene(
    scene: &Scene,
    bearing: Bearing,
    end_when_decided: bool,
    stop: &AtomicBool,
) -> anyhow::Result<Option<(RunResult, Duty, Option<Decision>)>> {
    let mut trace = Trace::with_capacity((scene.duration / scene.output_interval).ceil() as usize + 2);
    // A start: each plane's duty takes its own bearing's ball count at its first sample.
    let balls = scene.plane(0).balls.count();
    let decision = Decision::new(scene, end_when_decided);
    let mut hooks = MemberHooks { stop, decision: decision.as_ref() };
    let mut duty_sink = DutySink::new(&mut trace, bearing, balls);
    let mut sink = Watch { inner: &mut duty_sink, decision: decision.as_ref() };
    let run = run_into(scene, &crate::cosim::Launch::default(), &mut hooks, &mut sink)?;
    let duty = duty_sink.finish();
    match &run.outcome {
        Outcome::Interrupted => return Ok(None),
        // Ctrl-C in a terminal stops the controller process too: interrupted, not lost.
        _ if stop.load(Ordering::Relaxed) && run.outcome != Outcome::Completed => return Ok(None),
        // A member whose controller was lost says nothing of the controller's recovery: it
        // must not be counted (as a run that did not complete, it would count as diverged).
        Outcome::PeerLost(why) | Outcome::MissBudget(why) | Outcome::OverrunBudget(why) => {
            return Err(ControllerLost(why.clone()).into());
        }
        Outcome::InvalidCommands(why) => return Err(NotControlling(why.clone()).into()),
        Outcome::Completed | Outcome::Diverged(_) => {}
    }
    Ok(Some((RunResult { trace, run }, duty, decision)))
}

/// Runs a member with its duty; `None` when interrupted.
fn run_counted(
    point: &Point,
    spec: &EnsembleSpec,
    j: usize,
    bearing: Bearing,
    end_when_decided: bool,
    stop: &AtomicBool,
) -> anyhow::Result<Option<Counted>> {
    let run = |scene: &Scene| run_scene(scene, bearing, end_when_decided, stop);
    let (mut sets, draw, drawn) = member_overrides(point, spec, j);
    let scene = load_scene(point.path, &sets)?;
    let Some((result, mut duty, decision)) = run(&scene)? else { return Ok(None) };
    let first = figures_of(&scene, &result, &decision);
    let mut simulated_s = result.run.clock.simulated;
    let mut decided = decision.is_some_and(|d| d.decided.get());
    drop(result);
    let mut verified = None;
    if spec.verify && close_to_decision(&first, scene.first_shock_start(), spec) {
        sets = verification_overrides(point, spec, &drawn);
        let reference = load_scene(point.path, &sets)?;
        let Some((result, d, decision)) = run(&reference)? else { return Ok(None) };
        verified = Some(figures_of(&reference, &result, &decision));
        simulated_s += result.run.clock.simulated;
        decided = decision.is_some_and(|d| d.decided.get());
        duty = d;
    }
    Ok(Some(Counted {
        result: MemberResult::new(point, j, &draw, drawn, first, verified),
        duty,
        decided,
        simulated_s,
        sets,
    }))
}

/// Copy `k` (1 …) of a counted member: its counted run perturbed as `plant run --robustness`
/// perturbs a run; its mode and simulated time, `None` when interrupted.
fn run_copy(
    path: &Path,
    member: &Counted,
    k: usize,
    bearing: Bearing,
    end_when_decided: bool,
    stop: &AtomicBool,
) -> anyhow::Result<Option<(Mode, f64)>> {
    let scene = load_scene(path, &member.sets)?;
    let mut sets = member.sets.clone();
    sets.extend(crate::robustness::perturbation(&scene, k)?);
    let scene = load_scene(path, &sets)?;
    let Some((result, _, decision)) = run_scene(&scene, bearing, end_when_decided, stop)? else { return Ok(None) };
    Ok(Some((figures_of(&scene, &result, &decision).mode, result.run.clock.simulated)))
}

/// Each rung of the ladder from its counted members (sorted by member here) and whether its
/// own stopping rule decided it.
fn rungs_of(counted: &mut [Vec<Counted>], decided: &[bool], settings: &Settings) -> Vec<Rung> {
    let mut rungs = Vec::new();
    for (i, c) in counted.iter_mut().enumerate() {
        c.sort_by_key(|m| m.result.member);
        let refs: Vec<&MemberResult> = c.iter().map(|m| &m.result).collect();
        // The ladder stops a rung by its own rule (`decided`); the statistics' stopping reason
        // is not read.
        let duties: Vec<&Duty> = c.iter().map(|m| &m.duty).collect();
        rungs.push(Rung {
            peak_g: settings.peaks_g[i],
            tally: tally(&refs),
            verification: crate::ensemble::tally::verified(&refs),
            complete: decided[i],
            duty: rung_duty(&duties),
            duty_planes: (0..duties.iter().map(|d| d.planes.len()).min().unwrap_or(0))
                .map(|k| rung_duty(&duties.iter().map(|d| &d.planes[k]).collect::<Vec<_>>()))
                .collect(),
        });
    }
    rungs
}

/// What the perturbed copies of the ladder's members run with.
struct Copies<'a> {
    path: &'a Path,
    base: &'a crate::config::Scene,
    bearing: Bearing,
    end_early: bool,
    stop: &'a AtomicBool,
    log: &'a (dyn Fn(&str) + Sync),
}

impl Copies<'_> {
    /// Runs `settings.robustness` perturbed copies of every counted member and judges the
    /// ladder on them: the answer (none when interrupted or failed), the copies' simulated time,
    /// whether a copy was interrupted, and the first failure.
    fn judged(
        &self,
        counted: &[Vec<Counted>],
        rungs: &[Rung],
        settings: &Settings,
        safe_up_to_g: Option<f64>,
    ) -> (Option<LadderRobustness>, f64, bool, Option<anyhow::Error>) {
        let (path, bearing, end_early, stop) = (self.path, self.bearing, self.end_early, self.stop);
        let copies = settings.robustness;
        let work: Vec<(usize, usize, usize)> = counted
            .iter()
            .enumerate()
            .flat_map(|(i, c)| (0..c.len()).flat_map(move |m| (1..=copies).map(move |k| (i, m, k))))
            .collect();
        (self.log)(&format!("ladder robustness: {} perturbed copies of {} members", work.len(), work.len() / copies));
        let done: Vec<anyhow::Result<Option<(Mode, f64)>>> = super::jobs_for(self.base, || {
            work.par_iter().map(|&(i, m, k)| run_copy(path, &counted[i][m], k, bearing, end_early, stop)).collect()
        });
        let (mut simulated_s, mut interrupted, mut failed) = (0.0, false, None);
        let mut modes: Vec<Vec<Vec<Mode>>> = counted.iter().map(|c| c.iter().map(|_| Vec::new()).collect()).collect();
        for (&(i, m, _), r) in work.iter().zip(done) {
            match r {
                Ok(Some((mode, t))) => {
                    modes[i][m].push(mode);
                    simulated_s += t;
                }
                Ok(None) => interrupted = true,
                Err(e) => {
                    failed.get_or_insert(e);
                }
            }
        }
        if failed.is_some() || interrupted || stop.load(Ordering::Relaxed) {
            return (None, simulated_s, interrupted, failed);
        }
        let members: Vec<Vec<MemberCopies>> = counted
            .iter()
            .zip(modes)
            .map(|(c, modes)| {
                c.iter()
                    .zip(modes)
                    .map(|(m, copies)| MemberCopies {
                        member: m.result.member,
                        angle_deg: m.result.angle_deg,
                        mode: m.result.counted().mode,
                        copies,
                    })
                    .collect()
            })
            .collect();
        let complete: Vec<bool> = rungs.iter().map(|r| r.complete).collect();
        let answer = judge(&settings.peaks_g, &complete, &members, settings.min_p, copies, safe_up_to_g);
        (Some(answer), simulated_s, false, failed)
    }
}

/// Runs the ladder for the controller whose scene is `path` with `sets`. A member that fails
/// (its controller lost, a run that cannot start) stops the ladder after its round: the result
/// then holds the rungs so far, the undecided ones marked incomplete, with the error beside it.
/// `stable`: the loop's free decay at speed was measured stable (the members may then end once
/// decided, with `settings.end_when_decided`; module doc).
pub fn ladder(
    path: &Path,
    sets: &[String],
    settings: &Settings,
    bearing: Bearing,
    stable: bool,
    stop: &AtomicBool,
    log: &(dyn Fn(&str) + Sync),
) -> anyhow::Result<(LadderResult, Option<anyhow::Error>)> {
    let base = load_scene(path, sets)?;
    let spec = EnsembleSpec {
        members: settings.members,
        batch: settings.batch,
        seed: settings.seed,
        verify: settings.verify,
        ..EnsembleSpec::default()
    };
    let mut points = Vec::new();
    for (i, g) in settings.peaks_g.iter().enumerate() {
        let mut s = sets.to_vec();
        s.extend(rung_overrides(&base, *g)?);
        s.push("output.plots=false".into());
        let scene = load_scene(path, &s)?;
        points.push(Point { path, sets: s, scene, index: i, values: vec![*g] });
    }
    let end_early = settings.end_when_decided && stable;
    let mut member_setting = crate::ensemble::member::setting_description(&base, &spec);
    if end_early {
        member_setting.push_str(
            "; a member ends once its outcome is decided: the shock over, the rotor clear of the touchdown bearing \
             for 200 revolutions and its orbit no longer growing (the loop measured stable)",
        );
    }
    let mut counted: Vec<Vec<Counted>> = points.iter().map(|_| Vec::new()).collect();
    let mut decided = vec![false; points.len()];
    let mut members_run = 0;
    let mut interrupted = false;
    let mut failed: Option<anyhow::Error> = None;
    for round in 0..spec.rounds() {
        let work: Vec<(usize, usize)> = (0..points.len())
            .filter(|&i| !decided[i])
            .flat_map(|i| spec.batch_members(round).map(move |j| (i, j)))
            .collect();
        if work.is_empty() {
            break;
        }
        log(&format!(
            "ladder round {}: {} members on {} rungs",
            round + 1,
            work.len(),
            work.iter().map(|w| w.0).collect::<std::collections::BTreeSet<_>>().len()
        ));
        // A co-simulated controller's members: more at once than cores (super::COSIM_JOBS).
        let done: Vec<anyhow::Result<Option<Counted>>> = super::jobs_for(&base, || {
            work.par_iter().map(|&(i, j)| run_counted(&points[i], &spec, j, bearing, end_early, stop)).collect()
        });
        for r in done {
            match r {
                Ok(Some(c)) => {
                    members_run += 1;
                    counted[c.result.point].push(c);
                }
                Ok(None) => interrupted = true,
                Err(e) => {
                    failed.get_or_insert(e);
                }
            }
        }
        if failed.is_some() {
            break;
        }
        if interrupted || stop.load(Ordering::Relaxed) {
            interrupted = true;
            break;
        }
        for (i, c) in counted.iter().enumerate() {
            let n = c.len();
            let k = c.iter().filter(|m| m.result.counted().mode == crate::grid::Mode::Recovered).count();
            let [lo, hi] = wilson(k, n);
            decided[i] = decided[i] || lo >= settings.min_p || hi < settings.min_p || n >= spec.members;
        }
    }
    let rungs = rungs_of(&mut counted, &decided, settings);
    let safe_up_to_g =
        rungs.iter().take_while(|r| r.complete && r.tally.share.lo >= settings.min_p).last().map(|r| r.peak_g);
    let mut simulated_s: f64 = counted.iter().flatten().map(|m| m.simulated_s).sum();
    let mut robustness = None;
    if settings.robustness > 0 && failed.is_none() && !interrupted {
        let run = Copies { path, base: &base, bearing, end_early, stop, log };
        let (answer, copies_s, copies_interrupted, copies_failed) =
            run.judged(&counted, &rungs, settings, safe_up_to_g);
        simulated_s += copies_s;
        interrupted = copies_interrupted || (answer.is_none() && copies_failed.is_none());
        robustness = answer;
        failed = copies_failed;
    }
    let verified = rungs.iter().map(|r| r.verification.verified).sum();
    let ended_when_decided = counted.iter().flatten().filter(|m| m.decided).count();
    let result = LadderResult {
        rungs,
        safe_up_to_g,
        member_setting,
        members_run,
        verified,
        ended_when_decided,
        simulated_s,
        interrupted,
        robustness,
    };
    Ok((result, failed))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// All of n recovered gives the lower bound n / (n + z²) (the Wilson interval at p = 1), so
    /// min_p = 0.9 needs n ≥ 9 z² = 34.57: 35 members; 16 of 16 reach only 16 / 19.84 = 0.806.
    #[test]
    fn the_members_a_rung_needs_to_reach_min_p() {
        let z2 = 1.959_963_984_540_054_f64.powi(2);
        assert_eq!(members_needed(0.9), Some(35));
        assert_eq!(members_needed(0.95), Some((19.0 * z2).ceil() as usize));
        assert_eq!(members_needed(0.5), Some(z2.ceil() as usize));
        assert_eq!(members_needed(0.0), Some(1));
        assert_eq!(members_needed(1.0), None);
        let s = |members| Settings { members, ..Settings::default() };
        let why = s(16).unreachable().expect("16 members cannot reach 0.9");
        assert!(why.contains("ladder.members = 16") && why.contains("0.806") && why.contains("35"), "{why}");
        assert_eq!(s(35).unreachable(), None);
        assert!(s(34).unreachable().is_some());
        assert!((16.0 / (16.0 + z2) - wilson(16, 16)[0]).abs() < 1e-12);
    }

    /// The ladder's robustness from its members' copies: a member with a copy in another mode is
    /// fragile; one whose recovery flips lowers the rung's worst case, and the highest safe
    /// shock survives only when the worst case gives the same rung. 35 of 35 recovered gives the
    /// Wilson lower bound 35 / (35 + z²) = 0.9013 ≥ 0.9; 34 of 35 gives
    /// (p + z²/2n − z √(p(1−p)/n + z²/4n²)) / (1 + z²/n) = 0.8545 (p = 34/35) < 0.9.
    #[test]
    fn the_ladder_says_which_members_are_fragile_and_whether_its_safe_shock_survives() {
        let z: f64 = 1.959_963_984_540_054;
        let (n, p) = (35.0, 34.0 / 35.0);
        let lower_34 =
            (p + z * z / (2.0 * n) - z * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt()) / (1.0 + z * z / n);
        assert!((lower_34 - 0.8545).abs() < 5e-4, "{lower_34}");
        let member = |j, mode, copies: &[Mode]| MemberCopies {
            member: j,
            angle_deg: Some(j as f64),
            mode,
            copies: copies.to_vec(),
        };
        let all = |copies: &[Mode]| (0..35).map(|j| member(j, Mode::Recovered, copies)).collect::<Vec<_>>();
        let steady = [Mode::Recovered, Mode::Recovered];
        // 3 G: every member and copy recovered. 10 G: member 7 rebounds in its second copy, and
        // member 9 ends in dry whirl where its copies rebound (fragile, but not recovered in any
        // run, so the rung's counts do not move).
        let mut ten = all(&steady);
        ten[7].copies = vec![Mode::Recovered, Mode::Rebound];
        ten.push(member(35, Mode::DryWhirl, &[Mode::Rebound, Mode::DryWhirl]));
        let rungs = vec![all(&steady), ten];
        let complete = [true, true];
        // The ladder's own answer with 35 of 35 and 35 of 36 recovered at 10 G: the test gives it
        // as the counted modes say (10 G's 35 of 36: lower bound below 0.9, so 3 G).
        let r = judge(&[3.0, 10.0], &complete, &rungs, 0.9, 2, Some(3.0));
        assert_eq!((r.fragile_members, r.flipping_members), (2, 1));
        assert_eq!(r.rungs[0].fragile, 0);
        assert_eq!((r.rungs[1].fragile, r.rungs[1].recovered_worst, r.rungs[1].recovered_best), (2, 34, 35));
        let flip = &r.rungs[1].fragile_members[0];
        assert_eq!(
            (flip.member, flip.mode, flip.copies.clone(), flip.flips_recovery),
            (7, "recovered", vec!["recovered", "rebound"], true)
        );
        assert!(!r.rungs[1].fragile_members[1].flips_recovery);
        assert!((r.rungs[0].p_lo_worst - 35.0 / (35.0 + z * z)).abs() < 1e-12);
        assert_eq!(r.safe_up_to_g_worst, Some(3.0));
        assert!(r.safe_survives, "3 G in the worst case as in the ladder");
        // Without member 35 the 10 G rung is 35 of 35: safe up to 10 G in the ladder, but member
        // 7's flip leaves 34 of 35 in the worst case: the safe shock does not survive.
        let mut rungs = rungs;
        rungs[1].pop();
        let r = judge(&[3.0, 10.0], &complete, &rungs, 0.9, 2, Some(10.0));
        assert!((r.rungs[1].p_lo_worst - lower_34).abs() < 1e-9, "{}", r.rungs[1].p_lo_worst);
        assert_eq!((r.safe_up_to_g_worst, r.safe_up_to_g_best, r.safe_survives), (Some(3.0), Some(10.0), false));
        let words = r.words(Some(10.0));
        assert!(words.contains("FRAGILE members: 1 of 35 at 10 G"), "{words}");
        assert!(words.contains("does NOT survive: 3 G in the worst case, 10 G in the best"), "{words}");
        // An incomplete rung is safe in no case.
        let r = judge(&[3.0, 10.0], &[false, true], &rungs, 0.9, 2, None);
        assert_eq!((r.safe_up_to_g_worst, r.safe_up_to_g_best, r.safe_survives), (None, None, true));
        assert!(r.words(None).contains("the highest safe shock (none) survives"));
    }

    /// A member ended once decided is graded as its full run: on the 10 G scene with a
    /// well-damped sampled PD (ξ = 0.1, stable), a rung without contact (1 G) and one every
    /// member recovers from after touching (20 G), the rungs (modes, intervals, recovery times,
    /// verifications, every duty figure) are those of the full runs, to the bit, and the
    /// members simulate less.
    #[test]
    fn a_member_ended_once_decided_is_graded_as_its_full_run() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/paper-10g.toml");
        let sets = ["controller.mode=\"sampled\"", "controller.law=\"pd_delay\"", "controller.damping_ratio=0.1"]
            .map(String::from);
        let scene = load_scene(&path, &sets).expect("scene");
        let bearing = Bearing::of_scene(&scene, Default::default(), 0.5);
        let settings = |early| Settings {
            peaks_g: vec![1.0, 20.0],
            members: 3,
            batch: 3,
            end_when_decided: early,
            ..Settings::default()
        };
        let stop = AtomicBool::new(false);
        let run = |early| {
            let (l, failed) = ladder(&path, &sets, &settings(early), bearing, true, &stop, &|_| {}).expect("ladder");
            assert!(failed.is_none(), "{failed:?}");
            l
        };
        let (early, full) = (run(true), run(false));
        assert_eq!(early.rungs, full.rungs);
        assert_eq!(early.safe_up_to_g, full.safe_up_to_g);
        assert_eq!(full.ended_when_decided, 0);
        assert_eq!(early.ended_when_decided, 6, "every member recovers: each ends once decided");
        assert!(full.rungs[1].duty.contact_time_s.max.is_some_and(|c| c > 0.0), "20 G touches: {:?}", full.rungs[1]);
        assert!(
            early.simulated_s < 0.6 * full.simulated_s,
            "{} s simulated against {} s",
            early.simulated_s,
            full.simulated_s
        );
    }
}
