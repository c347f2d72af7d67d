//! Bad input's messages, by class (issue 40 item 8; the campaign: docs/dev/messages.md): every
//! flag that takes a number refuses a hostile value (negative, zero where it counts, NaN,
//! infinite, 1e300, empty, a word, a fraction where it counts) with exit 2, naming the flag,
//! the value as typed, what the value is and its unit or range, and writes nothing; a `--set`
//! of the wrong type is blamed on that one override, in words.

mod common;

use common::*;
use std::process::Command;

/// Refusals happen before anything runs: a hang fails.
const LIMIT: std::time::Duration = std::time::Duration::from_secs(120);

/// The hostile values of a class.
const COUNTS: &[&str] = &["-1", "nan", "inf", "1e300", "1e-300", "", "abc", "2.5"];
const NUMBERS: &[&str] = &["nan", "inf", "-inf", "1e300", "", "abc"];

/// Each number-taking flag: the command before it, the flag, what its refusal says (meaning,
/// unit or range), and the class of values it refuses (extra values of its own range after).
fn flags() -> Vec<(Vec<String>, &'static str, &'static str, Vec<&'static str>)> {
    let paper = scene("paper-10g.toml").display().to_string();
    let two_plane = scene("two-plane-asymmetric-10g.toml").display().to_string();
    let v = |a: &[&str]| a.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let with = |class: &[&'static str], more: &[&'static str]| [class, more].concat();
    vec![
        (
            v(&["run", &paper]),
            "--robustness",
            "is not a number of perturbed runs: a whole number from 0 to 256",
            with(COUNTS, &["257"]),
        ),
        (v(&["run", &paper]), "--save-state-at", "is not a time in the run: a number in s", vec!["", "abc"]),
        (v(&["assess", &paper]), "--robustness", "is not a number of perturbed runs", with(COUNTS, &["257"])),
        (v(&["compare", &paper]), "--robustness", "is not a number of perturbed runs", with(COUNTS, &["257"])),
        (
            v(&["compare", &paper, "--realtime"]),
            "--runs",
            "is not a number of realtime runs: a whole number from 1 to 1000",
            with(COUNTS, &["0", "1001"]),
        ),
        (
            v(&["campbell", &two_plane]),
            "--max-speed-hz",
            "is not a spin speed: a finite number from 0 to 100000 Hz",
            with(NUMBERS, &["-1", "100001"]),
        ),
        (
            v(&["campbell", &two_plane]),
            "--points",
            "is not a number of speeds: a whole number from 2 to 10000",
            with(COUNTS, &["0", "1", "10001"]),
        ),
        (
            v(&["campbell", &two_plane]),
            "--decay-speeds-hz",
            "is not a spin speed: a finite number from 0 to 100000 Hz",
            vec!["-1", "nan", "inf", "1e300", "abc"],
        ),
        (
            v(&["linear", &paper]),
            "--speed-hz",
            "is not a spin speed: a finite number from 0 to 100000 Hz",
            with(NUMBERS, &["-1"]),
        ),
        (
            v(&["fmu", &paper]),
            "--fmi",
            "is not an FMI version: a whole number from 2 to 3",
            with(COUNTS, &["1", "4", "259"]),
        ),
        (v(&["ensemble", &paper]), "--round", "is not a round: a whole number from 0 to 10000", COUNTS.to_vec()),
        (
            v(&["bench", "ipc"]),
            "--samples",
            "is not a number of round trips: a whole number from 1 to 10000000",
            with(COUNTS, &["0"]),
        ),
        (v(&["bench", "ipc"]), "--warmup", "is not a number of round trips", COUNTS.to_vec()),
        (
            v(&["bench", "ipc"]),
            "--spin-us",
            "is not a busy-poll budget: a finite number from 0 to 1000000 µs",
            with(NUMBERS, &["-1"]),
        ),
        (v(&["bench", "ipc"]), "--pin-cores", "is not a core number: a whole number from 0 to 1023", COUNTS.to_vec()),
        (
            v(&["bench", "host"]),
            "--rate-hz",
            "is not a tick rate: a finite number from 1 to 1000000 Hz",
            with(NUMBERS, &["-1", "0", "1e-300"]),
        ),
        (
            v(&["bench", "host"]),
            "--seconds",
            "is not a loop's duration: a finite number from 0.001 to 3600 s",
            with(NUMBERS, &["-1", "0", "1e-300"]),
        ),
        (
            v(&["bench", "host"]),
            "--realtime-priority",
            "is not a realtime priority (0: off): a whole number from 0 to 99",
            with(COUNTS, &["100"]),
        ),
        (v(&["bench", "tick"]), "--pin-core", "is not a core number", COUNTS.to_vec()),
        (
            v(&["bench", "tick"]),
            "--repeats",
            "is not a number of timed runs: a whole number from 1 to 1000",
            with(COUNTS, &["0"]),
        ),
        (v(&["bench", "accuracy"]), "--repeats", "is not a number of timed runs", with(COUNTS, &["0"])),
        (
            v(&["bench", "ensemble"]),
            "--members",
            "is not a number of members: a whole number from 1 to 10000",
            with(COUNTS, &["0"]),
        ),
    ]
}

/// Every number-taking flag refuses every hostile value of its class with exit 2, the flag,
/// the value as typed and what it should be, and writes nothing.
#[test]
fn every_number_flag_refuses_hostile_values_naming_flag_value_and_unit() {
    let dir = TempDir::new("messages-flags");
    let mut failures = Vec::new();
    for (command, flag, says, values) in flags() {
        for value in values {
            let out = dir.join("out");
            let mut cmd = Command::new(plant_bin());
            cmd.args(&command).arg(format!("{flag}={value}"));
            if command[0] != "bench" || command[1] != "ipc" {
                cmd.arg("--out").arg(&out);
            }
            let o = output_within(&mut cmd, LIMIT);
            let err = stderr(&o);
            let first = err.lines().find(|l| l.contains("error")).unwrap_or("").to_string();
            let names = first.contains(flag) && first.contains(&format!("`{value}`")) && first.contains(says);
            if o.status.code() != Some(2) || !names || out.exists() {
                failures.push(format!("{} {flag}={value:?}: exit {:?}: {first}", command.join(" "), o.status.code()));
            }
        }
    }
    assert!(failures.is_empty(), "{} weak refusals:\n{}", failures.len(), failures.join("\n"));
}

/// A `--set` of the wrong type names that one override (not every `--set` given) and the type
/// in words.
#[test]
fn a_set_of_the_wrong_type_is_blamed_on_that_override_in_words() {
    let dir = TempDir::new("messages-set");
    let cases = [
        ("rotor.mass_kg=\"\"", "--set rotor.mass_kg=\"\": invalid type: string \"\", expected a number"),
        ("rotor.speed_hz=true", "--set rotor.speed_hz=true: invalid type: boolean `true`, expected a number"),
        (
            "integrator.substeps=-1",
            "--set integrator.substeps=-1: invalid value: integer `-1`, expected a whole number ≥ 0",
        ),
        ("touchdown.air_gap_mm=[1]", "--set touchdown.air_gap_mm=[1]: invalid type: sequence, expected a number"),
        (
            "integrator.substeps=1e300",
            "--set integrator.substeps=1e300: invalid type: floating point `1e300`, expected a whole number ≥ 0",
        ),
        ("integrator.method=-1", "--set integrator.method=-1: expected one of the key's names, in quotes"),
    ];
    for (set, says) in cases {
        let out = dir.join("out");
        let o = output_within(
            &mut plant_run(&scene("paper-10g.toml"), &out, &["scene.duration_s=0.002", "output.plots=false", set]),
            LIMIT,
        );
        assert_exit(&o, 2);
        let err = stderr(&o);
        assert!(err.contains(says), "{set}: {err}");
        assert!(!err.contains("--set scene.duration_s"), "blamed on the other overrides too: {err}");
        assert!(!out.exists(), "nothing written");
    }
}
