//! Unipolar amplifiers (docs/MODEL.md §12.3, `amb.amplifier_topology = "unipolar"`): each of an
//! axis's two magnets has its own coil and amplifier, its reference `i_0 ± i`, its voltage
//! `0..V_dc` and a current that never reverses. Here: the levitated loop against the bipolar
//! amplifier's, each magnet's columns in the trace, a shock where the magnets' limits act, bad
//! input. The magnet coil's step, slew and fall against their closed forms are the physics
//! crate's tests (`plant/physics/src/amplifier.rs`).

mod common;

use common::{assert_exit, output_within, plant_run, read_json, scene, stderr, Csv, TempDir};
use std::time::Duration;

/// The realistic scene with the nonlinear law.
const NONLINEAR: &str = "amb.force_law=nonlinear";
/// ... and the unipolar amplifiers.
const UNIPOLAR: &str = "amb.amplifier_topology=unipolar";

fn run(dir: &TempDir, name: &str, file: &std::path::Path, sets: &[&str]) -> std::path::PathBuf {
    let out = dir.join(name);
    let o = output_within(&mut plant_run(file, &out, sets), Duration::from_secs(300));
    assert_exit(&o, 0);
    out
}

/// The bias current of the realistic scene's nonlinear law, `i_0 = s_0 k_s / k_i` (A).
const I0: f64 = 1e-3 * 4.32e5 / 216.0;

/// A small disturbance (the rotor released 20 µm off centre in x and y, no shock, the scene's
/// unbalance and runout) with the two-quadrant bridge: the bias keeps both magnets of each axis
/// conducting and neither amplifier reaches a limit, so each axis's differential current
/// `(i₊ − i₋)/2` obeys the bipolar coil's very equation (`L di/dt = v − R i − k_b ẋ`, its PI the
/// same linear map of the differential error) and the common current stays at `i_0`: the force
/// is the bipolar run's. Each magnet takes half the scene's `k_b` (MODEL.md §12.3), so the
/// unipolar run has `k_b = 432 V·s/m` against the bipolar run's 216: a wrong sign or share of
/// the motional voltage would show here as a change of the loop's damping by 43 N·s/m or more
/// (of its 300). Being the same equations, the runs agree to the integrator's tolerance
/// (`rtol = 1e-6`), asserted on the displacement and the coil current (4e-9 and 2e-8 of their
/// scales measured when this test was written). The one-quadrant bridge on the same run is
/// limited at once (the release's first command asks a magnet to fall faster than its `R i/L`;
/// the 500 Hz unbalance current too): it departs from the bipolar run by tenths.
#[test]
fn a_small_disturbance_with_unipolar_amplifiers_is_the_bipolar_run() {
    let dir = TempDir::new("unipolar-levitated");
    let file = scene("realistic-10g.toml");
    let text = std::fs::read_to_string(&file).unwrap();
    let cut = text.find("[[shock]]").expect("the scene has a shock");
    let decay = dir.join("decay.toml");
    std::fs::write(&decay, &text[..cut]).unwrap();
    let common =
        ["scene.duration_s=0.15", "output.plots=false", "initial.rotor_x_um=20", "initial.rotor_y_um=20", NONLINEAR];
    let mut sets = common.to_vec();
    sets.push("amb.back_emf_v_s_per_m=216");
    let bipolar = run(&dir, "bipolar", &decay, &sets);
    let mut sets = common.to_vec();
    sets.extend([UNIPOLAR, "amb.back_emf_v_s_per_m=432", "amb.unipolar_bridge=two_quadrant"]);
    let unipolar = run(&dir, "unipolar", &decay, &sets);
    sets.pop();
    let one_quadrant = run(&dir, "one-quadrant", &decay, &sets);

    let b = Csv::read(&bipolar.join("trace.csv"));
    let worst = |u: &Csv, name: &str| {
        let (x, y) = (b.column(name), u.column(name));
        assert_eq!(x.len(), y.len());
        let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = x.iter().zip(&y).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(scale > 0.0);
        diff / scale
    };
    let u = Csv::read(&unipolar.join("trace.csv"));
    let one = Csv::read(&one_quadrant.join("trace.csv"));
    let mut report = Vec::new();
    for name in ["dx_m", "dy_m", "ix_coil_a", "iy_coil_a"] {
        let (two, one) = (worst(&u, name), worst(&one, name));
        report.push(format!("{name}: two-quadrant {two:e}, one-quadrant {one:e} of the scale"));
        assert!(two < 1e-6, "{name}: the two-quadrant run differs from the bipolar one by {two:e} of the scale");
        assert!(one > 0.05, "{name}: the one-quadrant run differs from the bipolar one by only {one:e}");
    }
    eprintln!("{}", report.join("\n"));
    for out in [&bipolar, &unipolar] {
        let s = read_json(&out.join("summary.json"));
        assert_eq!(s["voltage_saturation_s"].as_f64(), Some(0.0), "{}: {s:#}", out.display());
    }
    let s = read_json(&one_quadrant.join("summary.json"));
    assert!(s["voltage_saturation_s"].as_f64().unwrap() > 0.01, "{s:#}");
    for axis in ["x", "y"] {
        let plus = u.column(&format!("i{axis}_plus_a"));
        let minus = u.column(&format!("i{axis}_minus_a"));
        for (p, m) in plus.iter().zip(&minus) {
            assert!(*p > 0.5 && *m > 0.5, "{axis}: a magnet stopped conducting ({p} A, {m} A)");
            assert!((p + m - 2.0 * I0).abs() < 1e-6, "{axis}: common current {} A, not i_0", (p + m) / 2.0);
        }
    }
}

/// The 10 G shock with unipolar amplifiers and a bias of 1 A (`nominal_gap_mm = 0.5`, so that
/// the command of up to 2 A asks the magnet on the unloaded side for less than nothing): each
/// magnet's current and voltage after all the other columns, the coil columns their
/// differential, every magnet current ≥ 0 and within the bus's reach (`V_dc/R`). Two-quadrant:
/// magnets are driven to zero and stay there (the clamp: at a zero current the coil's voltage
/// is its motional voltage `±(k_b/2) ẋ`, or above it while the current starts again, never
/// below), voltages within `±V_dc`. One-quadrant: voltages within `0..V_dc` (or the motional
/// voltage of a coil at zero), some magnet at its 0 V floor most of the run, and the magnets'
/// largest fall slower than their largest rise.
#[test]
fn a_unipolar_shock_run_records_each_magnet_within_its_limits() {
    let dir = TempDir::new("unipolar-columns");
    let (v_dc, r, kb) = (150.0, 1.0, 216.0);
    for bridge in ["two_quadrant", "one_quadrant"] {
        let set = format!("amb.unipolar_bridge={bridge}");
        let sets = ["scene.duration_s=0.06", "output.plots=false", NONLINEAR, UNIPOLAR, "amb.nominal_gap_mm=0.5", &set];
        let out = run(&dir, bridge, &scene("realistic-10g.toml"), &sets);
        let t = Csv::read(&out.join("trace.csv"));
        let tail: Vec<&str> = t.header.iter().rev().take(12).rev().map(String::as_str).collect();
        assert_eq!(
            tail,
            [
                "ix_coil_a",
                "iy_coil_a",
                "vx_coil_v",
                "vy_coil_v",
                "ix_plus_a",
                "ix_minus_a",
                "iy_plus_a",
                "iy_minus_a",
                "vx_plus_v",
                "vx_minus_v",
                "vy_plus_v",
                "vy_minus_v"
            ]
        );
        let floor = if bridge == "two_quadrant" { -v_dc } else { 0.0 };
        let (mut zeros, mut fall, mut rise) = (0, 0.0f64, 0.0f64);
        let time = t.column("t_s");
        for axis in ["x", "y"] {
            let coil = t.column(&format!("i{axis}_coil_a"));
            let speed = t.column(&format!("v{axis}_m_s"));
            let (ip, im) = (t.column(&format!("i{axis}_plus_a")), t.column(&format!("i{axis}_minus_a")));
            let (vp, vm) = (t.column(&format!("v{axis}_plus_v")), t.column(&format!("v{axis}_minus_v")));
            for k in 0..ip.len() {
                assert!((coil[k] - (ip[k] - im[k]) / 2.0).abs() <= 1e-12 * coil[k].abs().max(1.0));
                for (i, v, side) in [(&ip, &vp, 1.0), (&im, &vm, -1.0)] {
                    assert!(i[k] >= 0.0 && i[k] <= v_dc / r, "{bridge} {axis}: current {} A at row {k}", i[k]);
                    let emf = side * 0.5 * kb * speed[k];
                    if i[k] == 0.0 {
                        zeros += 1;
                        assert!(
                            v[k] >= emf - 1e-9 * emf.abs(),
                            "{bridge} {axis}: {} V on a coil at zero current",
                            v[k]
                        );
                    } else {
                        assert!(v[k] >= floor && v[k] <= v_dc, "{bridge} {axis}: {} V at row {k}", v[k]);
                    }
                    if k > 0 {
                        let rate = (i[k] - i[k - 1]) / (time[k] - time[k - 1]);
                        fall = fall.max(-rate);
                        rise = rise.max(rate);
                    }
                }
            }
        }
        let saturated = read_json(&out.join("summary.json"))["voltage_saturation_s"].as_f64().expect("a figure");
        eprintln!("{bridge}: {zeros} magnet samples at zero, fall ≤ {fall:.0} A/s, rise ≤ {rise:.0} A/s, {saturated} s limited");
        if bridge == "two_quadrant" {
            assert!(zeros > 10, "the shock drove no magnet to zero current");
        } else {
            assert!(saturated > 0.03, "{saturated} s at the limit");
            assert!(fall < 0.7 * rise, "one-quadrant: fall {fall} A/s against rise {rise} A/s");
        }
    }
}

/// A two-plane rotor with unipolar amplifiers on plane B only: plane B's magnet columns are
/// numbers, plane A's (bipolar) are `NaN`, all after the coil columns.
#[test]
fn a_two_plane_unipolar_run_has_each_planes_magnets() {
    let dir = TempDir::new("unipolar-two-plane");
    let sets = [
        "scene.duration_s=0.01",
        "output.plots=false",
        "amb.amplifier=true",
        NONLINEAR,
        "amb.b.amplifier_topology=unipolar",
    ];
    let out = run(&dir, "run", &scene("two-plane-asymmetric-10g.toml"), &sets);
    let t = Csv::read(&out.join("trace.csv"));
    assert_eq!(t.header.len(), 37 + 8 + 16);
    assert_eq!(t.header[45], "ix_plus_a");
    assert_eq!(t.header[53], "b_ix_plus_a");
    assert_eq!(t.header[60], "b_vy_minus_v");
    assert!(t.column("ix_plus_a").iter().all(|v| v.is_nan()));
    assert!(t.column("b_iy_plus_a").iter().all(|v| v.is_finite() && *v > 0.0));
}

/// Bad input: each a clear error naming key, value and unit, exit 2.
#[test]
fn bad_unipolar_settings_are_refused_naming_key_value_and_unit() {
    let dir = TempDir::new("unipolar-bad");
    let file = scene("realistic-10g.toml");
    let cases: &[(&[&str], &[&str])] = &[
        // The linear law has no bias for the magnets to carry.
        (&[UNIPOLAR], &["amb.amplifier_topology = unipolar", "amb.force_law = \"nonlinear\""]),
        (&["amb.amplifier_topology=tripolar"], &["amplifier_topology", "tripolar"]),
        (&[NONLINEAR, UNIPOLAR, "amb.unipolar_bridge=three_quadrant"], &["unipolar_bridge", "three_quadrant"]),
        // R i_0 = 1 Ω · 2 A = 2 V: a 1.5 V bus cannot hold the bias.
        (&[NONLINEAR, UNIPOLAR, "amb.bus_voltage_v=1.5"], &["amb.bus_voltage_v = 1.5 V", "R i_0 = 2.0000 V"]),
        (&[NONLINEAR, UNIPOLAR, "amb.amplifier=false"], &["amb.amplifier_topology = unipolar", "amb.amplifier = true"]),
    ];
    for (i, (sets, needles)) in cases.iter().enumerate() {
        let mut all = vec!["output.plots=false"];
        all.extend_from_slice(sets);
        let o = output_within(&mut plant_run(&file, &dir.join(&format!("{i}")), &all), Duration::from_secs(60));
        assert_exit(&o, 2);
        let e = stderr(&o);
        for needle in needles.iter() {
            assert!(e.contains(needle), "{sets:?}: expected `{needle}` in: {e}");
        }
    }
    // Two-plane: the plane's own key is named.
    let sets = ["output.plots=false", "amb.amplifier=true", "amb.b.amplifier_topology=unipolar"];
    let o = output_within(
        &mut plant_run(&scene("two-plane-asymmetric-10g.toml"), &dir.join("two"), &sets),
        Duration::from_secs(60),
    );
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("amb.b.amplifier_topology = unipolar"), "{}", stderr(&o));
}
