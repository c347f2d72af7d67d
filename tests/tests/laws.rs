//! End-to-end tests of the law registry and the laws' own parameters
//! (issue 10 items 1 and 2): `[controller.params]` reach the law unread by
//! the plant; a law refusing them stops the run with exit 2 naming the law,
//! the key, the value and the unit, in the plant and in an external
//! controller alike; the deprecated `relev_*` keys still run, with a
//! warning, byte for byte as the parameters they stand for; and a run
//! folder reproduces a run whose external controller overrode the design.
//!
//! Every process is bounded in time (`output_within`, `Proc::finish`).

mod common;

use common::{
    assert_exit, controller_bin, num, output_within, plant_bin, plant_run, read_json, scene, stderr, TempDir, SHORT,
};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// The limit of one short run in a debug build on a loaded machine.
const LIMIT: Duration = Duration::from_secs(120);

/// `SHORT` plus extra overrides.
fn sets<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    SHORT.iter().copied().chain(extra.iter().copied()).collect()
}

/// Runs `plant run` expecting bad input: exit 2 and every needle on stderr, no output folder.
fn assert_refused_at_load(name: &str, scene_file: &Path, sets: &[&str], needles: &[&str]) {
    let dir = TempDir::new(name);
    let out = dir.join("run");
    let run = output_within(&mut plant_run(scene_file, &out, sets), LIMIT);
    let err = stderr(&run);
    assert_exit(&run, 2);
    assert!(!err.contains("panicked"), "{err}");
    for n in needles {
        assert!(err.contains(n), "{sets:?}: no {n:?} in:\n{err}");
    }
    assert!(!out.exists(), "bad input created {}", out.display());
}

#[test]
fn a_law_refuses_an_unknown_parameter_naming_the_law_and_the_keys_it_reads() {
    assert_refused_at_load(
        "params-unknown",
        &scene("relev-10g.toml"),
        &sets(&["controller.params.enter_mm=0.1"]),
        &["law relev", "unknown parameter controller.params.enter_mm = 0.1", "enter_um", "arm_ms"],
    );
    assert_refused_at_load(
        "params-unknown-pd",
        &scene("paper-10g.toml"),
        &sets(&["controller.params.gain=2"]),
        &["law pd", "unknown parameter controller.params.gain = 2", "no parameters"],
    );
}

#[test]
fn a_law_refuses_a_parameter_of_the_wrong_type_naming_law_key_value_and_unit() {
    assert_refused_at_load(
        "params-type",
        &scene("relev-10g.toml"),
        &sets(&["controller.params.hold_ms=\"long\""]),
        &["law relev", "controller.params.hold_ms = \"long\"", "ms", "expected a number"],
    );
}

#[test]
fn a_law_refuses_a_parameter_out_of_range_naming_law_key_value_and_unit() {
    assert_refused_at_load(
        "params-range",
        &scene("relev-10g.toml"),
        &sets(&["controller.params.arm_ms=-5"]),
        &["law relev", "controller.params.arm_ms = -5 ms", ">= 0"],
    );
    assert_refused_at_load(
        "params-range-pid",
        &scene("paper-10g.toml"),
        &sets(&["controller.law=pid", "controller.params.integral_time_s=-0.5"]),
        &["law pid", "controller.params.integral_time_s = -0.5 s", "> 0"],
    );
}

#[test]
fn a_parameter_document_over_4096_bytes_is_refused() {
    let long = format!("controller.params.note=\"{}\"", "x".repeat(5000));
    assert_refused_at_load(
        "params-long",
        &scene("relev-10g.toml"),
        &sets(&[&long]),
        &["controller.params", "bytes of TOML text", "4096"],
    );
}

/// `relev-10g.toml` as it was written before `[controller.params]`: the rule in
/// `[controller] relev_*` keys.
fn old_relev_scene(dir: &TempDir) -> std::path::PathBuf {
    let text = std::fs::read_to_string(scene("relev-10g.toml")).unwrap();
    let (head, params) = text.split_once("[controller.params]").expect("relev-10g.toml has [controller.params]");
    let (_, rest) = params.split_once("\n[").expect("a table after [controller.params]");
    let old_keys = "relev_enter_um = 120.0\nrelev_exit_um = 45.0\nrelev_hold_ms = 50.0\n\
                    relev_damping_ratio = 0.2\nrelev_arm_ms = 500.0\n\n";
    let old = format!("{head}{old_keys}[{rest}");
    assert!(!old.contains("[controller.params]") && old.contains("[integrator]"));
    let path = dir.join("relev-old.toml");
    std::fs::write(&path, old).unwrap();
    path
}

#[test]
fn deprecated_relev_keys_still_run_with_a_warning_and_the_same_trace() {
    let dir = TempDir::new("relev-aliases");
    let old = old_relev_scene(&dir);
    let common = ["scene.duration_s=0.06", "controller.mode=sampled", "output.plots=false"];
    let run = |file: &Path, name: &str, arm: &str| {
        let out = dir.join(name);
        let sets: Vec<&str> = common.iter().copied().chain([arm]).collect();
        let o = output_within(&mut plant_run(file, &out, &sets), LIMIT);
        assert_exit(&o, 0);
        (std::fs::read(out.join("trace.csv")).unwrap(), stderr(&o), out)
    };
    let (new_trace, new_err, _) = run(&scene("relev-10g.toml"), "new", "controller.params.arm_ms=0");
    let (old_trace, old_err, old_out) = run(&old, "old", "controller.relev_arm_ms=0");
    assert!(new_trace == old_trace, "the deprecated keys gave another trace than the parameters");
    assert!(!new_err.contains("deprecated"), "{new_err}");
    for (old_key, new_key) in
        [("relev_enter_um", "enter_um"), ("relev_arm_ms", "arm_ms"), ("relev_damping_ratio", "recovery_damping_ratio")]
    {
        assert!(
            old_err.contains(&format!(
                "plant: warning: controller.{old_key} is deprecated: write controller.params.{new_key}"
            )),
            "{old_key}:\n{old_err}"
        );
    }
    // The record holds the parameters, not the deprecated keys.
    let resolved: toml::Table = std::fs::read_to_string(old_out.join("scene.toml")).unwrap().parse().unwrap();
    let ctl = resolved["controller"].as_table().unwrap();
    assert!(ctl.keys().all(|k| !k.starts_with("relev_")), "{ctl:?}");
    assert_eq!(ctl["params"]["arm_ms"].as_float(), Some(0.0));
    assert_eq!(ctl["params"]["enter_um"].as_float(), Some(120.0));
    // The same trace must also come from the run folder.
    let again = dir.join("again");
    let o = output_within(&mut plant_run(&old_out.join("scene.toml"), &again, &[]), LIMIT);
    assert_exit(&o, 0);
    assert!(std::fs::read(again.join("trace.csv")).unwrap() == old_trace, "scene.toml does not reproduce the run");
}

#[test]
fn a_deprecated_key_and_its_parameter_together_are_refused() {
    let dir = TempDir::new("relev-both");
    let old = old_relev_scene(&dir);
    assert_refused_at_load(
        "relev-both-run",
        &old,
        &sets(&["controller.params.hold_ms=5"]),
        &["controller.relev_hold_ms (deprecated)", "controller.params.hold_ms"],
    );
}

#[test]
fn deprecated_relev_keys_of_another_law_are_ignored_with_a_warning() {
    let dir = TempDir::new("relev-other-law");
    let out = dir.join("run");
    let o =
        output_within(&mut plant_run(&scene("paper-10g.toml"), &out, &sets(&["controller.relev_hold_ms=5"])), LIMIT);
    assert_exit(&o, 0);
    assert!(stderr(&o).contains("controller.relev_hold_ms is deprecated and ignored"), "{}", stderr(&o));
}

/// A child process killed on drop; `finish` waits for it within a limit.
struct Proc(Child);

impl Proc {
    fn spawn(cmd: &mut Command) -> Self {
        Self(cmd.stdout(Stdio::null()).stderr(Stdio::piped()).spawn().unwrap_or_else(|e| panic!("{cmd:?}: {e}")))
    }

    /// Exit code and stderr, within `LIMIT`.
    fn finish(mut self) -> (Option<i32>, String) {
        use std::io::Read;
        let deadline = Instant::now() + LIMIT;
        let status = loop {
            if let Some(s) = self.0.try_wait().unwrap() {
                break s;
            }
            assert!(Instant::now() < deadline, "process did not exit within {LIMIT:?}");
            std::thread::sleep(Duration::from_millis(10));
        };
        let mut err = String::new();
        let _ = self.0.stderr.take().map(|mut e| e.read_to_string(&mut err));
        (status.code(), err)
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn run_id(name: &str) -> String {
    format!("t{}-{name}", std::process::id())
}

/// A plant run of the short 10 G scene in lockstep, waiting for an external controller.
fn external_plant(out: &Path, id: &str, extra: &[&str]) -> Command {
    let mut all = sets(&["controller.mode=lockstep"]);
    all.extend_from_slice(extra);
    let mut cmd = plant_run(&scene("paper-10g.toml"), out, &all);
    cmd.args(["--controller", "external", "--run-id", id]);
    cmd
}

fn controller(id: &str, config: &Path) -> Command {
    let mut cmd = Command::new(controller_bin());
    cmd.arg("--run-id").arg(id).arg("--config").arg(config).args(["--connect-timeout-s", "60"]);
    cmd
}

#[test]
fn an_external_controller_refusing_its_parameters_stops_both_with_exit_2() {
    plant_bin();
    let dir = TempDir::new("params-external");
    let file = dir.join("ctl.toml");
    std::fs::write(&file, "[controller]\n[controller.params]\nbogus = 1.5\n").unwrap();
    let (id, out) = (run_id("params-ext"), dir.join("run"));
    let plant = Proc::spawn(&mut external_plant(&out, &id, &[]));
    let (ctl_code, ctl_err) = Proc::spawn(&mut controller(&id, &file)).finish();
    assert_eq!(ctl_code, Some(2), "{ctl_err}");
    assert!(ctl_err.contains("parameters rejected") && ctl_err.contains("controller.params.bogus"), "{ctl_err}");
    let (code, err) = plant.finish();
    assert_eq!(code, Some(2), "{err}");
    for n in ["refused", "parameters rejected", "law pd", "controller.params.bogus = 1.5"] {
        assert!(err.contains(n), "no {n:?} in:\n{err}");
    }
    let s = read_json(&out.join("summary.json"));
    assert_eq!(s["status"], "refused", "{s:#}");
    assert!(s["error"].as_str().unwrap_or_default().contains("controller.params.bogus"), "{s:#}");
}

/// Issue 11 item 9: the run folder's `scene.toml` left out an external controller's
/// `--config` overrides, so it did not reproduce the run.
#[test]
fn scene_toml_of_a_run_with_controller_overrides_reproduces_the_run() {
    plant_bin();
    let dir = TempDir::new("overrides");
    let file = dir.join("ctl.toml");
    std::fs::write(
        &file,
        "[controller]\nlaw = \"pid\"\ndamping_ratio = 0.2\n[controller.params]\nintegral_time_s = 0.05\n",
    )
    .unwrap();
    let (id, out) = (run_id("overrides"), dir.join("run"));
    let plant = Proc::spawn(&mut external_plant(&out, &id, &[]));
    let ctl = Proc::spawn(&mut controller(&id, &file));
    let (code, err) = plant.finish();
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(ctl.finish().0, Some(0));

    let s = read_json(&out.join("summary.json"));
    let o = &s["cosim"]["controller_overrides"];
    assert_eq!(o["law"], "pid", "{s:#}");
    assert_eq!(num(o, "damping_ratio"), 0.2, "{s:#}");
    assert_eq!(num(&o["params"], "integral_time_s"), 0.05, "{s:#}");
    assert_eq!(s["model"]["law"], "pid", "{s:#}");

    // The folder's scene, run in-process (sampled: bit-identical to lockstep), gives the same trace.
    let again = dir.join("again");
    let o = output_within(&mut plant_run(&out.join("scene.toml"), &again, &["controller.mode=sampled"]), LIMIT);
    assert_exit(&o, 0);
    let (a, b) = (std::fs::read(out.join("trace.csv")).unwrap(), std::fs::read(again.join("trace.csv")).unwrap());
    assert!(a == b, "scene.toml of the run does not reproduce it");
    // And the overrides changed the run: the scene file alone gives another trace.
    let plain = dir.join("plain");
    let o = output_within(&mut plant_run(&scene("paper-10g.toml"), &plain, &sets(&["controller.mode=sampled"])), LIMIT);
    assert_exit(&o, 0);
    assert!(std::fs::read(plain.join("trace.csv")).unwrap() != a, "the overrides did not change the run");
}

/// Issue 31 item 7: a law in this process answering ±∞ had them clamped to the limit and
/// counted valid (exit 0, `invalid_commands = 0`). Every non-finite current (NaN, +∞, −∞, on
/// either axis) is an invalid command: held, counted, and past `controller.max_invalid_burst`
/// (10 in a row) the run ends as `invalid_commands`.
#[test]
fn every_non_finite_current_of_a_law_in_process_is_invalid() {
    use controller::{ControlLaw, Design, LawEntry, LawError, Params, Sample};
    use std::sync::atomic::{AtomicUsize, Ordering};
    const VALUES: [[f64; 2]; 4] =
        [[f64::NAN, 0.0], [f64::INFINITY, 0.0], [0.0, f64::NEG_INFINITY], [f64::INFINITY, f64::NEG_INFINITY]];
    static CASE: AtomicUsize = AtomicUsize::new(0);
    struct Bad([f64; 2]);
    impl ControlLaw for Bad {
        fn name(&self) -> &'static str {
            "bad_after_100"
        }
        fn update(&mut self, s: &Sample) -> [f64; 2] {
            if s.seq >= 100 {
                self.0
            } else {
                [0.0, 0.5]
            }
        }
        fn reset(&mut self) {}
    }
    fn build(_: &Design, _: &Params) -> Result<Box<dyn ControlLaw>, LawError> {
        Ok(Box::new(Bad(VALUES[CASE.load(Ordering::SeqCst)])))
    }
    const LAW: LawEntry = LawEntry { name: "bad_after_100", summary: "", build };
    let scene = plant::config::load_scene(
        &scene("paper-10g.toml"),
        &sets(&["controller.mode=\"sampled\""]).iter().map(|s| s.to_string()).collect::<Vec<_>>(),
    )
    .unwrap();
    for (i, value) in VALUES.iter().enumerate() {
        CASE.store(i, Ordering::SeqCst);
        let run = plant::check::run_law(&scene, &LAW, &mut plant::run::Quiet).unwrap();
        let outcome = &run.run.outcome;
        assert!(
            matches!(outcome, plant::run::Outcome::InvalidCommands(w) if w.contains("11 samples in a row, from sample 100")),
            "{value:?}: {outcome:?}"
        );
        assert_eq!(run.run.invalid_commands, 11, "{value:?}");
        assert!(run.trace.loads.ix_a.iter().chain(&run.trace.loads.iy_a).all(|i| i.is_finite()), "{value:?}");
    }
}
