//! The property test over every scene key (issue 11, "Tests"): each key of
//! the scene format, set to values a careless operator or a hostile input
//! would give (NaN, ±infinity, zero, negative, huge, tiny, the wrong type,
//! and seeded random values around its default), makes `plant run` end
//! within a time bound with exit 0, 2 or 3 (a realtime run also 6 or 10, its
//! budgets), never a signal death, never a panic; a value refused is refused at load with a message that names the
//! key.
//!
//! The keys come from the format itself, so a new key is covered without
//! editing this file: the default `RawScene` serialised and walked, and each
//! table asked for its whole field list (serde's "unknown field" answer lists
//! the fields it expects, Option fields included); each `[[shock]]` kind the
//! same way, each law's own parameters from its "unknown parameter" answer.
//! Only one thing is written here by hand: a valid example of each shock kind
//! to put the kind's keys in, and the test fails if a kind has none.
//!
//! Speed: every case is loaded in-process first (the scene loader and the
//! stability check, as `plant run` does before anything runs); the cases
//! refused there (most of them) are checked through the binary on a seeded
//! sample only; every case that loads runs through the binary, on a base
//! scene 5 ms long without charts, two at a time. Deterministic: a fixed
//! seed for the random values and for the sample.
//!
//! What it found, and what was fixed: `controller.stiffness_n_per_m = 1e300`
//! loaded and its 5 ms run took five minutes (the loop chattered; now bounded
//! at 1e12 N/m); NaN, ±∞ and negative values of keys read by one choice only
//! (`amb.nominal_gap_mm` and `magnet_force_limit_n` with the linear bearing,
//! `rotor.drive_*` with held spin, `touchdown.palmgren_*` with the constant
//! drag, `touchdown.lumped_reference_mm` with the balls) were accepted
//! silently (now refused whatever the choice).
//!
//! Diagnostics: `PROPERTIES_LIST=1` prints the cases that load,
//! `PROPERTIES_LOAD_ONLY=1` skips the binary.

mod common;

use common::{controller_bin, output_within, plant_bin, stderr, TempDir};
use plant::rng::SplitMix64;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Seed of the random values and of the sample of refused cases run through the binary.
const SEED: u64 = 0x0011_2026;
/// Refused cases run through the binary as well (a sample: the loader is the same code).
const REFUSED_SAMPLE: usize = 40;
/// The bound on one run of the 5 ms base scene, in a debug build on a loaded machine: a run
/// that takes longer than this is a hang as far as this test is concerned.
const RUN_LIMIT: Duration = Duration::from_secs(120);

/// The base scene: the format's defaults, 5 ms, no charts (the values not under test).
const BASE_SETS: &[(&str, &str)] = &[("scene", "duration_s = 0.005"), ("output", "plots = false")];

/// A valid example of each shock kind, starting inside the 5 ms base run.
const SHOCK_EXAMPLES: &[(&str, &str)] = &[
    ("double_half_sine", "peak_g = 10.0\nf1_hz = 10.0\nf2_hz = 80.0\nstart_s = 0.001"),
    ("half_sine", "peak_g = 5.0\nduration_s = 0.002\nstart_s = 0.001"),
    ("sine", "amplitude_g = 1.0\nfreq_hz = 500.0\ncycles = 1\nstart_s = 0.001"),
    ("recorded", "file = \"record.csv\"\nstart_s = 0.001"),
];

/// The record the `recorded` example reads (beside the base scenes).
const RECORD: &str = "t_s,accel_m_s2\n0,0\n0.001,50\n0.002,-50\n0.003,0\n";

/// What a key holds, as far as the format says.
#[derive(Clone, Debug)]
enum Kind {
    Float(f64),
    Int(i64),
    Bool,
    /// A string; the values the format accepts, where it lists them (enums).
    Str(Vec<String>),
    Array,
}

/// One key of the format: its `--set` path, the base scene it is set in, and its kind.
#[derive(Clone, Debug)]
struct Key {
    path: String,
    base: PathBuf,
    kind: Kind,
}

/// One case: a key set to one value.
#[derive(Clone, Debug)]
struct Case {
    key: String,
    value: String,
    base: PathBuf,
}

impl Case {
    fn set(&self) -> String {
        format!("{}={}", self.key, self.value)
    }
}

/// The fields serde expects in a table, from its answer to an unknown one:
/// "unknown field `__probe__`, expected one of `a`, `b`" (or "expected `a` or `b`").
fn expected_names(message: &str, what: &str) -> Vec<String> {
    let Some(at) = message.find(&format!("unknown {what} `__probe__`, expected")) else {
        return Vec::new();
    };
    let tail = &message[at..];
    let tail = tail.split('\n').next().unwrap_or_default();
    tail.split('`').skip(3).step_by(2).map(str::to_string).collect()
}

/// Parses a scene table as the loader does (format only, no validation).
fn parses(table: &toml::Table) -> Result<plant::config::RawScene, String> {
    toml::Value::Table(table.clone()).try_into::<plant::config::RawScene>().map_err(|e| e.to_string())
}

/// The kind of a key absent from the default serialisation (an `Option`): the first value
/// kind the format parses.
fn probe_kind(table: &toml::Table, section: &str, key: &str) -> Option<Kind> {
    let tries: [(toml::Value, Kind); 4] = [
        (toml::Value::Float(0.5), Kind::Float(0.5)),
        (toml::Value::Integer(1), Kind::Int(1)),
        (toml::Value::Boolean(true), Kind::Bool),
        (toml::Value::String("x".into()), Kind::Str(Vec::new())),
    ];
    tries.into_iter().find_map(|(v, kind)| {
        let mut t = table.clone();
        t.get_mut(section)?.as_table_mut()?.insert(key.into(), v);
        parses(&t).is_ok().then_some(kind)
    })
}

/// The values a string key accepts, when the format lists them (an enum's variants).
fn variants(table: &toml::Table, set: impl Fn(&mut toml::Table, toml::Value)) -> Vec<String> {
    let mut t = table.clone();
    set(&mut t, toml::Value::String("__probe__".into()));
    parses(&t).err().map(|e| expected_names(&e, "variant")).unwrap_or_default()
}

fn kind_of(value: &toml::Value) -> Option<Kind> {
    Some(match value {
        toml::Value::Float(f) => Kind::Float(*f),
        toml::Value::Integer(i) => Kind::Int(*i),
        toml::Value::Boolean(_) => Kind::Bool,
        toml::Value::String(_) => Kind::Str(Vec::new()),
        toml::Value::Array(_) => Kind::Array,
        _ => return None,
    })
}

/// Writes the base scenes into `dir` and returns every key of the format with its base.
fn discover(dir: &Path) -> Vec<Key> {
    std::fs::write(dir.join("record.csv"), RECORD).unwrap();
    let mut base: toml::Table =
        toml::Table::try_from(plant::config::RawScene::default()).expect("the default scene serialises");
    for (section, kv) in BASE_SETS {
        let (k, v) = kv.split_once(" = ").unwrap();
        base[*section]
            .as_table_mut()
            .unwrap()
            .insert(k.into(), toml::from_str::<toml::Table>(&format!("v = {v}")).unwrap()["v"].clone());
    }
    base.remove("shock");
    let write = |name: &str, table: &toml::Table| {
        let path = dir.join(name);
        std::fs::write(&path, toml::to_string(table).unwrap()).unwrap();
        path
    };
    let base_path = write("base.toml", &base);
    let mut keys = Vec::new();

    // Every table of the scene and every field each one takes.
    for (section, value) in &base {
        let Some(defaults) = value.as_table() else { continue };
        let mut probe = base.clone();
        probe[section].as_table_mut().unwrap().insert("__probe__".into(), toml::Value::Integer(0));
        let fields = expected_names(&parses(&probe).expect_err("an unknown field is refused"), "field");
        assert!(!fields.is_empty(), "[{section}] did not list its fields");
        for field in fields {
            let kind = match defaults.get(&field) {
                Some(v) => kind_of(v),
                None => probe_kind(&base, section, &field),
            };
            let Some(mut kind) = kind else { continue }; // a free table (controller.params): below
            if let Kind::Str(ref mut accepted) = kind {
                *accepted = variants(&base, |t, v| {
                    t[section].as_table_mut().unwrap().insert(field.clone(), v);
                });
                if section == "controller" && field == "law" {
                    accepted.extend(controller::law_names().into_iter().map(str::to_string));
                }
            }
            keys.push(Key { path: format!("{section}.{field}"), base: base_path.clone(), kind });
        }
    }
    assert!(keys.iter().any(|k| k.path == "integrator.atol_position_m"), "Option fields must be found too");

    // Every shock kind, and every key of each.
    let mut probe = base.clone();
    probe.insert(
        "shock".into(),
        toml::Value::Array(vec![toml::from_str::<toml::Value>("kind = \"__probe__\"").unwrap()]),
    );
    let kinds = expected_names(&parses(&probe).expect_err("an unknown shock kind is refused"), "variant");
    let mut with_examples: Vec<&str> = SHOCK_EXAMPLES.iter().map(|(k, _)| *k).collect();
    with_examples.sort_unstable();
    let mut sorted = kinds.clone();
    sorted.sort();
    assert_eq!(sorted, with_examples, "every shock kind needs an example in SHOCK_EXAMPLES");
    for (kind, example) in SHOCK_EXAMPLES {
        let mut shock: toml::Table = toml::from_str(example).unwrap();
        shock.insert("kind".into(), toml::Value::String(kind.to_string()));
        let mut scene = base.clone();
        scene.insert("shock".into(), toml::Value::Array(vec![toml::Value::Table(shock.clone())]));
        parses(&scene).unwrap_or_else(|e| panic!("the {kind} example does not parse: {e}"));
        let path = write(&format!("base-{kind}.toml"), &scene);
        let mut probe = shock.clone();
        probe.insert("__probe__".into(), toml::Value::Integer(0));
        scene.insert("shock".into(), toml::Value::Array(vec![toml::Value::Table(probe)]));
        let fields = expected_names(&parses(&scene).expect_err("an unknown shock key is refused"), "field");
        assert!(fields.len() >= shock.len() - 1, "{kind}: fields {fields:?}");
        for field in fields {
            let kind_of_field = match shock.get(&field) {
                Some(v) => kind_of(v),
                None => Some(Kind::Float(1.0)),
            };
            let Some(k) = kind_of_field else { continue };
            keys.push(Key { path: format!("shock[0].{field}"), base: path.clone(), kind: k });
        }
    }

    // Each law's own parameters, from the law's answer to one it does not read.
    for law in controller::law_names() {
        let mut scene = base.clone();
        scene["controller"].as_table_mut().unwrap().insert("law".into(), toml::Value::String(law.into()));
        let path = write(&format!("base-law-{law}.toml"), &scene);
        let design = plant::config::validate(parses(&scene).unwrap(), dir).unwrap().plane_design(0);
        let mut params = toml::Table::new();
        params.insert("__probe__".into(), toml::Value::Integer(0));
        match controller::build_law(law, &design, &controller::Params::new(params)) {
            Err(controller::LawError::UnknownParam { known, .. }) => {
                for p in known {
                    keys.push(Key {
                        path: format!("controller.params.{p}"),
                        base: path.clone(),
                        kind: Kind::Float(1.0),
                    });
                }
            }
            other => panic!("law {law} took an unknown parameter: {:?}", other.err()),
        }
    }
    keys
}

/// Text of a float for `--set` (a TOML literal).
fn float(v: f64) -> String {
    if v.is_nan() {
        "nan".into()
    } else if v.is_infinite() {
        if v > 0.0 {
            "inf".into()
        } else {
            "-inf".into()
        }
    } else {
        format!("{v:?}")
    }
}

/// The values tried for a key: the hostile ones of its kind, the wrong type, and seeded random
/// ones around its default.
fn values(kind: &Kind, rng: &mut SplitMix64) -> Vec<String> {
    let mut v: Vec<String> = Vec::new();
    match kind {
        Kind::Float(default) => {
            for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 0.0, -1.0, 1e300, -1e300, 1e-300] {
                v.push(float(x));
            }
            v.push("\"x\"".into());
            for _ in 0..2 {
                let magnitude = if *default != 0.0 { default.abs() } else { 1.0 };
                let mut x = magnitude * 10f64.powf(rng.uniform([-3.0, 3.0]));
                if rng.unit() < 0.15 || *default < 0.0 {
                    x = -x;
                }
                v.push(float(x));
            }
        }
        Kind::Int(default) => {
            for x in ["0", "1", "-1", "4294967295", "9223372036854775807", "1.5", "\"x\""] {
                v.push(x.into());
            }
            v.push(((rng.unit() * (2 * default.abs() + 10) as f64) as i64).to_string());
            v.push((10f64.powf(rng.uniform([0.0, 9.0])) as i64).to_string());
        }
        Kind::Bool => v.extend(["true", "false", "1"].map(String::from)),
        Kind::Str(accepted) => {
            v.extend(["\"\"", "\"zz\"", "1"].map(String::from));
            v.push(format!("\"{}\"", "x".repeat(5000)));
            v.extend(accepted.iter().map(|a| format!("\"{a}\"")));
        }
        Kind::Array => v.extend(["[]", "[0, 1]", "[0]", "[999999, 0]", "[-1, 0]", "[\"a\"]"].map(String::from)),
    }
    v
}

/// What the in-process load said about a case.
enum Loaded {
    /// Loaded and passed the stability check: `plant run` runs it; the load's warnings.
    Runs(Vec<String>),
    /// Refused with this message (exit 2).
    Refused(String),
}

/// Loads a case as `plant run` does before it runs anything; a panic fails the test here.
fn load(case: &Case) -> Loaded {
    let set = [case.set()];
    let result = std::panic::catch_unwind(|| plant::config::load_scene(&case.base, &set));
    match result {
        Err(_) => panic!("loading {} panicked", case.set()),
        Ok(Err(e)) => {
            let chain: Vec<String> = std::iter::successors(Some(&e as &dyn std::error::Error), |e| e.source())
                .map(|e| e.to_string())
                .collect();
            Loaded::Refused(chain.join(": "))
        }
        Ok(Ok(scene)) => match plant::stability::check(&scene) {
            plant::stability::StepVerdict::Refuse(why) => Loaded::Refused(why),
            _ => Loaded::Runs(scene.warnings),
        },
    }
}

/// Runs `plant run <base> --set <case>` and returns a description of what is wrong with how it
/// ended, if anything: not within the bound, a signal, a panic, another exit code than allowed.
fn run_binary(case: &Case, out: &Path, allowed: &[i32]) -> Option<String> {
    let mut cmd = Command::new(plant_bin());
    cmd.arg("run").arg(&case.base).arg("--out").arg(out).arg("--quiet").args(["--set", &case.set()]);
    let started = Instant::now();
    let o = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| output_within(&mut cmd, RUN_LIMIT)));
    let _ = std::fs::remove_dir_all(out);
    let Ok(o) = o else {
        return Some(format!("--set {}: did not end within {RUN_LIMIT:?}", case.set()));
    };
    let err = stderr(&o);
    let short: String = err.chars().take(600).collect();
    match o.status.code() {
        None => Some(format!("--set {}: killed by a signal ({}); stderr: {short}", case.set(), o.status)),
        Some(_) if err.contains("panicked") => Some(format!("--set {}: panicked: {short}", case.set())),
        Some(c) if !allowed.contains(&c) => Some(format!(
            "--set {}: exit {c} (allowed {allowed:?}) after {:.1?}; stderr: {short}",
            case.set(),
            started.elapsed()
        )),
        Some(_) => None,
    }
}

#[test]
fn every_scene_key_with_hostile_values_ends_in_time_with_exit_0_2_or_3() {
    controller_bin(); // lockstep and realtime values start the controller next to the plant
    let dir = TempDir::new("properties");
    let keys = discover(&dir.join(""));
    let mut rng = SplitMix64::new(SEED);
    let cases: Vec<Case> = keys
        .iter()
        .flat_map(|k| {
            values(&k.kind, &mut rng)
                .into_iter()
                .map(|value| Case { key: k.path.clone(), value, base: k.base.clone() })
                .collect::<Vec<_>>()
        })
        .collect();

    // In-process: the loader refuses or accepts each case; a refusal names the key.
    let mut problems = Vec::new();
    let (mut runs, mut refused) = (Vec::new(), Vec::new());
    for case in &cases {
        match load(case) {
            Loaded::Runs(warnings) => {
                // Not a number is never a value; a key the scene ignores says so.
                let ignored = warnings.iter().any(|w| w.contains(&case.key) && w.contains("ignored"));
                if case.value == "nan" && !ignored {
                    problems.push(format!("--set {}: accepted", case.set()));
                }
                runs.push(case.clone());
            }
            Loaded::Refused(why) => {
                let leaf = case.key.rsplit('.').next().unwrap_or_default();
                if !why.contains(leaf) {
                    problems.push(format!("--set {}: refused without naming the key: {why}", case.set()));
                }
                refused.push(case.clone());
            }
        }
    }

    if std::env::var_os("PROPERTIES_LIST").is_some() {
        for c in &runs {
            eprintln!("runs: --set {}", c.set());
        }
    }
    // The binary: every case that loads, and a seeded sample of the refused ones.
    let mut sample = refused.clone();
    let mut pick = SplitMix64::new(SEED ^ 1);
    for i in 0..sample.len().min(REFUSED_SAMPLE) {
        let j = i + (pick.next_u64() % (sample.len() - i) as u64) as usize;
        sample.swap(i, j);
    }
    sample.truncate(REFUSED_SAMPLE);
    let jobs: Vec<(Case, &[i32])> = runs
        .iter()
        // A realtime run on this loaded machine may end past its deadline-miss or overrun budget
        // (exit 6 or 10, by default 1 % and 5 % of the ticks): the budget doing its work.
        .map(|c| match (c.key.as_str(), c.value.as_str()) {
            ("controller.mode", "\"realtime\"") => (c.clone(), &[0, 2, 3, 6, 10][..]),
            _ => (c.clone(), &[0, 2, 3][..]),
        })
        .chain(sample.iter().map(|c| (c.clone(), &[2][..])))
        .filter(|_| std::env::var_os("PROPERTIES_LOAD_ONLY").is_none())
        .collect();
    let next = AtomicUsize::new(0);
    let found = Mutex::new(Vec::new());
    let started = Instant::now();
    std::thread::scope(|s| {
        for worker in 0..2 {
            let (jobs, next, found, dir) = (&jobs, &next, &found, &dir);
            s.spawn(move || loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some((case, allowed)) = jobs.get(i) else { break };
                if let Some(p) = run_binary(case, &dir.join(&format!("run{worker}")), allowed) {
                    found.lock().unwrap().push(p);
                }
            });
        }
    });
    problems.extend(found.into_inner().unwrap());
    eprintln!(
        "{} keys, {} cases: {} refused at load, {} ran; {} runs of the binary in {:.1?}",
        keys.len(),
        cases.len(),
        refused.len(),
        runs.len(),
        jobs.len(),
        started.elapsed()
    );
    assert!(problems.is_empty(), "{} problem(s):\n{}", problems.len(), problems.join("\n"));
}
