//! A `Plant` step from a driver outside the CLI allocates nothing: the state, the integrator's
//! stages, the output times and the rows are all made before the first tick. Counted with a
//! global allocator that counts, over many ticks in and out of contact, on the planar model,
//! the two-plane rotor, the flexible rotor and a scene with amplifiers and a sensor front end,
//! and with every tick's execution time measured (`Plant::time_ticks`: a realtime driver's
//! histograms, recorded in place).

use plant::run::Sink;
use plant::stepper::{Command, Plant};
use plant::trace::Record;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicU64, Ordering};

struct Counting;

static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// A sink that keeps the largest radius, and nothing per row.
struct Largest(f64);

impl Sink for Largest {
    fn sample(&mut self, record: &Record) {
        let r = &record.a;
        self.0 = self.0.max(r.motion.dx_m.hypot(r.motion.dy_m));
    }
}

#[test]
fn a_plant_step_allocates_nothing() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("config");
    for (file, timed, sets) in [
        ("paper-10g.toml", false, vec!["controller.mode=\"sampled\""]),
        ("paper-10g.toml", true, vec!["controller.mode=\"sampled\""]),
        ("two-plane-asymmetric-10g.toml", false, vec!["controller.mode=\"sampled\""]),
        ("flexible-10g.toml", false, vec!["controller.mode=\"sampled\""]),
        ("realistic-10g.toml", false, vec![]),
        (
            "paper-10g.toml",
            false,
            vec![
                "controller.mode=\"sampled\"",
                "integrator.method=\"rk4\"",
                "integrator.substeps=1",
                "integrator.contact_substeps=3",
                "touchdown.race_when_clear=\"parked\"",
                "touchdown.race_release=\"equilibrium\"",
            ],
        ),
    ] {
        let mut sets: Vec<String> = sets.into_iter().map(String::from).collect();
        sets.extend(["scene.duration_s=0.06".into(), "shock[0].start_s=0.005".into()]);
        let scene = plant::config::load_scene(&root.join(file), &sets).unwrap();
        let bias = plant::run::bias_of(&scene, &plant::run::plane_gains(&scene).unwrap());
        let mut plant = Plant::new(&scene, &Command::Held(bias)).unwrap();
        if timed {
            plant.time_ticks();
        }
        let mut sink = Largest(0.0);
        // A proportional law of the test's own: no allocation of its own.
        let step = |plant: &mut Plant, sink: &mut Largest| {
            let s = *plant.sample();
            let mut c = bias;
            for (i, v) in s.sensor_v.iter().enumerate().take(s.axes as usize) {
                c[i] -= 0.02 * v;
            }
            plant.step(&Command::Held(c), sink).unwrap();
        };
        step(&mut plant, &mut sink);
        let before = ALLOCATIONS.load(Ordering::Relaxed);
        while !plant.finished() {
            step(&mut plant, &mut sink);
        }
        let during = ALLOCATIONS.load(Ordering::Relaxed) - before;
        assert!(before > 0, "the counter counts (building the plant allocates)");
        assert!(sink.0 > scene.plane(0).contact.gap, "{file}: the shock brought the rotor into contact");
        assert_eq!(
            during,
            0,
            "{file} {sets:?} (ticks timed: {timed}): {during} allocations in {} ticks",
            plant.tick() - 1
        );
    }
}
