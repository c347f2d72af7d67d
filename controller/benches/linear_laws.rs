//! The cost of one tick of the linear laws (issue 39 item 5): `state_space` with 10 states on
//! the two-plane rotor's 4 axes (continuous, Tustin at 20 kHz), and `transfer_function` of
//! order 3 on the same 4 axes (once per plane). A timing figure, never asserted.
//!
//! Run: `cargo bench -p controller --no-default-features --bench linear_laws`.

use controller::{build_rotor_law, Params, RotorDesign, RotorSample};
use criterion::{black_box, criterion_group, criterion_main, Criterion};

fn matrix(rows: usize, cols: usize, f: impl Fn(usize, usize) -> f64) -> String {
    let rows: Vec<String> = (0..rows)
        .map(|i| format!("[{}]", (0..cols).map(|j| format!("{:e}", f(i, j))).collect::<Vec<_>>().join(", ")))
        .collect();
    format!("[{}]", rows.join(", "))
}

fn laws(c: &mut Criterion) {
    let design = RotorDesign::symmetric_study();
    // A stable 10-state system: a chain of first-order lags from 100 Hz to 3 kHz, coupled.
    let n = 10;
    let a = matrix(n, n, |i, j| {
        if i == j {
            -std::f64::consts::TAU * (100.0 + 300.0 * i as f64)
        } else if j + 1 == i {
            50.0
        } else {
            0.0
        }
    });
    let text = format!(
        "a = {a}\nb = {}\nc = {}\nd = {}",
        matrix(n, 4, |i, j| if i % 4 == j { 100.0 } else { 0.0 }),
        matrix(4, n, |i, j| if j % 4 == i { -1e-3 } else { 1e-5 }),
        matrix(4, 4, |i, j| if i == j { -0.3 } else { 0.0 })
    );
    let mut ss = build_rotor_law("state_space", &design, &Params::parse(&text).unwrap()).unwrap();
    let mut k = 0u64;
    c.bench_function("state_space 10 states, 4 axes: one tick", |b| {
        b.iter(|| {
            k += 1;
            let s = RotorSample { seq: k, axes: 4, sensor_v: [1e-3, -2e-3, 5e-4, 0.0], ..Default::default() };
            black_box(ss.update(black_box(&s)))
        })
    });
    let tf = "num = [-1.2e-3, -1.2, -2.0e4, -7.0e7]\nden = [1.0e-4, 1.0, 1.0e4, 3.0e7]";
    let mut law = build_rotor_law("transfer_function", &design, &Params::parse(tf).unwrap()).unwrap();
    c.bench_function("transfer_function order 3, 4 axes (2 planes): one tick", |b| {
        b.iter(|| {
            k += 1;
            let s = RotorSample { seq: k, axes: 4, sensor_v: [1e-3, -2e-3, 5e-4, 0.0], ..Default::default() };
            black_box(law.update(black_box(&s)))
        })
    });
}

criterion_group!(benches, laws);
criterion_main!(benches);
