//! The amplifier and the sensor's front end between the wire and the physics (docs/MODEL.md §11,
//! `amb.amplifier`, `[sensor]`'s bandwidth, runout and range): the levitated loop's damping
//! against the linear analysis, the trace's coil columns and the summary's saturation time, bad
//! input. The coil's step responses against their closed forms are the physics crate's tests
//! (`plant/physics/src/amplifier.rs`); the runout at the centre and the low-pass's lag, the
//! plant's (`plant/sim/src/hardware.rs`, `plant/sim/src/sensor.rs`).

mod common;

use common::{assert_exit, output_within, plant_run, read_json, scene, stderr, Csv, TempDir};
use std::time::Duration;

/// `paper-10g.toml` without its shock (a free decay), written to `dir`.
fn no_shock(dir: &TempDir, from: &str) -> std::path::PathBuf {
    let text = std::fs::read_to_string(scene(from)).unwrap();
    let cut = text.find("[[shock]]").expect("the scene has a shock");
    let path = dir.join("decay.toml");
    std::fs::write(&path, &text[..cut]).unwrap();
    path
}

/// The free decay's overrides: 0.6 s, no unbalance, 10 µm off centre in x, damping ratio `xi`.
fn decay_sets(xi: f64) -> Vec<String> {
    vec![
        "scene.duration_s=0.6".to_string(),
        "rotor.eccentricity_um=0".into(),
        "initial.rotor_x_um=10".into(),
        "output.plots=false".into(),
        "output.rate_hz=20000".into(),
        format!("controller.damping_ratio={xi}"),
    ]
}

/// A complex number as (re, im), for the root finder.
type C = (f64, f64);

fn mul(a: C, b: C) -> C {
    (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0)
}

fn div(a: C, b: C) -> C {
    let d = b.0 * b.0 + b.1 * b.1;
    ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
}

/// The roots of the polynomial with coefficients `c` (highest power first), Durand–Kerner.
fn roots(c: &[f64]) -> Vec<C> {
    let n = c.len() - 1;
    let a: Vec<f64> = c.iter().map(|x| x / c[0]).collect();
    let eval = |z: C| a.iter().fold((0.0, 0.0), |acc, &k| (mul(acc, z).0 + k, mul(acc, z).1));
    let scale = a.iter().skip(1).map(|x| x.abs()).fold(1.0, f64::max);
    let mut z: Vec<C> = (0..n)
        .map(|k| {
            let phi = 0.4 + std::f64::consts::TAU * k as f64 / n as f64;
            (scale * phi.cos(), scale * phi.sin())
        })
        .collect();
    for _ in 0..5000 {
        for i in 0..n {
            let mut d = (1.0, 0.0);
            for j in 0..n {
                if j != i {
                    d = mul(d, (z[i].0 - z[j].0, z[i].1 - z[j].1));
                }
            }
            let step = div(eval(z[i]), d);
            z[i] = (z[i].0 - step.0, z[i].1 - step.1);
        }
    }
    z
}

/// The decay rate σ (1/s, < 0 decaying) of the oscillation in `x` over `t`: a least-squares
/// line through the logarithms of its positive peaks after `from` (s).
fn decay_rate(t: &[f64], x: &[f64], from: f64) -> f64 {
    let peaks: Vec<(f64, f64)> = (1..x.len() - 1)
        .filter(|&i| t[i] >= from && x[i] > 0.0 && x[i] >= x[i - 1] && x[i] > x[i + 1])
        .map(|i| (t[i], x[i].ln()))
        .collect();
    assert!(peaks.len() > 10, "{} peaks", peaks.len());
    let n = peaks.len() as f64;
    let (st, sy) = peaks.iter().fold((0.0, 0.0), |(a, b), p| (a + p.0, b + p.1));
    let (mt, my) = (st / n, sy / n);
    let (num, den) = peaks.iter().fold((0.0, 0.0), |(a, b), p| (a + (p.0 - mt) * (p.1 - my), b + (p.0 - mt).powi(2)));
    num / den
}

/// The levitated loop's free decay (continuous PD on the planar rotor, no shock, no unbalance,
/// 10 µm off centre in x) with each amplifier setting, against the least-damped root of the
/// linear loop: `m s² x = k_i i + k_s x`, `i_ref = −(P + D s) x` (`k_i P = k_e + k_s`,
/// `k_i D = c_e`), and the coil with its PI loop (zero on the coil's pole, bandwidth ω_c):
/// `i = K_p/(L s + K_p) i_ref − k_b s² x / ((L s + K_p)(s + R/L))`, `K_p = L ω_c`.
#[test]
fn levitated_damping_with_the_amplifier_is_the_linear_analysis() {
    let dir = TempDir::new("hw-damping");
    let file = no_shock(&dir, "paper-10g.toml");
    let (m, ks, ki, ke): (f64, f64, f64, f64) = (11.5, 4.32e5, 216.0, 1.0e6);
    let (l, r): (f64, f64) = (58e-3, 1.0);
    // (label, xi_e, current-loop bandwidth (Hz; 0 = ideal), k_b)
    let cases = [("ideal", 0.04, 0.0, 0.0), ("1.5 kHz", 0.04, 1500.0, 0.0), ("1.5 kHz, back-EMF", 0.04, 1500.0, 216.0)];
    let mut report = Vec::new();
    for (label, xi, fc, kb) in cases {
        let mut sets = decay_sets(xi);
        if fc > 0.0 {
            sets.extend([
                "amb.amplifier=true".to_string(),
                format!("amb.current_loop_hz={fc}"),
                format!("amb.back_emf_v_s_per_m={kb}"),
                format!("amb.coil_inductance_mh={}", l * 1e3),
                format!("amb.coil_resistance_ohm={r}"),
                // Far above the demand: the loop stays linear.
                "amb.bus_voltage_v=10000".into(),
            ]);
        }
        let out = dir.join(label);
        let sets_ref: Vec<&str> = sets.iter().map(String::as_str).collect();
        let o = output_within(&mut plant_run(&file, &out, &sets_ref), Duration::from_secs(300));
        assert_exit(&o, 0);
        let trace = Csv::read(&out.join("trace.csv"));
        let measured = decay_rate(&trace.column("t_s"), &trace.column("dx_m"), 0.02);
        let ce = 2.0 * xi * (ke * m).sqrt();
        let (p, d) = ((ke + ks) / ki, ce / ki);
        let poly: Vec<f64> = if fc == 0.0 {
            vec![m, ki * d, ki * p - ks]
        } else {
            // (m s² − k_s)(L s + K_p)(s + R/L) + k_i K_p (P + D s)(s + R/L) + k_i k_b s² = 0
            let kp = l * std::f64::consts::TAU * fc;
            let a = r / l;
            // (L s + K_p)(s + a) = L s² + (L a + K_p) s + K_p a
            let q = [l, l * a + kp, kp * a];
            // (m s² − k_s) q: degree 4
            let mut c = [m * q[0], m * q[1], m * q[2] - ks * q[0], -ks * q[1], -ks * q[2]];
            // k_i K_p (D s + P)(s + a) = k_i K_p (D s² + (D a + P) s + P a)
            c[2] += ki * kp * d + ki * kb;
            c[3] += ki * kp * (d * a + p);
            c[4] += ki * kp * p * a;
            c.to_vec()
        };
        let wn = ((ke) / m).sqrt();
        let root = roots(&poly)
            .into_iter()
            .filter(|z| z.1 > 0.3 * wn && z.1 < 3.0 * wn)
            .max_by(|a, b| a.0.partial_cmp(&b.0).unwrap())
            .expect("the rigid mode's root");
        let predicted = root.0;
        report.push(format!("{label}: measured σ = {measured:.4} 1/s, linear {predicted:.4} 1/s"));
        assert!(
            (measured - predicted).abs() < 0.01 * predicted.abs() + 0.02,
            "{label}: measured σ = {measured} 1/s against the linear analysis's {predicted} 1/s"
        );
    }
    // The bandwidth costs damping, the back-EMF gives some back: the three differ.
    eprintln!("{}", report.join("\n"));
}

/// The continuous PD reads the sensor's front end: its free decay with a 5 kHz sensor (second
/// order, then first) is the least-damped root of the linear loop with the filter,
/// `(m s² − k_s)(s² + √2 ω s + ω²) + k_i ω² (P + D s) = 0` (first order: `(m s² − k_s)(s + ω)
/// + k_i ω (P + D s) = 0`), not the ideal loop's.
#[test]
fn the_continuous_pd_through_a_sensor_bandwidth_is_the_linear_analysis() {
    let dir = TempDir::new("hw-sensor-damping");
    let file = no_shock(&dir, "paper-10g.toml");
    let (m, ks, ki, ke, xi): (f64, f64, f64, f64, f64) = (11.5, 4.32e5, 216.0, 1.0e6, 0.04);
    let ce = 2.0 * xi * (ke * m).sqrt();
    let (p, d) = ((ke + ks) / ki, ce / ki);
    let w = std::f64::consts::TAU * 5000.0;
    let wn = (ke / m).sqrt();
    let ideal = -ce / (2.0 * m);
    for order in [2u32, 1] {
        let mut sets = decay_sets(xi);
        sets.extend(["sensor.bandwidth_hz=5000".to_string(), format!("sensor.filter_order={order}")]);
        let out = dir.join(&format!("order-{order}"));
        let sets_ref: Vec<&str> = sets.iter().map(String::as_str).collect();
        let o = output_within(&mut plant_run(&file, &out, &sets_ref), Duration::from_secs(300));
        assert_exit(&o, 0);
        let trace = Csv::read(&out.join("trace.csv"));
        let measured = decay_rate(&trace.column("t_s"), &trace.column("dx_m"), 0.02);
        let poly: Vec<f64> = if order == 2 {
            // (m s² − k_s)(s² + √2 ω s + ω²) + k_i ω² (D s + P)
            let r2 = std::f64::consts::SQRT_2 * w;
            vec![m, m * r2, m * w * w - ks, -ks * r2 + ki * w * w * d, -ks * w * w + ki * w * w * p]
        } else {
            // (m s² − k_s)(s + ω) + k_i ω (D s + P)
            vec![m, m * w, -ks + ki * w * d, -ks * w + ki * w * p]
        };
        let root = roots(&poly)
            .into_iter()
            .filter(|z| z.1 > 0.3 * wn && z.1 < 3.0 * wn)
            .max_by(|a, b| a.0.partial_cmp(&b.0).unwrap())
            .expect("the rigid mode's root");
        eprintln!("order {order}: measured σ = {measured:.4} 1/s, linear {:.4} 1/s, ideal {ideal:.4} 1/s", root.0);
        assert!(
            (measured - root.0).abs() < 0.01 * root.0.abs() + 0.02,
            "order {order}: measured σ = {measured} 1/s against the linear analysis's {} 1/s",
            root.0
        );
        // The filter's lag is visible: at least a tenth of the ideal loop's damping is gone.
        assert!(measured > 0.9 * ideal, "order {order}: σ = {measured} 1/s, the ideal loop's {ideal} 1/s");
    }
}

/// An amplifier run's trace has the coils' columns after all the others, `plant analyze` still
/// reads it, and the summary has the time at the voltage limit: none with the realistic
/// scene's 150 V, some with 20 V, where the coil voltage sits at ±20 V.
#[test]
fn an_amplifier_run_records_its_coils_and_its_time_at_the_voltage_limit() {
    let dir = TempDir::new("hw-columns");
    let file = scene("realistic-10g.toml");
    let short = ["scene.duration_s=0.08", "output.plots=false"];
    let out = dir.join("realistic");
    assert_exit(&output_within(&mut plant_run(&file, &out, &short), Duration::from_secs(120)), 0);
    let header = std::fs::read_to_string(out.join("trace.csv")).unwrap();
    let header = header.lines().next().unwrap();
    assert!(header.ends_with(",housing_y_m,ix_coil_a,iy_coil_a,vx_coil_v,vy_coil_v"), "{header}");
    let summary = read_json(&out.join("summary.json"));
    assert_eq!(summary["voltage_saturation_s"].as_f64(), Some(0.0), "{summary:#}");
    let analyzed = output_within(
        std::process::Command::new(common::plant_bin()).args(["analyze"]).arg(&out),
        Duration::from_secs(120),
    );
    assert_exit(&analyzed, 0);

    let low = dir.join("low-bus");
    let sets = [short[0], short[1], "amb.bus_voltage_v=20"];
    assert_exit(&output_within(&mut plant_run(&file, &low, &sets), Duration::from_secs(120)), 0);
    let summary = read_json(&low.join("summary.json"));
    let saturated = summary["voltage_saturation_s"].as_f64().unwrap();
    assert!(saturated > 1e-3 && saturated < 0.08, "{summary:#}");
    let trace = Csv::read(&low.join("trace.csv"));
    let v = trace.column("vy_coil_v");
    assert!(v.iter().all(|v| v.abs() <= 20.0), "a coil voltage beyond the bus");
    assert!(v.iter().any(|v| v.abs() == 20.0), "no sample at the limit");
    // The ideal scene's trace has no coil columns and no saturation figure.
    let ideal = dir.join("ideal");
    let sets = ["scene.duration_s=0.02", "output.plots=false", "shock[0].start_s=0.01"];
    assert_exit(&output_within(&mut plant_run(&scene("paper-10g.toml"), &ideal, &sets), Duration::from_secs(120)), 0);
    let text = std::fs::read_to_string(ideal.join("trace.csv")).unwrap();
    assert!(text.lines().next().unwrap().ends_with(",housing_y_m"));
    assert!(read_json(&ideal.join("summary.json")).get("voltage_saturation_s").is_none());
}

/// A two-plane rotor with amplifiers: plane B's coil columns after plane A's.
#[test]
fn a_two_plane_amplifier_run_has_both_planes_coils() {
    let dir = TempDir::new("hw-two-plane");
    let out = dir.join("run");
    let sets = ["scene.duration_s=0.01", "output.plots=false", "amb.amplifier=true", "amb.b.bus_voltage_v=100"];
    let o =
        output_within(&mut plant_run(&scene("two-plane-asymmetric-10g.toml"), &out, &sets), Duration::from_secs(120));
    assert_exit(&o, 0);
    let text = std::fs::read_to_string(out.join("trace.csv")).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    assert_eq!(header.len(), 37 + 8);
    assert_eq!(
        header[37..],
        [
            "ix_coil_a",
            "iy_coil_a",
            "vx_coil_v",
            "vy_coil_v",
            "b_ix_coil_a",
            "b_iy_coil_a",
            "b_vx_coil_v",
            "b_vy_coil_v"
        ]
    );
}

/// The bad input: each a clear error naming key, value and unit, exit 2.
#[test]
fn bad_amplifier_and_sensor_values_are_refused_naming_key_value_and_unit() {
    let dir = TempDir::new("hw-bad");
    let file = scene("realistic-10g.toml");
    let cases: &[(&[&str], &str)] = &[
        (&["amb.coil_inductance_mh=0"], "amb.coil_inductance_mh = 0 mH"),
        (&["amb.bus_voltage_v=-5"], "amb.bus_voltage_v = -5 V"),
        (&["amb.coil_resistance_ohm=-1"], "amb.coil_resistance_ohm = -1 Ω"),
        (
            &["integrator.method=rk4", "integrator.substeps=1", "amb.current_loop_hz=20000"],
            "amb.current_loop_hz = 20000 Hz",
        ),
        (
            &["integrator.method=rk4", "integrator.substeps=1", "sensor.bandwidth_hz=50000"],
            "sensor.bandwidth_hz = 50000 Hz",
        ),
        (&["integrator.method=symplectic_euler"], "symplectic_euler"),
        (&["sensor.filter_order=3"], "sensor.filter_order = 3"),
        (&["sensor.range_um=-1"], "sensor.range_um = -1 µm"),
        (&["sensor.runout=[{axis = \"x\", order = 0, amplitude_um = 1.0}]"], "sensor.runout[0].order = 0"),
        (
            &["sensor.runout=[{axis = \"y\", order = 1, amplitude_um = 200.0}]"],
            "sensor.runout[0].amplitude_um = 200 µm",
        ),
        (&["sensor.runout=[{axis = \"x_b\", order = 1, amplitude_um = 1.0}]"], "sensor.runout[0].axis"),
        (&["amb.a.coil_inductance_mh=1"], "amb.a"),
    ];
    for (i, (sets, needle)) in cases.iter().enumerate() {
        let mut all = vec!["output.plots=false"];
        all.extend_from_slice(sets);
        let o = output_within(&mut plant_run(&file, &dir.join(&format!("{i}")), &all), Duration::from_secs(60));
        assert_exit(&o, 2);
        let e = stderr(&o);
        assert!(e.contains(needle), "{sets:?}: expected `{needle}` in: {e}");
    }
}
