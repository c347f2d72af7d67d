//! Benchmark: building a flexible rotor's reduced model against the shaft's element count
//! (`cargo bench -p plant-physics --bench shaft`): a uniform steel shaft of 0.5 m, 40 mm, in
//! `n` Timoshenko elements, AMBs and touchdown bearings at the nodes nearest 10 % and 90 % of
//! its length, modes below 2 kHz with the static and gyroscopic corrections (as the shipped
//! flexible scene reduces). Up to `flex::DENSE_ELEMENTS` (200) the full matrices are dense
//! (4 (n + 1) coordinates) and the modes come from a dense symmetric eigensolver: the cost grows
//! as n³. Above it the matrices are bands and the modes come from subspace iteration: the cost
//! grows as n, the cost per element the slope of the band sizes (docs/results/flexible-rotor.md,
//! "How big a shaft"), up to `flex::MAX_ELEMENTS` (2,000).

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion};
use plant_physics::flex::reduce::{Reduced, Reduction};
use plant_physics::flex::rotor::Rotor;
use plant_physics::flex::shaft::{Material, ShaftElement};

fn shaft(n: usize) -> (Rotor, Reduction) {
    let steel = Material { density: 7810.0, modulus: 211e9, shear_modulus: 81.2e9 };
    let elements = (0..n).map(|_| ShaftElement::cylinder(0.5 / n as f64, 0.0, 0.04, steel)).collect();
    let rotor = Rotor { elements, disks: Vec::new(), bearings: Vec::new(), alpha: 0.0, beta: 0.0 };
    let (a, b) = (n / 10, n - n / 10);
    let spec = Reduction {
        cutoff_hz: 2000.0,
        force_nodes: vec![a, b],
        static_correction: true,
        gyroscopic_correction: true,
        modal_damping: 0.005,
    };
    (rotor, spec)
}

fn build(c: &mut Criterion) {
    let mut g = c.benchmark_group("shaft/reduce");
    g.sample_size(10);
    for n in [16usize, 64, 128, 200, 250, 500, 1000, 2000] {
        let (rotor, spec) = shaft(n);
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| Reduced::new(black_box(&rotor), black_box(&spec)).expect("reduces"))
        });
    }
    g.finish();
}

criterion_group!(benches, build);
criterion_main!(benches);
