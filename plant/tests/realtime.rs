//! The realtime setting (`integrator.realtime`): what a realtime scene integrates on, and that
//! its cost per tick is bounded in evaluations of the model (never in seconds: timing is
//! measured by `plant bench tick`, not asserted).

use plant::config::{load_scene, RealtimeSetting, Scene};
use plant::integrate::Method;
use plant::model::RaceWhenClear;
use plant::run::{run, Hooks, Outcome, Quiet};
use std::path::{Path, PathBuf};

fn cosim_10g() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/cosim-10g.toml")
}

fn load(sets: &[&str]) -> Scene {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    load_scene(&cosim_10g(), &sets).unwrap()
}

/// A realtime scene runs the fixed-step setting by default, says so, and records it in the
/// resolved scene; `integrator.realtime = "scene"` and the other modes keep the scene's keys.
#[test]
fn a_realtime_scene_gets_the_fixed_step_setting_unless_it_asks_for_its_own() {
    let lockstep = load(&[]);
    assert_eq!((lockstep.integrator.method, lockstep.plane(0).race_when_clear), (Method::Dp5, RaceWhenClear::Free));
    assert!(lockstep.warnings.is_empty(), "{:?}", lockstep.warnings);

    let realtime = load(&["controller.mode=\"realtime\""]);
    let i = &realtime.integrator;
    assert_eq!((i.method, i.substeps, i.realtime), (Method::Rk4, 1, RealtimeSetting::Fixed));
    // The stability estimate's substeps under a 10 kN contact at 20 kHz.
    assert_eq!(i.contact_substeps, plant::stability::safe_contact_substeps(&realtime, Method::Rk4));
    assert!(i.contact_substeps > 1, "{}", i.contact_substeps);
    assert!(matches!(realtime.plane(0).race_when_clear, RaceWhenClear::Parked(_)));
    let said = realtime.warnings.join("\n");
    assert!(said.contains("fixed-step setting") && said.contains("dp5 rtol 1e-6"), "{said}");
    // What ran is what the run folder's scene.toml says: rerun, it is the same setting, unsaid.
    let resolved = realtime.to_toml().unwrap();
    assert!(resolved.contains("method = \"rk4\"") && resolved.contains("race_when_clear = \"parked\""), "{resolved}");
    let again = realtime.reload(&[]).unwrap();
    assert_eq!(again.integrator.contact_substeps, i.contact_substeps);
    assert!(again.warnings.is_empty(), "{:?}", again.warnings);

    let own = load(&["controller.mode=\"realtime\"", "integrator.realtime=\"scene\""]);
    assert_eq!((own.integrator.method, own.plane(0).race_when_clear), (Method::Dp5, RaceWhenClear::Free));
    assert!(own.warnings.is_empty(), "{:?}", own.warnings);
    // The ensembles' fast setting is the same one.
    assert_eq!(
        lockstep.fixed_step_overrides(),
        plant::ensemble::member::setting_overrides(&lockstep, plant::ensemble::spec::MemberSetting::Fast)
    );
}

struct Timed;
impl Hooks for Timed {
    fn time_ticks(&self) -> bool {
        true
    }
}

/// The fixed-step setting's cost per tick is bounded: at most `4 × contact_substeps + 1` model
/// evaluations (the last for the cubic Hermite interpolant of an output sample inside the
/// last substep), twice that in the ticks split at the shock's breakpoints, through impacts and
/// rubbing; the scene's adaptive DP5 takes what the contact asks for. Every tick is timed,
/// and the execution-time figures are consistent.
#[test]
fn the_fixed_step_setting_costs_a_bounded_number_of_evaluations_per_tick() {
    // The law in process (sampled mode is the lockstep arithmetic); 60 ms: the shock at 20 ms
    // and the first impacts.
    let sets = ["controller.mode=\"sampled\"", "scene.duration_s=0.06", "output.plots=false"];
    let own = load(&sets);
    let mut fixed_sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    fixed_sets.extend(own.fixed_step_overrides());
    let fixed = load_scene(&cosim_10g(), &fixed_sets).unwrap();
    let n = u64::from(fixed.integrator.contact_substeps);

    let r = plant::run::run_with(&fixed, &plant::cosim::Launch::default(), &mut Timed).unwrap();
    assert_eq!(r.run.outcome, Outcome::Completed);
    let s = plant::summary::Summary::new(&fixed, &r);
    let peak = s.max_contact_force_n.expect("rows before the end");
    assert!(peak > 1000.0, "the window holds impacts: {peak} N");
    assert!(r.run.ticks.max_rhs_evals <= 2 * (4 * n + 1), "{} evaluations in one tick", r.run.ticks.max_rhs_evals);
    assert!(r.run.ticks.max_rhs_evals >= 4 * n, "{} evaluations in one tick", r.run.ticks.max_rhs_evals);
    assert_eq!(s.integrator.max_rhs_evals_per_tick, r.run.ticks.max_rhs_evals);

    let tet = r.run.ticks.tet.as_ref().expect("ticks timed").report();
    let ticks = (fixed.duration / fixed.controller.period).ceil() as u64;
    assert_eq!((tet.tick.count, tet.command.count, tet.integration.count), (ticks, ticks, ticks));
    assert!(tet.integration_contact.count > 0 && tet.integration_contact.count < ticks, "{tet:?}");
    for p in [tet.tick, tet.command, tet.integration, tet.integration_contact] {
        assert!(p.p50 <= p.p99 && p.p99 <= p.p999 && p.p999 <= p.max, "{p:?}");
    }
    assert!(tet.integration.max <= tet.tick.max && tet.command.max <= tet.tick.max, "{tet:?}");
    assert!(tet.integration_contact.max <= tet.integration.max, "{tet:?}");
    let bins = r.run.ticks.tet.as_ref().unwrap().bins();
    assert_eq!(bins.iter().map(|b| b.ticks).sum::<u64>(), ticks);

    // The adaptive setting is not bounded by its setting: the contact makes it take more.
    let adaptive = run(&own, &mut Quiet).unwrap();
    assert!(adaptive.run.ticks.max_rhs_evals > 2 * (4 * n + 1), "{}", adaptive.run.ticks.max_rhs_evals);
    // Untimed runs keep no execution times.
    assert!(adaptive.run.ticks.tet.is_none());
}
