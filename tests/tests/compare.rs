//! End-to-end test of `plant compare`: continuous against sampled PD, in
//! process and over iceoryx2.

mod common;

use common::*;
use std::process::Command;

/// One comparison (a dozen short runs) in a debug build on a loaded machine: a hang fails.
const LIMIT: std::time::Duration = std::time::Duration::from_secs(900);

#[test]
fn compare_reports_deviation_damping_and_mode_per_rate() {
    controller_bin(); // the lockstep runs start the controller next to the plant
    let dir = TempDir::new("compare");
    let out = dir.join("out");
    let o = output_within(
        Command::new(plant_bin())
            .arg("compare")
            .arg(scene("paper-10g.toml"))
            .args(["--rates", "20k,50k", "--maps", "--out"])
            .arg(&out)
            .args(["--set", "scene.duration_s=0.04", "--set", "shock[0].start_s=0.01"])
            // Whole runs whatever this machine's load (the budgets' default would end a late one).
            .args(["--set", "controller.max_miss_fraction=1", "--set", "controller.max_overrun_fraction=1"]),
        LIMIT,
    );
    assert_exit(&o, 0);
    let text = std::fs::read_to_string(out.join("compare.csv")).expect("compare.csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no column {name}"));
    let num = |r: &Vec<&str>, name: &str| r[col(name)].parse::<f64>().expect("number");
    let modes: Vec<(&str, f64)> = rows.iter().map(|r| (r[col("mode")], num(r, "rate_hz"))).collect();
    assert_eq!(
        modes,
        vec![("continuous", 0.0), ("sampled", 2e4), ("lockstep", 2e4), ("sampled", 5e4), ("lockstep", 5e4)]
    );
    // The continuous loop has the designed damping (free decay, log decrement).
    assert!((num(&rows[0], "damping_ratio") - 0.01).abs() < 5e-4, "{}", num(&rows[0], "damping_ratio"));
    // The sampled loop loses the damping its phase lag costs: at 20 kHz with one sample of
    // delay more than the design has (the decay grows), at 50 kHz less than that.
    for (r, rate) in [(1, 2e4), (3, 5e4)] {
        let (measured, expected) = (num(&rows[r], "damping_ratio"), sampled_damping(0.01, rate, 1.0));
        assert!((measured - expected).abs() < 5e-4, "{rate} Hz: damping {measured}, expected {expected}");
    }
    assert!(num(&rows[1], "damping_ratio") < 0.0 && num(&rows[3], "damping_ratio") > 0.0);
    // Over iceoryx2 the same law gives the same run.
    for (s, l) in [(1, 2), (3, 4)] {
        assert_eq!(rows[s][col("rms_dev_m")], rows[l][col("rms_dev_m")]);
        assert_eq!(rows[s][col("post_shock_mode")], rows[l][col("post_shock_mode")]);
    }
    // The sampled runs deviate from the continuous one, less at the higher rate; RMS below max.
    for r in &rows[1..] {
        assert!(num(r, "rms_dev_m") > 0.0 && num(r, "rms_dev_m") <= num(r, "max_dev_m"), "{r:?}");
    }
    assert!(num(&rows[3], "rms_dev_m") < num(&rows[1], "rms_dev_m"), "50 kHz should follow the continuous law closer");
    for png in ["compare_radius.png", "compare_orbit.png"] {
        let n = Png::read(&out.join(png)).count_in_plot(SERIES_BLUE);
        assert!(n > 300, "{png}: {n} pixels of the first series");
    }
    // Stability maps: at 20 kHz with one sample of delay the naive PD needs more design damping
    // than the study's 0.01; without the delay it holds 0.01; each extra sample costs more.
    // Every point's measured damping is the design's less its phase lag's cost.
    let points = Table::read(&out.join("stability_map.csv"));
    assert_eq!(points.rows.len(), 2 * (6 + 4));
    for r in 0..points.rows.len() {
        let (rate, value) = (points.num(r, "rate_hz"), points.num(r, "value"));
        let expected = match points.text(r, "map") {
            "rate_damping" => sampled_damping(value, rate, 1.0),
            _ => sampled_damping(0.01, rate, value),
        };
        let measured = points.num(r, "damping_measured");
        assert!((measured - expected).abs() < 5e-4, "{:?}: measured {measured}, expected {expected}", points.rows[r]);
        assert_eq!(points.text(r, "class") == "unstable", measured <= 0.0, "{:?}", points.rows[r]);
    }
    let map = std::fs::read_to_string(out.join("stability_map.csv")).expect("stability_map.csv");
    let class = |m: &str, rate: &str, value: &str| {
        map.lines()
            .find(|l| l.starts_with(&format!("{m},{rate},{value},")))
            .and_then(|l| l.rsplit(',').next())
            .unwrap_or_else(|| panic!("no map point {m} {rate} {value}"))
            .to_string()
    };
    assert_eq!(class("rate_damping", "20000", "0.01"), "unstable");
    assert!(class("rate_damping", "20000", "0.05").starts_with("stable"));
    assert!(class("rate_delay", "20000", "0").starts_with("stable"));
    assert_eq!(class("rate_delay", "20000", "2"), "unstable");
    for png in ["stability_rate_damping.png", "stability_rate_delay.png"] {
        let n = Png::read(&out.join(png)).count_in_plot(SERIES_BLUE);
        assert!(n > 20, "{png}: {n} pixels of the first class");
    }
}

/// The damping ratio the sampled PD keeps at `rate_hz` with `delay` samples, designed for
/// `design` (paper-10g: k_e = 1e6 N/m, k_s = 4.32e5 N/m, m_r = 11.5 kg). The zero-order hold
/// and the delay lag the loop by φ = ω_n T (d + ½) at its natural frequency ω_n = √(k_e / m_r);
/// the lagged proportional force (k_e + k_s) x then does negative work, a damping of
/// −(k_e + k_s) sin φ / ω_n, i.e. Δξ = −(k_e + k_s) φ / (2 k_e) for a small lag.
fn sampled_damping(design: f64, rate_hz: f64, delay: f64) -> f64 {
    let (k_e, k_s, m) = (1e6, 4.32e5, 11.5_f64);
    let phi = (k_e / m).sqrt() / rate_hz * (delay + 0.5);
    design - (k_e + k_s) * phi / (2.0 * k_e)
}

/// The re-levitation law against the study's design on the 10 G scene, both in the
/// controller process: the design stays in dry whirl, `relev` brings the rotor back once
/// its rule is armed (the whirl is established by then).
#[test]
fn relev_brings_the_rotor_back_from_the_dry_whirl_the_design_stays_in() {
    controller_bin();
    let dir = TempDir::new("compare-laws");
    let out = dir.join("out");
    let arm_s = 0.35;
    let o = output_within(
        Command::new(plant_bin())
            .arg("compare")
            .arg(scene("relev-10g.toml"))
            .args(["--laws", "pd_delay,relev", "--out"])
            .arg(&out)
            .args(["--set", "scene.duration_s=0.8", "--set", &format!("controller.params.arm_ms={}", arm_s * 1e3)]),
        LIMIT,
    );
    assert_exit(&o, 0);
    let csv = Table::read(&out.join("laws.csv"));
    assert_eq!(csv.rows.len(), 2);
    for r in 0..2 {
        assert_eq!(csv.text(r, "mode"), "lockstep");
        assert_eq!(csv.text(r, "status"), "completed");
    }
    assert_eq!(csv.text(0, "law"), "pd_delay");
    assert_eq!(csv.text(0, "post_shock_mode"), "dry_whirl");
    assert!(csv.num(0, "recovery_s").is_nan(), "the design should still touch at the end");
    assert!(csv.num(0, "steady_contact_fraction") > 0.9);
    assert!(csv.num(0, "whirl_hz") < -30.0, "backward whirl expected: {}", csv.num(0, "whirl_hz"));
    assert_eq!(csv.text(1, "law"), "relev");
    assert_eq!(csv.text(1, "post_shock_mode"), "recovered");
    assert_eq!(csv.num(1, "steady_contact_fraction"), 0.0);
    // Shock at 0.02 s: the last contact comes within 50 ms of arming, not before it.
    let recovery = csv.num(1, "recovery_s");
    assert!(recovery > arm_s - 0.02 && recovery < arm_s - 0.02 + 0.05, "recovery {recovery} s");
    for png in ["laws_radius.png", "laws_current.png", "laws_orbit.png"] {
        let n = Png::read(&out.join(png)).count_in_plot(SERIES_BLUE);
        assert!(n > 300, "{png}: {n} pixels of the first law");
    }
}

#[test]
fn unknown_law_in_compare_is_bad_input() {
    let dir = TempDir::new("compare-bad-law");
    let o = output_within(
        Command::new(plant_bin())
            .arg("compare")
            .arg(scene("relev-10g.toml"))
            .args(["--laws", "pd,bang_bang", "--out"])
            .arg(dir.join("out")),
        LIMIT,
    );
    assert_exit(&o, 2);
    assert!(String::from_utf8_lossy(&o.stderr).contains("bang_bang"), "{}", String::from_utf8_lossy(&o.stderr));
    // Issue 21 item 7: the folder it had created was left empty.
    assert!(!dir.join("out").exists(), "a refused compare leaves no folder behind");
}

/// Issue 22: `plant compare --realtime` runs the scene in realtime and once in lockstep on the
/// same (realtime) integrator setting, and writes one row each. The lockstep row is its own
/// reference; a realtime run without a deadline miss is the lockstep run bit for bit (the
/// reply to sample k is applied at tick k + 1 in both), one with misses may not be.
#[test]
fn compare_realtime_puts_realtime_runs_beside_their_lockstep_twin() {
    controller_bin();
    let dir = TempDir::new("compare-realtime");
    let out = dir.join("out");
    // An earlier comparison's tables of other forms, and a robustness table not asked for.
    let earlier = ["laws.csv", "compare_robustness.json", "stability_damping.png"];
    seed_earlier_outputs(&out, &earlier);
    let o = output_within(
        Command::new(plant_bin())
            .arg("compare")
            .arg(scene("cosim-10g.toml"))
            .args(["--realtime", "--runs", "2", "--out"])
            .arg(&out)
            .args(["--set", "scene.duration_s=0.04", "--set", "shock[0].start_s=0.01"])
            // Whole runs whatever this machine's load (the budgets' default would end a late one).
            .args(["--set", "controller.max_miss_fraction=1", "--set", "controller.max_overrun_fraction=1"]),
        LIMIT,
    );
    assert_exit(&o, 0);
    let text = std::fs::read_to_string(out.join("realtime.csv")).unwrap();
    let rows: Vec<Vec<&str>> = text.lines().skip(1).map(|l| l.split(',').collect()).collect();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no column {name}"));
    let modes: Vec<(&str, &str)> = rows.iter().map(|r| (r[col("run")], r[col("mode")])).collect();
    assert_eq!(modes, [("0", "lockstep"), ("1", "realtime"), ("2", "realtime")]);
    assert_eq!((rows[0][col("same_as_lockstep")], rows[0][col("deadline_misses")]), ("true", "0"));
    let num = |r: &Vec<&str>, c: &str| r[col(c)].parse::<f64>().unwrap_or_else(|_| panic!("{c}: {r:?}"));
    assert_eq!(num(&rows[0], "max_dev_m"), 0.0);
    for r in &rows[1..] {
        if r[col("deadline_misses")] == "0" {
            assert_eq!(r[col("same_as_lockstep")], "true", "a realtime run without a miss: {r:?}");
        }
        if r[col("same_as_lockstep")] == "true" {
            assert_eq!(num(r, "max_dev_m"), 0.0, "{r:?}");
        }
    }
    for r in &rows {
        for c in ["tick_max_us", "integration_max_us"] {
            assert!(num(r, c) > 0.0 && num(r, c).is_finite(), "{c}: {r:?}");
        }
    }
    assert!(stderr(&o).contains("realtime 2:"), "{}", stderr(&o));
    assert!(out.join("realtime_radius.png").exists());
    assert_only_this_runs_outputs(&out, &earlier, plant::compare::FILES);
}

/// Issue 40 item 1: `plant compare --robustness N` gives each compared run the robustness
/// answer of `plant run --robustness N` (its N perturbed members and its refined-integrator
/// run) and says of each run's difference from the reference (the first law) whether it lies
/// within the runs' spreads: compare_robustness.csv and .json. Checked against the law table
/// written beside it: each run's own peak force lies in its spread, the reference is the same as
/// itself, and each verdict on the force follows from the two runs' ranges in the JSON.
/// Bad members are refused before anything runs, nothing written.
#[test]
fn compare_says_how_robust_each_run_and_each_difference_is() {
    controller_bin();
    let dir = TempDir::new("compare-robustness");
    let out = dir.join("out");
    let o = output_within(
        Command::new(plant_bin())
            .arg("compare")
            .arg(scene("paper-10g.toml"))
            .args(["--laws", "pd,pd_delay", "--robustness", "2", "--out"])
            .arg(&out)
            .args(["--set", "scene.duration_s=0.04", "--set", "shock[0].start_s=0.01"])
            .args(["--set", "controller.max_miss_fraction=1", "--set", "controller.max_overrun_fraction=1"]),
        LIMIT,
    );
    assert_exit(&o, 0);
    let laws = Table::read(&out.join("laws.csv"));
    let robust = Table::read(&out.join("compare_robustness.csv"));
    assert_eq!(robust.rows.len(), 2);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("compare_robustness.json")).unwrap()).unwrap();
    assert_eq!(json["reference"], "pd");
    let runs = json["runs"].as_array().expect("runs");
    assert_eq!(runs.len(), 2);
    for (r, run) in runs.iter().enumerate() {
        assert_eq!(robust.text(r, "run"), laws.text(r, "law"));
        assert_eq!(robust.num(r, "members"), 2.0);
        assert!(robust.num(r, "same_mode") <= 2.0);
        assert!(["robust", "fragile", "unconverged"].contains(&robust.text(r, "verdict")), "{:?}", robust.rows[r]);
        assert_eq!(robust.text(r, "run_mode"), laws.text(r, "post_shock_mode"));
        let force = laws.num(r, "max_contact_force_n");
        assert!(robust.num(r, "force_min_n") <= force && force <= robust.num(r, "force_max_n"), "{:?}", robust.rows[r]);
        assert_eq!(run["robustness"]["members"], 2);
        assert!(run["robustness"]["integration"]["setting"].is_string(), "the refined run: {run}");
    }
    for c in ["mode_vs_reference", "force_vs_reference", "radius_vs_reference"] {
        assert_eq!(robust.text(0, c), "same");
    }
    let range = |r: usize| {
        let i = &runs[r]["robustness"]["integration"]["max_contact_force_n"];
        let refined = i.as_f64().unwrap_or(f64::NAN);
        (robust.num(r, "force_min_n").min(refined), robust.num(r, "force_max_n").max(refined))
    };
    let ((lo_a, hi_a), (lo_b, hi_b)) = (range(0), range(1));
    let expected = if laws.num(0, "max_contact_force_n") == laws.num(1, "max_contact_force_n") {
        "same"
    } else if lo_a <= hi_b && lo_b <= hi_a {
        "within_spread"
    } else {
        "beyond_spread"
    };
    assert_eq!(robust.text(1, "force_vs_reference"), expected, "{:?} {:?}", (lo_a, hi_a), (lo_b, hi_b));

    // Too many members: refused by the key, nothing written.
    let bad = dir.join("bad");
    let o = output_within(
        Command::new(plant_bin())
            .arg("compare")
            .arg(scene("paper-10g.toml"))
            .args(["--laws", "pd", "--robustness", "300", "--out"])
            .arg(&bad),
        LIMIT,
    );
    assert_exit(&o, 2);
    assert!(
        ["--robustness", "`300`", "from 0 to 256"].iter().all(|n| String::from_utf8_lossy(&o.stderr).contains(n)),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(!bad.exists(), "a refused compare leaves no folder behind");
}
