//! Benchmarks of `plant::Plant` from a driver outside the CLI (issues 28 and 29): one tick
//! stepped (the mean over a 60 ms run through a 10 G shock and its touchdown, restarted from
//! its first state when it ends), and the cost of the state as a value: `Plant::snapshot`,
//! `Plant::restore`, the snapshot as JSON and back (what an FMU's serialised state carries),
//! and `Snapshot::write` / `Snapshot::read` (what `plant run --save-state-at` and
//! `--from-state` do), on the planar, the two-plane and the flexible rotor.
//!
//! `cargo bench -p plant --bench stepper` (scripts/bench/fmu.sh runs it; figures in
//! docs/guide/fmu-plant.md, "Speed").

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use plant::run::Sink;
use plant::snapshot::Snapshot;
use plant::stepper::{Command, Plant};
use plant::trace::Record;
use std::time::{Duration, Instant};

/// A sink that keeps nothing.
struct Nothing;

impl Sink for Nothing {
    fn sample(&mut self, record: &Record) {
        black_box(record);
    }
}

/// The scenes benched: file, label.
const SCENES: [(&str, &str); 3] =
    [("cosim-10g.toml", "planar"), ("two-plane-asymmetric-10g.toml", "two_plane"), ("flexible-10g.toml", "flexible")];

/// The plant of `file` in sampled mode, 60 ms with the shock at 5 ms, and its bias currents.
fn plant_of(file: &str) -> (Plant, [f64; controller::ROTOR_AXES]) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../config").join(file);
    let sets: Vec<String> = ["controller.mode=\"sampled\"", "scene.duration_s=0.06", "shock[0].start_s=0.005"]
        .into_iter()
        .map(String::from)
        .collect();
    let scene = plant::config::load_scene(&path, &sets).expect("scene");
    let bias = plant::run::bias_of(&scene, &plant::run::plane_gains(&scene).expect("gains"));
    (Plant::new(&scene, &Command::Held(bias)).expect("plant"), bias)
}

/// One tick with a proportional law of the bench's own on every axis.
fn step(plant: &mut Plant, bias: &[f64; controller::ROTOR_AXES]) {
    let s = *plant.sample();
    let mut c = *bias;
    for (i, v) in s.sensor_v.iter().enumerate().take(s.axes as usize) {
        c[i] -= 0.02 * v;
    }
    plant.step(&Command::Held(c), &mut Nothing).expect("step");
}

fn tick(c: &mut Criterion) {
    for (file, label) in SCENES {
        let (mut plant, bias) = plant_of(file);
        let start = plant.snapshot();
        c.bench_function(&format!("plant_step/{label}/60ms_10g_mean"), |b| {
            b.iter_custom(|iters| {
                let mut spent = Duration::ZERO;
                for _ in 0..iters {
                    if plant.finished() {
                        plant.restore(&start).expect("restore");
                    }
                    let t = Instant::now();
                    step(&mut plant, &bias);
                    spent += t.elapsed();
                }
                spent
            })
        });
    }
}

fn state(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("amb-testbed-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp folder");
    for (file, label) in SCENES {
        let (mut plant, bias) = plant_of(file);
        // 20 ms in: 15 ms after the shock, in the touchdown.
        while plant.time() < 0.02 {
            step(&mut plant, &bias);
        }
        let snap = plant.snapshot();
        let json = serde_json::to_vec(&snap).expect("json");
        let path = dir.join(format!("{label}.json"));
        plant::snapshot::write(&snap, &path).expect("write");
        let bytes = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
        eprintln!("{label}: state of {} numbers; JSON {} bytes, the file {bytes} bytes", snap.state.len(), json.len());
        c.bench_function(&format!("snapshot/{label}/take"), |b| b.iter(|| black_box(plant.snapshot())));
        c.bench_function(&format!("snapshot/{label}/restore"), |b| {
            b.iter(|| plant.restore(black_box(&snap)).expect("restore"))
        });
        c.bench_function(&format!("snapshot/{label}/to_json"), |b| {
            b.iter(|| serde_json::to_vec(black_box(&snap)).expect("json"))
        });
        c.bench_function(&format!("snapshot/{label}/from_json"), |b| {
            b.iter(|| serde_json::from_slice::<Snapshot>(black_box(&json)).expect("json"))
        });
        c.bench_function(&format!("snapshot/{label}/write_file"), |b| {
            b.iter(|| plant::snapshot::write(&snap, &path).expect("write"))
        });
        c.bench_function(&format!("snapshot/{label}/read_file"), |b| {
            b.iter(|| Snapshot::read(black_box(&path)).expect("read"))
        });
    }
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group! {
    name = benches;
    config = Criterion::default().warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(2)).sample_size(30);
    targets = tick, state
}
criterion_main!(benches);
