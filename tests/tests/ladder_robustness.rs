//! The report card's ladder says how robust it is (issue 40 item 1): `ladder.robustness = N`
//! repeats every counted member N times with the perturbations `plant run --robustness` uses,
//! and report.json, report.html and the printed verdict say which members are fragile and
//! whether the highest safe shock survives; without the key, the report is as before.

mod common;

use common::*;
use std::path::Path;
use std::process::Command;

/// Seven members and their 14 copies of the two-plane 10 G scene (1.5 s each) in a debug build
/// on a loaded machine: a hang fails.
const LIMIT: std::time::Duration = std::time::Duration::from_secs(1500);

fn assess(path: &Path, out: &Path) -> std::process::Output {
    output_within(Command::new(plant_bin()).arg("assess").arg(path).arg("--out").arg(out), LIMIT)
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&read_text(path)).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The two-plane asymmetric machine at 10 G sits next to the boundary between recovering and
/// rebounding (docs/results/robustness.md): of the ladder's first 16 members (seed 1), member 6
/// rebounds while its second copy (the unbalance turned back by 1e-9 rad, the rotor moved back
/// by 1 pm) recovers. A ladder of its first seven members must name it, and only it, as
/// fragile, in every output.
#[test]
fn the_ladder_names_a_fragile_member_of_the_two_plane_10g_scene() {
    let dir = TempDir::new("ladder-robustness");
    let path = dir.join("assess.toml");
    let text = format!(
        "scene = {:?}\nparts = [\"ladder\"]\n[[controller]]\nlabel = \"scene PD\"\nset = []\n\
         [ladder]\npeaks_g = [10.0]\nmembers = 7\nbatch = 7\nverify = false\nrobustness = 2\n",
        scene("two-plane-asymmetric-10g.toml").display().to_string()
    );
    std::fs::write(&path, text).unwrap();
    let out = dir.join("out");
    let o = assess(&path, &out);
    assert_exit(&o, 0);
    let report = json(&out.join("report.json"));
    assert_eq!(report["ladder_settings"]["robustness"], 2);
    let ladder = &report["controllers"][0]["ladder"]["result"];
    let r = &ladder["robustness"];
    assert_eq!(r["copies"], 2, "{r:#}");
    assert_eq!(r["fragile_members"], 1, "{r:#}");
    let rung = &r["rungs"][0];
    assert_eq!((rung["peak_g"].as_f64(), rung["members"].as_u64()), (Some(10.0), Some(7)));
    let member = &rung["fragile_members"][0];
    assert_eq!(member["member"], 6, "{r:#}");
    let own = member["mode"].as_str().unwrap();
    let copies: Vec<&str> = member["copies"].as_array().unwrap().iter().map(|c| c.as_str().unwrap()).collect();
    assert_eq!(copies.len(), 2);
    assert!(copies.iter().any(|c| *c != own), "a fragile member has a copy in another mode: {member:#}");
    assert_eq!(member["flips_recovery"], true, "{member:#}");
    // The rung's counts bound the worst and best cases: the members recovered in the ladder
    // (its tally) lie between them.
    let tally = ladder["rungs"][0]["recovered"].as_u64().unwrap();
    let (worst, best) = (rung["recovered_worst"].as_u64().unwrap(), rung["recovered_best"].as_u64().unwrap());
    assert!(worst <= tally && tally <= best && worst < best, "{worst} ≤ {tally} ≤ {best}");
    // No rung is safe with seven members, in any case: the answer survives.
    assert_eq!((ladder["safe_up_to_g"].is_null(), r["safe_survives"].as_bool()), (true, Some(true)));
    // The printed verdict and the page say so.
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("robustness (2 perturbed copies per member): FRAGILE members: 1 of 7 at 10 G"), "{stderr}");
    assert!(stderr.contains("the highest safe shock (none) survives"), "{stderr}");
    let verdict = report["controllers"][0]["verdict"].as_str().unwrap();
    assert!(verdict.contains("FRAGILE members: 1 of 7 at 10 G"), "{verdict}");
    let html = read_text(&out.join("report.html"));
    assert!(html.contains("FRAGILE members: 1 of 7 at 10 G"), "the page's ladder section");
    assert!(html.contains(&format!("<td>{own}</td><td>{}</td>", copies.join(", "))), "the fragile member's row");
}

/// Without `ladder.robustness` the report holds no robustness answer and no copies run: the
/// outputs of an assessment that was valid before are those it gave before.
#[test]
fn without_the_key_the_ladder_runs_no_copies_and_says_nothing_of_them() {
    let dir = TempDir::new("ladder-plain");
    let out = dir.join("out");
    let o = assess(&small_assessment(&dir), &out);
    assert_exit(&o, 0);
    let report = json(&out.join("report.json"));
    assert!(report["ladder_settings"].get("robustness").is_none(), "{:#}", report["ladder_settings"]);
    let ladder = &report["controllers"][0]["ladder"]["result"];
    assert!(ladder.is_object() && ladder.get("robustness").is_none(), "{ladder:#}");
    let text = read_text(&out.join("report.json"));
    assert!(!text.contains("robustness"), "report.json names no robustness: {text}");
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!stderr.contains("perturbed copies"), "{stderr}");
}

/// `plant assess --robustness N` asks the same as the key (and overrides it): the small
/// assessment's two members get one copy each, and the report says so.
#[test]
fn the_flag_asks_for_the_ladders_robustness_as_the_key_does() {
    let dir = TempDir::new("ladder-flag");
    let out = dir.join("out");
    let o = output_within(
        Command::new(plant_bin())
            .arg("assess")
            .arg(small_assessment(&dir))
            .args(["--robustness", "1", "--out"])
            .arg(&out),
        LIMIT,
    );
    assert_exit(&o, 0);
    let report = json(&out.join("report.json"));
    assert_eq!(report["ladder_settings"]["robustness"], 1);
    let r = &report["controllers"][0]["ladder"]["result"]["robustness"];
    assert_eq!((r["copies"].as_u64(), r["rungs"][0]["members"].as_u64()), (Some(1), Some(2)), "{r:#}");
    assert!(String::from_utf8_lossy(&o.stderr).contains("robustness (1 perturbed copy per member)"));
}
