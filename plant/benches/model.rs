//! Benchmarks: one derivative evaluation (all 19 ball contacts evaluated, rotor
//! in contact with the race; the two-plane rotor with both planes so) and one macro
//! step (one controller period) of each integrator, levitated and in contact.

mod common;

use common::{contact_state, model, two_plane_contact_state, two_plane_model};
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use plant::integrate::{Integrator, Method, Settings};
use plant::machine::Machine;
use plant::model::Control;
use plant::run::settings_with;

fn derivative(c: &mut Criterion) {
    let (model, _) = model();
    let y = contact_state();
    let ev = model.evaluate(0.002, &y);
    assert!(ev.contact.normal > 0.0 && ev.balls.loaded >= 3, "bench state must load the contacts: {ev:?}");
    c.bench_function("derivative/contact_19_balls", |b| b.iter(|| model.evaluate(black_box(0.002), black_box(&y)).dy));
    let levitated = plant::initial::initial_state(&model_scene(), &model.params);
    c.bench_function("derivative/levitated", |b| b.iter(|| model.evaluate(black_box(0.002), black_box(&levitated)).dy));
    let (two, scene) = two_plane_model();
    let y = two_plane_contact_state();
    let ev = two.evaluate(0.002, &y);
    assert!(ev.planes.iter().all(|p| p.contact.normal > 0.0 && p.balls.loaded >= 3), "both planes in contact: {ev:?}");
    c.bench_function("derivative/two_plane_contact_2x19_balls", |b| {
        b.iter(|| two.evaluate(black_box(0.002), black_box(&y)).dy)
    });
    let levitated = plant::initial::two_plane_initial_state(&scene, &two.params);
    c.bench_function("derivative/two_plane_levitated", |b| {
        b.iter(|| two.evaluate(black_box(0.002), black_box(&levitated)).dy)
    });
}

/// The flexible rotor's derivative in contact against the size of its reduced basis: the
/// shipped `config/flexible-10g.toml` at several cutoffs (`derivative/flexible_contact_r{r}`, r from 10 to 22,
/// `r` the reduced coordinates), both touchdown nodes 15 µm into their races, the continuous
/// PD at each plane. The slope over `r` is the cost per retained mode
/// (docs/results/flexible-rotor.md, "Speed").
fn flexible_derivative(c: &mut Criterion) {
    use plant_physics::flex::machine::Model;
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/flexible-10g.toml");
    for cutoff_hz in [1000.0, 2000.0, 4000.0, 8000.0] {
        let scene =
            plant::config::load_scene(&path, &[format!("rotor.cutoff_hz={cutoff_hz}")]).expect("flexible scene");
        let params = match &scene.rotor {
            plant::config::Rotor::Flexible(p) => p.clone(),
            other => panic!("a flexible scene, not {:?}", other.model()),
        };
        let gains = plant::run::plane_gains(&scene).expect("gains");
        let mut y = Model::from_rigid(&params, &two_plane_contact_state());
        // Spinning at the scene's held speed, as its runs do (the contact state is the planar
        // scene's, at its own speed).
        y[plant_physics::flex::machine::ix::WR] = params.machine.rotor.speed;
        let r = params.reduced.size();
        let model = Model {
            params,
            base: scene.base.clone(),
            control: [Control::Continuous(gains[0]), Control::Continuous(gains[1])],
            race_parked: [false; 2],
        };
        let ev = model.evaluate(0.002, &y);
        assert!(
            ev.planes.iter().all(|p| p.contact.normal > 0.0 && p.balls.loaded >= 3),
            "both planes in contact: {ev:?}"
        );
        c.bench_function(&format!("derivative/flexible_contact_r{r}"), |b| {
            b.iter(|| model.evaluate(black_box(0.002), black_box(&y)).dy)
        });
    }
}

fn model_scene() -> plant::config::Scene {
    model().1
}

fn macro_step(c: &mut Criterion) {
    let (model, scene) = model();
    let period = scene.controller.period;
    let levitated = plant::initial::initial_state(&scene, &model.params);
    let integrator_settings =
        |scene: &plant::config::Scene| settings_with(scene, plant::model::Model::atol(scene.integrator.atol_groups));
    let cases: [(&str, Settings<{ plant::model::N }>); 3] = [
        ("dp5_rtol1e-6", integrator_settings(&scene)),
        ("rk4_16", Settings { substeps: 16, ..Settings::fixed(Method::Rk4, 16) }),
        ("dop853_rtol1e-9", Settings { rtol: 1e-9, atol: [1e-12; plant::model::N], ..integrator_settings(&scene) }),
    ];
    for (name, settings) in cases {
        for (state_name, y0) in [("levitated", levitated), ("contact", contact_state())] {
            let settings = Settings {
                method: if name.starts_with("dop853") { Method::Dop853 } else { settings.method },
                ..settings.clone()
            };
            let mut integrator = Integrator::new(settings);
            c.bench_function(&format!("macro_step/{name}/{state_name}"), |b| {
                b.iter(|| {
                    let mut y = y0;
                    integrator.advance(&model, 0.002, 0.002 + period, &mut y).expect("step");
                    y
                })
            });
        }
    }
}

criterion_group!(benches, derivative, flexible_derivative, macro_step);
criterion_main!(benches);
