//! Issue 38 item 2: turned AMB axes (`amb.axis_angle_deg`, docs/MODEL.md §3.3) through whole
//! runs. The rotor's motion is in the housing's (x, y), the currents in the plane's (u, v):
//! a rig turned by θ, its law in its own axes, moves as the rig at 0° does, and its currents are
//! the 0° rig's turned, `i_u = i_x cos θ + i_y sin θ`, `i_v = −i_x sin θ + i_y cos θ` (by hand
//! below), while the loop is the same in every direction (linear law, no saturation or range
//! reached, no runout, which is a per-axis signal). At 45° each coil pair carries the weight
//! over √2. Bad angles are refused naming the key, the value and its unit.

use plant::config::{load_scene, ConfigError, Scene};
use plant::trace::Trace;
use std::path::Path;

fn scene(file: &str, sets: &[&str]) -> Result<Scene, ConfigError> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../config").join(file);
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    load_scene(&path, &sets)
}

fn run(file: &str, sets: &[&str]) -> Trace {
    let s = scene(file, sets).unwrap_or_else(|e| panic!("{file} {sets:?}: {e}"));
    plant::run::run(&s, &mut plant::hooks::Quiet).expect("runs").trace
}

/// Each plane's (dx, dy, ix, iy) at every sample.
fn planes(t: &Trace) -> Vec<[Vec<f64>; 4]> {
    let mut out = vec![[t.motion.dx_m.clone(), t.motion.dy_m.clone(), t.loads.ix_a.clone(), t.loads.iy_a.clone()]];
    if let Some(b) = &t.b {
        let column = |f: fn(&plant::trace::RowB) -> f64| b.iter().map(f).collect::<Vec<f64>>();
        out.push([
            column(|r| r.motion.dx_m),
            column(|r| r.motion.dy_m),
            column(|r| r.loads.ix_a),
            column(|r| r.loads.iy_a),
        ]);
    }
    out
}

/// The run at `deg` against the run at 0° (the same `sets` otherwise): positions equal within
/// `1e-7` of the largest, currents the 0° run's turned by hand within `1e-7` of the largest.
fn same_motion(file: &str, sets: &[&str], deg: f64) {
    let turned_key = format!("amb.axis_angle_deg={deg:?}");
    let mut turned_sets: Vec<&str> = sets.to_vec();
    turned_sets.push(&turned_key);
    let (plain, turned) = (run(file, sets), run(file, &turned_sets));
    assert_eq!(plain.len(), turned.len(), "{file}");
    let (s, c) = deg.to_radians().sin_cos();
    for (p, (a, b)) in planes(&plain).iter().zip(&planes(&turned)).enumerate() {
        let size = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let moved = size(&a[0]).max(size(&a[1]));
        let current = size(&a[2]).max(size(&a[3]));
        assert!(moved > 1e-7 && current > 1e-3, "{file}: the rotor does not move ({moved} m, {current} A)");
        for i in 0..a[0].len() {
            for k in 0..2 {
                let d = (a[k][i] - b[k][i]).abs();
                assert!(
                    d <= 1e-7 * moved,
                    "{file} {deg}°: plane {p} position {k} at sample {i}: {} against {}",
                    b[k][i],
                    a[k][i]
                );
            }
            let (ix, iy) = (a[2][i], a[3][i]);
            let want = [ix * c + iy * s, -ix * s + iy * c];
            for k in 0..2 {
                let d = (b[2 + k][i] - want[k]).abs();
                assert!(
                    d <= 1e-7 * current,
                    "{file} {deg}°: plane {p} current {k} at sample {i}: {} against {}",
                    b[2 + k][i],
                    want[k]
                );
            }
        }
    }
}

/// The planar study rig at 1 G (levitated, no contact) with the continuous PD.
#[test]
fn a_turned_planar_rig_moves_as_the_plain_one() {
    let sets = ["scene.duration_s=0.06", "output.plots=false"];
    same_motion("levitation-1g.toml", &sets, 45.0);
    same_motion("levitation-1g.toml", &sets, -30.0);
}

/// The realistic rig (amplifiers with back-EMF, the sensor's 5 kHz filter and range) with the
/// PD sampled at 20 kHz: the law, the coils and the sensor filter in (u, v). Without the gravity
/// bias (a sampled law adds it on its own y: refused turned) and without runout, stepped by RK4.
#[test]
fn a_turned_realistic_rig_moves_as_the_plain_one() {
    let sets = [
        "scene.duration_s=0.05",
        "output.plots=false",
        "shock[0].peak_g=1.0",
        "sensor.runout=[]",
        "controller.gravity_bias=false",
        // Without the bias the coils start at 0 A and step to the weight's current: at 150 V each
        // axis's amplifier saturates, and a voltage limit per axis is not the same in every
        // direction. A bus that never limits keeps the loop linear.
        "amb.bus_voltage_v=5000",
        // Fixed steps: the adaptive step's error norm weighs the coils' states axis by axis, so
        // its steps (and its error, rtol = 1e-6) would differ with the axes.
        "integrator.method=\"rk4\"",
    ];
    same_motion("realistic-10g.toml", &sets, 45.0);
}

/// The two-plane and the flexible rotor, each plane turned by the same angle.
#[test]
fn turned_two_plane_and_flexible_rigs_move_as_the_plain_ones() {
    let sets = ["scene.duration_s=0.04", "output.plots=false", "shock[0].peak_g=1.0"];
    same_motion("two-plane-asymmetric-10g.toml", &sets, 45.0);
    same_motion("flexible-10g.toml", &sets, 45.0);
}

/// At 45°, levitated before the shock, each coil pair carries the plane's weight over √2:
/// `i_u = i_v = m g / (√2 k_i)` with the study's m = 11.5 kg, g = 9.80665 m/s², k_i = 216 N/A
/// (the scene's numbers, written out); at 0° the y pair carries it all.
#[test]
fn at_45_degrees_each_axis_carries_the_weight_over_root_two() {
    let weight = 11.5 * 9.80665 / 216.0;
    let sets = ["scene.duration_s=0.01", "output.plots=false", "shock[0].start_s=0.5", "rotor.eccentricity_um=0"];
    let t = run("levitation-1g.toml", &[sets[0], sets[1], sets[2], sets[3], "amb.axis_angle_deg=45"]);
    for i in 0..t.len() {
        for (k, got) in [t.loads.ix_a[i], t.loads.iy_a[i]].into_iter().enumerate() {
            assert!((got - weight / 2f64.sqrt()).abs() < 1e-9, "sample {i}, axis {k}: {got} A");
        }
        assert!(t.motion.dx_m[i].abs() < 1e-12 && t.motion.dy_m[i].abs() < 1e-12, "sample {i}: the rotor moves");
    }
    let t = run("levitation-1g.toml", &sets);
    assert!(t.loads.ix_a[0].abs() < 1e-12 && (t.loads.iy_a[0] - weight).abs() < 1e-9);
}

/// The key's bad values: refused naming the key, the value and its unit; the sampled law with
/// its gravity bias on a turned plane, refused naming the way out.
#[test]
fn bad_angles_are_refused() {
    for (value, shown) in [("91", "91"), ("-90.5", "-90.5"), ("nan", "NaN"), ("inf", "inf"), ("1e300", "1e300")] {
        let set = format!("amb.axis_angle_deg={value}");
        let e = scene("levitation-1g.toml", &[&set]).expect_err(&set).to_string();
        assert!(
            e.contains("amb.axis_angle_deg") && e.contains(shown) && e.contains('°') && e.contains("[-90, 90]"),
            "{set}: {e}"
        );
    }
    let e = scene("levitation-1g.toml", &["amb.axis_angle_deg=\"45\""]).expect_err("a string").to_string();
    assert!(e.contains("axis_angle_deg"), "{e}");
    for edge in ["90", "-90", "0"] {
        scene("levitation-1g.toml", &[&format!("amb.axis_angle_deg={edge}")]).unwrap_or_else(|e| panic!("{edge}: {e}"));
    }
    let e = scene("realistic-10g.toml", &["amb.axis_angle_deg=45"]).expect_err("sampled with gravity bias").to_string();
    assert!(e.contains("amb.axis_angle_deg") && e.contains("controller.gravity_bias = false"), "{e}");
    // Plane B's own angle is named as plane B's.
    let e = scene("two-plane-asymmetric-10g.toml", &["amb.b.axis_angle_deg=120"]).expect_err("plane B").to_string();
    assert!(e.contains("amb.b.axis_angle_deg") && e.contains("120"), "{e}");
}
