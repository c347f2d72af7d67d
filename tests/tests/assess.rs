//! End-to-end tests of `plant assess`: a small report card of two controllers (one stable, one
//! the study's PD sampled at 20 kHz, unstable), bad input refused before anything runs, an
//! excitation that drives the rotor into the touchdown bearing and a rotor not levitated
//! before the shock (exit 9, the report kept), an external controller killed during the
//! measurement (exit 4), and Ctrl-C midway (exit 130, the parts measured so far kept).

mod common;

use common::*;
use std::path::Path;
use std::process::Command;

/// A few short runs and a small ladder in a debug build on a loaded machine: a hang fails.
const LIMIT: std::time::Duration = std::time::Duration::from_secs(600);

/// Writes the assessment file `path` around the 10 G scene, shortened, with `extra` appended.
fn file(path: &Path, controllers: &str, extra: &str) -> std::path::PathBuf {
    let scene = scene("paper-10g.toml");
    let text = format!(
        "scene = {scene:?}\nset = [\"controller.mode=\\\"sampled\\\"\", \"scene.duration_s=0.3\"]\n{controllers}\n\
         [sensitivity]\nf_min_hz = 20.0\nf_max_hz = 200.0\npoints = 4\nprobe_s = 0.3\nresolution = 0.05\nspeeds = [\"standstill\"]\n\
         [ladder]\npeaks_g = [3.0, 20.0]\nmembers = 2\nbatch = 2\nverify = false\n{extra}",
        scene = scene.display().to_string()
    );
    std::fs::write(path, text).expect("write");
    path.to_path_buf()
}

fn assess(path: &Path, out: &Path) -> std::process::Output {
    output_within(Command::new(plant_bin()).arg("assess").arg(path).arg("--out").arg(out).arg("--quiet"), LIMIT)
}

#[test]
fn a_report_card_of_a_stable_and_an_unstable_controller() {
    let dir = TempDir::new("assess-card");
    let controllers = "[[controller]]\nlabel = \"damped\"\nset = [\"controller.law=\\\"pd_delay\\\"\", \"controller.damping_ratio=0.2\"]\n\
                       [[controller]]\nlabel = \"study pd\"\nset = [\"controller.law=\\\"pd\\\"\"]\n";
    let out = dir.join("out");
    // An earlier assessment's charts of a third controller: not this one's.
    let earlier = ["sensitivity_3.png", "open_loop_3.png"];
    seed_earlier_outputs(&out, &earlier);
    let o = assess(&file(&dir.join("assess.toml"), controllers, ""), &out);
    assert_exit(&o, 0);
    assert_only_this_runs_outputs(&out, &earlier, plant::assess::FILES);
    let r = read_json(&out.join("report.json"));
    let c = r["controllers"].as_array().expect("controllers");
    assert_eq!(c.len(), 2);
    // The damped loop: stable on both axes, a peak, a zone, the closed form's peak near it.
    let s = &c[0]["sensitivity"]["result"];
    for axis in s["axes"].as_array().expect("axes") {
        assert_eq!(axis["stable"], true, "{axis}");
        let measured = num(&axis["peak"], "s_db");
        let closed = num(&s["closed_form"], "s_db");
        assert!((measured - closed).abs() < 0.5, "measured {measured} dB, closed form {closed} dB");
        assert!(["A", "B", "C", "D"].contains(&axis["zone"].as_str().expect("zone")));
    }
    // Its gain and phase margins: computed from the law's linear form on the linear plant and
    // measured from S (L = 1/S − 1); the phase margins agree within the measurement's grid.
    for m in s["margins"].as_array().expect("margins") {
        let (computed, measured) = (&m["computed"], &m["measured"]);
        let (pc, pm) = (num(computed, "phase_margin_deg"), num(measured, "phase_margin_deg"));
        assert!(pc > 0.0 && (pc - pm).abs() < 3.0, "{m}");
        let (fc, fm) = (num(computed, "phase_margin_hz"), num(measured, "phase_margin_hz"));
        assert!((fc - fm).abs() < 0.05 * fc, "{m}");
        assert!(num(computed, "gain_margin_db").is_finite(), "{m}");
    }
    // The study's PD at 20 kHz: unstable, no peak, and its closed form agrees.
    let s = &c[1]["sensitivity"]["result"];
    for axis in s["axes"].as_array().expect("axes") {
        assert_eq!(axis["zone"], "unstable", "{axis}");
        assert!(axis["peak"].is_null());
    }
    assert_eq!(s["closed_form"]["stable"], false);
    assert!(c[1]["verdict"].as_str().expect("verdict").contains("UNSTABLE"));
    // Its orbit is a growing transient, not a vibration: measured, not graded.
    assert_eq!(c[1]["vibration"]["result"]["zone"], "not graded (unstable loop)", "{}", c[1]["vibration"]);
    assert!(["A", "B", "C", "D"].contains(&c[0]["vibration"]["result"]["zone"].as_str().expect("zone")));
    // Vibration and ladder with the duty, for both.
    for k in c {
        assert_eq!(k["vibration"]["status"], "measured", "{}", k["vibration"]);
        let v = &k["vibration"]["result"];
        assert!(num(v, "peak_um") > 0.0 && num(v, "peak_um") < 150.0);
        let rungs = k["ladder"]["result"]["rungs"].as_array().expect("rungs");
        assert_eq!(rungs.len(), 2);
        let top = &rungs[1];
        assert_eq!(top["members"], 2);
        // 20 G: the rotor hits the race; the duty has a force, a pressure and friction.
        let d = &top["duty"];
        assert!(num(&d["peak_contact_force_n"], "max") > 100.0, "{d}");
        assert!(num(&d["peak_race_pressure_mpa"], "max") > 0.0);
        assert!(num(&d["peak_ball_pressure_mpa"], "max") > 0.0);
        assert!(num(&d["friction_energy_j"], "max") > 0.0);
    }
    // Two members per rung cannot lift a rung's lower bound to 0.9 (35 are needed): said on the
    // terminal (with --quiet too), in report.json and on the page; the verdict gives the interval.
    let warning = "ladder.members = 2 cannot reach ladder.min_p = 0.9";
    assert!(
        stderr(&o).contains(&format!("warning: {warning}")) && stderr(&o).contains("at least 35 members"),
        "{}",
        stderr(&o)
    );
    assert!(r["warnings"][0].as_str().expect("warnings").contains(warning), "{}", r["warnings"]);
    for k in c {
        let verdict = k["verdict"].as_str().expect("verdict");
        assert!(verdict.contains("at no rung (at 3 G: ") && verdict.contains("/2 recovered, ["), "{verdict}");
    }
    let html = std::fs::read_to_string(out.join("report.html")).expect("report.html");
    assert!(html.contains("<b>Warning:</b> ladder.members = 2 cannot reach"), "the page warns");
    assert!(html.contains("gain and phase margins") && html.contains(": computed PM "), "the page gives the margins");
    assert!(html.contains("data:image/png;base64,") && html.contains("damped") && html.contains("study pd"));
    assert!(!html.contains("http://") && !html.contains("https://") && !html.contains("<script"), "self-contained");
    for png in ["sensitivity_1.png", "ladder_probability.png", "duty_friction.png"] {
        Png::read(&out.join(png));
    }
}

#[test]
fn bad_input_is_refused_before_anything_runs() {
    let dir = TempDir::new("assess-bad");
    let cases = [
        ("[[controller]]\nlabel = \"x\"\nset = [\"controller.law=\\\"nope\\\"\"]\n", "", "nope"),
        ("", "[duty]\npoisson = 0.7\n", "duty.poisson = 0.7"),
        ("", "[sensitivity2]\n", "sensitivity2"),
        // Appended inside [ladder]: the verdict's duty rung must be a rung.
        ("", "duty_g = 4.0\n", "ladder.duty_g = 4 G"),
        // An external controller that cannot be started: found by starting it once, for one tick.
        (
            "[[controller]]\nlabel = \"x\"\nset = [\"controller.mode=\\\"lockstep\\\"\", \"controller.command=[\\\"/nonexistent/ctl\\\"]\"]\n",
            "",
            "cannot run \"/nonexistent/ctl\"",
        ),
    ];
    for (i, (controllers, extra, says)) in cases.iter().enumerate() {
        let sub = dir.join(&format!("case{i}"));
        std::fs::create_dir_all(&sub).expect("dir");
        let out = sub.join("out");
        let o = assess(&file(&sub.join("assess.toml"), controllers, extra), &out);
        assert_exit(&o, 2);
        assert!(stderr(&o).contains(says), "{}", stderr(&o));
        assert!(!out.join("report.json").exists());
    }
    // A lowest frequency whose periods alone outlast the measurement's run (it ran 3000 s
    // simulated, then failed with exit 1).
    let sub = dir.join("slow");
    std::fs::create_dir_all(&sub).expect("dir");
    let path = file(&sub.join("assess.toml"), "", "");
    std::fs::write(&path, read_text(&path).replace("f_min_hz = 20.0", "f_min_hz = 0.001")).expect("write");
    let out = sub.join("out");
    let o = assess(&path, &out);
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("sensitivity.f_min_hz = 0.001 Hz"), "{}", stderr(&o));
    assert!(!out.exists());
}

#[test]
fn an_excitation_into_the_touchdown_bearing_is_not_graded() {
    let dir = TempDir::new("assess-touch");
    // `parts` is a top-level key: before the first table.
    let controllers = "parts = [\"sensitivity\"]\n[[controller]]\nlabel = \"light\"\nset = [\"controller.law=\\\"pd_delay\\\"\", \"controller.damping_ratio=0.05\"]\n";
    let out = dir.join("out");
    let path = file(&dir.join("assess.toml"), controllers, "");
    let text = std::fs::read_to_string(&path)
        .expect("read")
        .replace("speeds =", "auto_level = false\nexcitation_um = 10.0\nspeeds =");
    std::fs::write(&path, text).expect("write");
    let o = assess(&path, &out);
    assert_exit(&o, 9);
    assert!(stderr(&o).contains("excitation"), "{}", stderr(&o));
    let r = read_json(&out.join("report.json"));
    assert_eq!(r["controllers"][0]["sensitivity"]["failure"], "not_gradable");
}

#[test]
fn a_rotor_not_levitated_before_the_shock_is_not_graded() {
    // A coil current limit of 0.1 A cannot carry the rotor's weight: it sinks onto the race.
    let dir = TempDir::new("assess-drop");
    let controllers = "parts = [\"vibration\", \"ladder\"]\n[[controller]]\nlabel = \"weak\"\nset = [\"controller.law=\\\"pd_delay\\\"\", \"controller.current_limit_a=0.1\"]\n";
    let out = dir.join("out");
    let o = assess(&file(&dir.join("assess.toml"), controllers, ""), &out);
    assert_exit(&o, 9);
    assert!(stderr(&o).contains("not levitated"), "{}", stderr(&o));
    let r = read_json(&out.join("report.json"));
    let c = &r["controllers"][0];
    assert_eq!(c["vibration"]["failure"], "not_gradable", "{}", c["vibration"]);
    // No ladder for a rotor that is down before the shock (no member was run).
    assert_eq!(c["ladder"]["failure"], "not_gradable", "{}", c["ladder"]);
    assert!(c["ladder"]["result"].is_null());
}

/// A controller process killed (SIGKILL, by itself) 0.2 s into each run, co-simulated in
/// lockstep: every part fails as "controller lost" (exit 4), none is graded, the report is
/// written and says why.
#[cfg(unix)]
#[test]
fn a_controller_killed_during_the_measurement_is_reported_lost() {
    let dir = TempDir::new("assess-killed");
    let command = format!(
        "controller.command=[{:?}, \"--mode\", \"die\", \"--die-at\", \"4000\"]",
        rogue_bin().display().to_string()
    );
    let controllers =
        format!("[[controller]]\nlabel = \"dies\"\nset = [\"controller.mode=\\\"lockstep\\\"\", \"controller.law=\\\"pd_delay\\\"\", \"controller.damping_ratio=0.2\", {:?}]\n", command);
    let out = dir.join("out");
    let path = file(&dir.join("assess.toml"), &controllers, "");
    // The probe over by 0.1 s: the controller dies in the stepped sine.
    let text = read_text(&path).replace("probe_s = 0.3", "probe_s = 0.1");
    std::fs::write(&path, text).expect("write");
    let o = assess(&path, &out);
    assert_exit(&o, 4);
    assert!(stderr(&o).contains("controller lost"), "{}", stderr(&o));
    let r = read_json(&out.join("report.json"));
    let c = &r["controllers"][0];
    for part in ["sensitivity", "vibration", "ladder"] {
        assert_eq!(c[part]["status"], "failed", "{part}: {}", c[part]);
        assert_eq!(c[part]["failure"], "peer_lost", "{part}: {}", c[part]);
    }
    // No member whose controller died is counted (as diverged or otherwise).
    for rung in c["ladder"]["result"]["rungs"].as_array().expect("rungs") {
        assert_eq!(rung["members"], 0, "{rung}");
    }
    assert!(c["sensitivity"]["result"].is_null());
}

/// Issue 31 item 7: a controller answering +∞ was graded as a mere "unstable loop" (exit 0): its
/// ∞ currents were clamped to the limit and counted valid. It follows the invalid-command rule
/// now, as one answering NaN: every part fails as `invalid_commands`, exit 8, the report written.
#[test]
fn a_controller_answering_infinite_currents_is_not_graded() {
    let dir = TempDir::new("assess-inf");
    let command = format!(
        "controller.command=[{:?}, \"--mode\", \"nan\", \"--value\", \"inf\"]",
        rogue_bin().display().to_string()
    );
    let controllers = format!(
        "[[controller]]\nlabel = \"infinite\"\nset = [\"controller.mode=\\\"lockstep\\\"\", \"controller.law=\\\"pd_delay\\\"\", {:?}]\n",
        command
    );
    let out = dir.join("out");
    let o = assess(&file(&dir.join("assess.toml"), &controllers, ""), &out);
    assert_exit(&o, 8);
    assert!(stderr(&o).contains("non-finite"), "{}", stderr(&o));
    let r = read_json(&out.join("report.json"));
    let c = &r["controllers"][0];
    for part in ["sensitivity", "vibration", "ladder"] {
        assert_eq!(c[part]["status"], "failed", "{part}: {}", c[part]);
        assert_eq!(c[part]["failure"], "invalid_commands", "{part}: {}", c[part]);
    }
}

/// SIGINT once the ladder has started: the sensitivity and the vibration measured before it
/// are in the report, the ladder is marked interrupted, exit 130.
#[cfg(unix)]
#[test]
fn ctrl_c_midway_keeps_the_parts_measured_and_says_so() {
    let dir = TempDir::new("assess-sigint");
    let controllers = "[[controller]]\nlabel = \"damped\"\nset = [\"controller.law=\\\"pd_delay\\\"\", \"controller.damping_ratio=0.2\"]\n\
                       [[controller]]\nlabel = \"second\"\nset = [\"controller.law=\\\"pd_delay\\\"\"]\n";
    let out = dir.join("out");
    let path = file(&dir.join("assess.toml"), controllers, "");
    // A ladder long enough to be interrupted in: up to 64 members per rung, two per round.
    let text = read_text(&path).replace("members = 2", "members = 64");
    std::fs::write(&path, text).expect("write");
    let mut p = Proc::spawn(Command::new(plant_bin()).arg("assess").arg(&path).arg("--out").arg(&out));
    p.wait_line("damped: shock ladder");
    p.signal(libc::SIGINT);
    let (code, log) = p.finish_within(LIMIT);
    assert_eq!(code, Some(130), "{log}");
    assert!(log.contains("interrupted"), "{log}");
    let r = read_json(&out.join("report.json"));
    assert_eq!(r["interrupted"], true);
    let c = &r["controllers"][0];
    assert_eq!(c["sensitivity"]["status"], "measured", "{}", c["sensitivity"]);
    assert_eq!(c["vibration"]["status"], "measured", "{}", c["vibration"]);
    assert_eq!(c["ladder"]["status"], "interrupted", "{}", c["ladder"]);
    assert!(c["verdict"].as_str().expect("verdict").contains("ladder interrupted"), "{}", c["verdict"]);
    // The second controller was never started.
    let second = &r["controllers"][1];
    for part in ["sensitivity", "vibration", "ladder"] {
        assert_eq!(second[part]["status"], "interrupted", "{part}: {}", second[part]);
    }
    assert!(std::fs::read_to_string(out.join("report.html")).expect("report.html").contains("INTERRUPTED"));
}

/// SIGINT during the sensitivity measurement, once one axis is measured: that axis is kept in
/// the report (the part marked interrupted, its reason naming what was measured), nothing after
/// it runs, exit 130.
#[cfg(unix)]
#[test]
fn ctrl_c_during_the_sensitivity_keeps_the_axes_measured() {
    let dir = TempDir::new("assess-sigint-sens");
    let controllers = "[[controller]]\nlabel = \"damped\"\nset = [\"controller.law=\\\"pd_delay\\\"\", \"controller.damping_ratio=0.2\"]\n";
    let out = dir.join("out");
    let path = file(&dir.join("assess.toml"), controllers, "");
    // Four axis runs (x and y, at standstill and at speed) on a pool of at most two threads.
    let text = read_text(&path).replace("speeds = [\"standstill\"]", "speeds = [\"standstill\", \"rated\"]");
    std::fs::write(&path, text).expect("write");
    let mut p = Proc::spawn(Command::new(plant_bin()).arg("assess").arg(&path).arg("--out").arg(&out));
    p.wait_line("  axis ");
    p.signal(libc::SIGINT);
    let (code, log) = p.finish_within(LIMIT);
    assert_eq!(code, Some(130), "{log}");
    let r = read_json(&out.join("report.json"));
    let c = &r["controllers"][0];
    let s = &c["sensitivity"];
    assert_eq!(s["status"], "interrupted", "{s}");
    let axes = s["result"]["axes"].as_array().expect("the axes measured are kept");
    assert!(!axes.is_empty() && axes.len() < 4, "{s}");
    for axis in axes {
        assert_eq!(axis["stable"], true, "{axis}");
        assert!(num(&axis["peak"], "s_db").is_finite(), "{axis}");
    }
    assert!(s["why"].as_str().expect("why").contains("measured before it"), "{s}");
    for part in ["vibration", "ladder"] {
        assert_eq!(c[part]["status"], "interrupted", "{part}: {}", c[part]);
    }
    assert!(c["verdict"].as_str().expect("verdict").starts_with("sensitivity interrupted, on the"), "{}", c["verdict"]);
}

#[test]
fn a_two_plane_scene_is_graded_at_each_bearing() {
    // The four axes' sensitivity against the modal closed form is a plant test
    // (`assess::tests::a_symmetric_two_plane_machine_…`); here the command takes a two-plane
    // scene and grades the vibration and the duty at each of its two bearings.
    let dir = TempDir::new("assess-two-plane");
    let text = format!(
        "scene = {:?}\nset = [\"scene.duration_s=0.3\"]\nparts = [\"vibration\", \"ladder\"]\n\
         [[controller]]\nlabel = \"pd per plane\"\nset = []\n\
         [ladder]\npeaks_g = [20.0]\nmembers = 2\nbatch = 2\nverify = false\nduty_g = 20.0\n",
        scene("two-plane-asymmetric-10g.toml").display().to_string()
    );
    let path = dir.join("assess.toml");
    std::fs::write(&path, text).expect("write");
    let out = dir.join("out");
    let o = assess(&path, &out);
    assert_exit(&o, 0);
    let r = read_json(&out.join("report.json"));
    let c = &r["controllers"][0];
    let v = &c["vibration"]["result"];
    let planes = v["planes"].as_array().expect("planes");
    assert_eq!(planes.len(), 2);
    // Each plane against its own clearance (the scene's planes have different air gaps).
    assert_ne!(num(&planes[0], "clearance_um"), num(&planes[1], "clearance_um"));
    for p in planes {
        assert!(num(p, "peak_um") > 0.0 && num(p, "ratio") < 0.3, "{p}");
    }
    assert_eq!(v["current_mean_a"].as_array().expect("currents").len(), 4);
    // 20 G: both bearings hit; the rung's figure is the larger bearing's.
    let rung = &c["ladder"]["result"]["rungs"][0];
    let per = rung["duty_planes"].as_array().expect("duty per bearing");
    assert_eq!(per.len(), 2);
    let force = |d: &serde_json::Value| num(&d["peak_contact_force_n"], "max");
    assert!(force(&per[0]) > 100.0 && force(&per[1]) > 100.0, "{per:?}");
    assert_eq!(force(&rung["duty"]), force(&per[0]).max(force(&per[1])));
    assert!(c["verdict"].as_str().expect("verdict").contains("at plane"));
}

/// Issue 31, item 2: a controller over the wire graded at the shipped `[sensitivity]` settings
/// (the whole 5–2000 Hz grid of 40 frequencies, refined to 0.2 % around the peak), at standstill
/// and at 500 Hz: the built-in `controller` process serving `pd_delay` (ξ = 0.1, lockstep at
/// 20 kHz), a black box to the plant whose closed form is known. Every axis' peak lies within
/// 0.1 dB of the closed form and within 0.5 % of its frequency; and the grid costs less
/// simulated time (round trips) than the stepped sine's own floor, two periods of settling and
/// two windows at every frequency (`least_simulated_s`), since the multisine measures the
/// frequencies together.
#[test]
fn a_controller_over_the_wire_is_graded_within_a_tenth_of_a_db_of_its_closed_form() {
    controller_bin();
    let dir = TempDir::new("assess-wire");
    let path = dir.join("wire.toml");
    let text = format!(
        "scene = {:?}\nparts = [\"sensitivity\"]\n[[controller]]\nlabel = \"pd_delay over the wire\"\n\
         set = [\"controller.mode=\\\"lockstep\\\"\", \"controller.law=\\\"pd_delay\\\"\", \"controller.damping_ratio=0.1\"]\n",
        scene("cosim-10g.toml").display().to_string()
    );
    std::fs::write(&path, text).expect("write");
    let out = dir.join("out");
    let o = assess(&path, &out);
    assert_exit(&o, 0);
    let r = read_json(&out.join("report.json"));
    let s = &r["controllers"][0]["sensitivity"]["result"];
    let closed = num(&s["closed_form"], "s_db");
    let closed_f = num(&s["closed_form"], "f_hz");
    let axes = s["axes"].as_array().expect("axes");
    assert_eq!(axes.len(), 4, "x and y at standstill and at speed");
    let settings = plant::assess::sensitivity::Settings::for_gap(150e-6);
    let floor = plant::assess::sensitivity::least_simulated_s(&settings);
    for axis in axes {
        let peak = &axis["peak"];
        let (db, f) = (num(peak, "s_db"), num(peak, "f_hz"));
        assert!((db - closed).abs() < 0.1, "{}: measured {db} dB, closed form {closed} dB", axis["axis"]);
        assert!((f / closed_f - 1.0).abs() < 0.005, "{}: measured {f} Hz, closed form {closed_f} Hz", axis["axis"]);
        assert!(num(peak, "spacing") <= 0.002 * (1.0 + 1e-9), "{peak}");
        let simulated = num(axis, "simulated_s");
        assert!(simulated < floor, "{}: {simulated} s simulated, the stepped sine's floor {floor} s", axis["axis"]);
        assert!(axis["points"].as_array().expect("points").len() >= 30, "{axis}");
    }
}

/// Issue 31, item 2: a whole report card over the wire (sensitivity, vibration and a ladder)
/// of the built-in `controller` process serving `pd_delay` (ξ = 0.1, lockstep at 20 kHz), made
/// within a bound a card of minutes does not meet ([`WIRE_LIMIT`], a debug build on the loaded
/// machine; the work is what is asserted): the loop is measured stable, every ladder member
/// recovers and ends once its outcome is decided (the shock over, clear of the bearing for 200
/// revolutions, the orbit no longer growing), so the members simulate (and exchange frames
/// for) well under the scene's 1.5 s each.
#[test]
fn a_report_card_over_the_wire_is_made_within_a_bound() {
    controller_bin();
    let dir = TempDir::new("assess-wire-card");
    let path = dir.join("card.toml");
    let text = format!(
        "scene = {:?}\n[[controller]]\nlabel = \"pd_delay over the wire\"\n\
         set = [\"controller.mode=\\\"lockstep\\\"\", \"controller.law=\\\"pd_delay\\\"\", \"controller.damping_ratio=0.1\"]\n\
         [sensitivity]\nf_min_hz = 30.0\nf_max_hz = 200.0\npoints = 4\nprobe_s = 0.3\nresolution = 0.2\nmin_cycles = 4\nspeeds = [\"rated\"]\n\
         [ladder]\npeaks_g = [10.0]\nmembers = 2\nbatch = 2\nverify = false\n",
        scene("cosim-10g.toml").display().to_string()
    );
    std::fs::write(&path, text).expect("write");
    let out = dir.join("out");
    let o = output_within(
        Command::new(plant_bin()).arg("assess").arg(&path).arg("--out").arg(&out).arg("--quiet"),
        WIRE_LIMIT,
    );
    assert_exit(&o, 0);
    let r = read_json(&out.join("report.json"));
    let c = &r["controllers"][0];
    for part in ["sensitivity", "vibration", "ladder"] {
        assert_eq!(c[part]["status"], "measured", "{part}: {}", c[part]);
    }
    assert!(c["sensitivity"]["result"]["axes"].as_array().expect("axes").iter().all(|a| a["stable"] == true));
    let l = &c["ladder"]["result"];
    let rung = &l["rungs"][0];
    assert_eq!((rung["members"].as_u64(), rung["recovered"].as_u64()), (Some(2), Some(2)), "{rung}");
    assert_eq!(l["ended_when_decided"], 2, "{l}");
    let simulated = num(l, "simulated_s");
    assert!(simulated > 0.0 && simulated < 2.0 * 0.6 * 1.5, "{simulated} s simulated by 2 members of a 1.5 s scene");
}

/// The bound of [`a_report_card_over_the_wire_is_made_within_a_bound`]: its card takes seconds.
const WIRE_LIMIT: std::time::Duration = std::time::Duration::from_secs(120);

/// Issue 31, item 2: an assessment's lockstep runs block for each other's frame
/// (`controller.spin_us = 0`, [`plant::assess::LOCKSTEP_WAIT`]). Blocking waits had made a
/// loaded debug build ten times slower: not by a lost wake-up, but because the plant, at every
/// 1 ms slice of a reply later than `controller.reply_timeout_ms`, listed every iceoryx2 node
/// of the machine to see whether its controller still lived. A controller answering each frame
/// 2 ms late (every wait of the plant blocks past that timeout, whatever the machine), with
/// no spin: every blocked wait is ended by the controller's wake-up, not by a timed slice (a
/// lost wake-up would leave every one of them `unwoken`), and the plant looks up no node of a
/// controller it started that still runs (it did at each slice, 200 times here at least).
#[test]
fn a_blocked_lockstep_wait_is_ended_by_the_peer_and_lists_no_node() {
    let dir = TempDir::new("assess-blocking-wait");
    let out = dir.join("run");
    let late = format!(
        "controller.command=[{:?}, \"--mode\", \"late\", \"--late-us\", \"2000\"]",
        rogue_bin().display().to_string()
    );
    let sets = ["scene.duration_s=0.01", "output.plots=false", "controller.spin_us=0", late.as_str()];
    let o = output_within(&mut plant_run(&scene("cosim-10g.toml"), &out, &sets), LIMIT);
    assert_exit(&o, 0);
    let s = read_json(&out.join("summary.json"));
    assert_eq!(s["status"], "completed", "{s:#}");
    let c = &s["cosim"];
    let ticks = num(c, "messages_sent");
    assert_eq!(ticks, 200.0, "{c:#}");
    // Each wait blocks for a reply 2 ms late, unless the plant itself was kept off its core for
    // those 2 ms between sending and waiting (a loaded machine: 196 of 200 were seen at a load
    // of 8 to 10); a wait that does not block has nothing to be woken from.
    let blocking = num(c, "blocking_waits");
    assert!(blocking >= 0.9 * ticks && blocking <= ticks, "the waits block for a reply 2 ms late: {c:#}");
    assert!(num(c, "unwoken_waits") <= 0.05 * blocking, "waits that progressed only by a timed slice: {c:#}");
    assert_eq!(num(c, "node_lookups"), 0.0, "{c:#}");
}

/// Issue 31, item 3: the report reads without the guide and names no folder of the machine.
/// Run from a folder of its own, on an assessment file and an output folder given by absolute
/// paths: neither that folder's nor the repository's absolute path, nor any other absolute
/// path, appears in `report.html` or `report.json` (the file, the scene and the output are
/// shown relative to where the command ran); the page explains the zones of both standards
/// with their limits, the worst axis' rule, the motion modes and the colours; the highest safe
/// shock's colour follows its value against the duty rung; both speeds are drawn.
#[test]
fn the_report_explains_itself_and_names_no_absolute_path() {
    let dir = TempDir::new("assess-text");
    let controllers = "[[controller]]\nlabel = \"damped\"\nset = [\"controller.law=\\\"pd_delay\\\"\", \"controller.damping_ratio=0.2\"]\n";
    let path = file(&dir.join("assess.toml"), controllers, "");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("speeds = [\"standstill\"]", "speeds = [\"standstill\", \"rated\"]");
    std::fs::write(&path, text).unwrap();
    let here = dir.join("here");
    std::fs::create_dir_all(&here).unwrap();
    let out = dir.join("out");
    let o = output_within(
        Command::new(plant_bin()).current_dir(&here).arg("assess").arg(&path).arg("--out").arg(&out).arg("--quiet"),
        LIMIT,
    );
    assert_exit(&o, 0);
    let html = std::fs::read_to_string(out.join("report.html")).expect("report.html");
    let json = std::fs::read_to_string(out.join("report.json")).expect("report.json");
    let tmp = dir.join("").display().to_string();
    let root = workspace_root().display().to_string();
    for (name, text) in [("report.html", &html), ("report.json", &json)] {
        // Either folder only inside a path relative to where the command ran (`../../…`).
        for folder in [tmp.trim_end_matches('/'), root.as_str()] {
            let relative = text.match_indices(folder).all(|(i, _)| text[..i].ends_with(".."));
            assert!(relative, "{name} names {folder}");
        }
        // No absolute path at all: a `/` after a space, a quote, `=`, `(` or `>` that starts
        // two or more path components.
        let bytes = text.as_bytes();
        for (i, w) in bytes.windows(2).enumerate() {
            let starts = matches!(w[0], b' ' | b'"' | b'\'' | b'=' | b'(' | b'>' | b'\n') && w[1] == b'/';
            if !starts {
                continue;
            }
            let rest: String =
                text[i + 1..].chars().take_while(|c| c.is_alphanumeric() || "/._-".contains(*c)).collect();
            let components = rest.split('/').filter(|c| !c.is_empty()).count();
            assert!(components < 2, "{name}: an absolute path {rest:?}");
        }
    }
    let r = read_json(&out.join("report.json"));
    assert_eq!(r["out"], "../out", "{}", r["out"]);
    let scene = r["scene"].as_str().expect("scene");
    assert!(scene.starts_with("../") && scene.ends_with("config/paper-10g.toml"), "{scene}");
    assert!(
        r["file"].as_str().expect("file").ends_with("assess.toml") && r["file"].as_str().unwrap().starts_with("..")
    );
    // The explanations.
    for needed in [
        "How to read this report",
        "zone <b>A</b> |S| &lt; 3",
        "<b>D</b> 5 or more",
        "<b>A</b> below 0.3 C<sub>min</sub>",
        "the minimum radial clearance",
        "<b>dry whirl</b>",
        "<b>rebound</b>",
        "<b>diverged</b>",
        "then within it the highest peak",
        "Wilson 95 %",
        "<b class=\"low\">amber</b>",
        "x at 0 Hz",
        "x at 500 Hz",
    ] {
        let flat = |s: &str| s.split_whitespace().collect::<Vec<_>>().join(" ");
        assert!(flat(&html).contains(&flat(needed)), "report.html does not say {needed:?}");
    }
    // The highest safe shock coloured by its value: green only from the duty rung up.
    let c = &r["controllers"][0];
    let duty = num(&r["ladder_settings"], "duty_g");
    if let Some(g) = c["ladder"]["result"]["safe_up_to_g"].as_f64() {
        let class = if g >= duty { "ok" } else { "low" };
        assert!(html.contains(&format!("<b class=\"{class}\">{g} G</b>")), "{g} G against the {duty} G rung");
    }
    // The verdict names the worst axis and, with a symmetric machine, its equals.
    let verdict = c["verdict"].as_str().expect("verdict");
    assert!(verdict.contains("equal within 0.05 dB"), "{verdict}");
    // Standstill and speed side by side: the chart is wider than a one-panel chart.
    let png = Png::read(&out.join("sensitivity_1.png"));
    let ladder = Png::read(&out.join("ladder_probability.png"));
    assert!(png.width > ladder.width, "{} px against {} px", png.width, ladder.width);
}
