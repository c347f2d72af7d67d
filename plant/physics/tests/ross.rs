//! The flexible rotor against ROSS itself (docs/results/flexible-rotor.md): for ROSS's own
//! example rotor and an AMB machine rotor, both saved by ROSS's `Rotor.save()`, the natural
//! frequencies (`run_modal`) and the Campbell diagram (`run_campbell`, forward and backward,
//! the first six modes, 0 to 500 Hz) that ROSS 3.1.0 and ROSS 2.3.0 computed
//! (`scripts/ross/fixture.sh` committed them under `tests/fixtures/ross/`, 2.3's in `v2.3/`)
//! against this crate's from each version's file, within 0.5 %; the reduced model against the full one within 0.1 % below the cutoff; a very
//! stiff shaft against the rigid two-plane rotor.

use nalgebra::DVector;
use plant_physics::flex::modes::{Linear, Whirl};
use plant_physics::flex::reduce::{Kind, Reduced, Reduction};
use plant_physics::flex::ross::{AtAmbs, BearingUse};
use plant_physics::flex::{ross, FlexError, LinearBearing, Rotor};
use plant_physics::two_plane::linear::{LinearRotor, PlaneLoop};
use serde_json::Value;
use std::f64::consts::TAU;
use std::path::PathBuf;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/ross").join(name)
}

/// ROSS 2.3.0's file and figures of the same rotor.
const V23: &str = "v2.3/";

fn load(name: &str) -> (Rotor, Value) {
    let rotor = ross::read(&fixture(&format!("{name}.toml"))).expect("the ROSS file reads");
    let text = std::fs::read_to_string(fixture(&format!("{name}.json"))).expect("ROSS's figures");
    (rotor, serde_json::from_str(&text).expect("JSON"))
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().expect("array").iter().map(|x| x.as_f64().expect("number")).collect()
}

fn whirls(v: &Value) -> Vec<Option<Whirl>> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| match x.as_str() {
            Some("forward") => Some(Whirl::Forward),
            Some("backward") => Some(Whirl::Backward),
            Some("mixed") => Some(Whirl::Mixed),
            _ => None,
        })
        .collect()
}

/// The largest relative error of ours against ROSS over `run_modal` at every speed (lateral
/// modes, in ascending order, one for one) and `run_campbell` (each of ROSS's six curves
/// against our nearest mode at that speed); whirl senses agree where ROSS finds one.
fn compare_with_ross(name: &str) -> f64 {
    let (rotor, ross) = load(name);
    let (mass, ross_mass) = (rotor.mass(), ross["mass_kg"].as_f64().unwrap());
    assert!((mass - ross_mass).abs() < 1e-9 * ross_mass, "{name}: mass {mass} against ROSS's {ross_mass}");
    let full = Linear::full(&rotor.matrices()).prepare().unwrap();
    let mut worst: f64 = 0.0;
    // Ours once per speed (the modal and Campbell speeds are the same).
    let mut ours_at: Vec<(f64, Vec<plant_physics::flex::Mode>)> = Vec::new();
    let mut at = |speed: f64| -> Vec<plant_physics::flex::Mode> {
        if let Some((_, m)) = ours_at.iter().find(|(w, _)| *w == speed) {
            return m.clone();
        }
        let m = full.modes(speed, 10).unwrap();
        ours_at.push((speed, m.clone()));
        m
    };
    for entry in ross["modal"].as_array().unwrap() {
        let speed = entry["speed_rad_s"].as_f64().unwrap();
        let (wd, whirl) = (floats(&entry["wd_rad_s"]), whirls(&entry["whirl"]));
        // ROSS's list holds its axial and torsional modes too (no whirl): ours has none.
        let lateral: Vec<(f64, Option<Whirl>)> =
            wd.iter().zip(&whirl).filter(|(_, w)| w.is_some()).map(|(f, w)| (*f, *w)).collect();
        let ours = at(speed);
        assert!(ours.len() >= lateral.len(), "{name} at {speed} rad/s");
        let table = speed == 0.0 || entry == ross["modal"].as_array().unwrap().last().unwrap();
        if table {
            eprintln!(
                "{name} at {:.0} Hz: | mode | ROSS (Hz) | ours (Hz) | difference | whirl (ROSS / ours) |",
                speed / TAU
            );
        }
        for (k, (mode, (f, w))) in ours.iter().zip(&lateral).enumerate() {
            let err = (mode.wd - f).abs() / f;
            if table {
                eprintln!(
                    "| {} | {:.4} | {:.4} | {:.1e} % | {:?} / {:?} |",
                    k + 1,
                    f / TAU,
                    mode.wd / TAU,
                    100.0 * (mode.wd - f) / f,
                    w.unwrap(),
                    mode.whirl
                );
            }
            worst = worst.max(err);
            assert!(
                err < 5e-3,
                "{name} at {speed} rad/s: ours {} against ROSS's {f} rad/s ({:.3} %)",
                mode.wd,
                100.0 * err
            );
            if speed > 0.0 && matches!(w, Some(Whirl::Forward | Whirl::Backward)) {
                assert_eq!(Some(mode.whirl), *w, "{name} at {speed} rad/s, {f} rad/s: whirl");
            }
        }
    }
    let campbell = &ross["campbell"];
    let speeds = floats(&campbell["speeds_rad_s"]);
    for (i, &speed) in speeds.iter().enumerate() {
        let ours = at(speed);
        let (wd, whirl) = (floats(&campbell["wd_rad_s"][i]), whirls(&campbell["whirl"][i]));
        for (f, w) in wd.iter().zip(&whirl) {
            if w.is_none() {
                continue; // an axial or torsional mode
            }
            let nearest = ours.iter().min_by(|a, b| (a.wd - f).abs().total_cmp(&(b.wd - f).abs())).unwrap();
            let err = (nearest.wd - f).abs() / f;
            worst = worst.max(err);
            assert!(
                err < 5e-3,
                "{name} Campbell at {speed} rad/s: ours {} against ROSS's {f} ({:.3} %)",
                nearest.wd,
                100.0 * err
            );
            if speed > 0.0 && matches!(w, Some(Whirl::Forward | Whirl::Backward)) {
                assert_eq!(Some(nearest.whirl), *w, "{name} Campbell at {speed} rad/s, {f} rad/s: whirl");
            }
        }
    }
    eprintln!("{name}: largest difference against ROSS {:.2e} (relative)", worst);
    worst
}

#[test]
fn ross_example_rotor_matches_ross_modal_and_campbell() {
    compare_with_ross("rotor_example");
}

#[test]
fn amb_machine_rotor_matches_ross_modal_and_campbell() {
    compare_with_ross("amb_machine");
}

/// ROSS 2.3.0's files (saved by the same script on Python 3.11) against ROSS 2.3.0's own
/// figures: the same check, each version's file read by the same reader.
#[test]
fn ross_2_3_files_match_ross_2_3_modal_and_campbell() {
    for name in ["rotor_example", "amb_machine"] {
        let (_, ross) = load(&format!("{V23}{name}"));
        assert_eq!(ross["ross_version"], "2.3.0", "{name}: the fixture is ROSS 2.3's");
        let text = std::fs::read_to_string(fixture(&format!("{V23}{name}.toml"))).unwrap();
        assert!(text.contains("ross_version = \"2.3.0\""), "{name}: the file is ROSS 2.3's");
        compare_with_ross(&format!("{V23}{name}"));
    }
}

/// The reduced model's whirl modes against the full model's over the Campbell speeds (0 to
/// 500 Hz): each reduced mode below the cutoff against the nearest full-model mode, and each
/// full-model mode below half the cutoff against the nearest reduced mode (a mode above the
/// cutoff at rest is not in the reduced model even where its backward branch falls below it).
/// The largest relative difference, and how many modes were compared at most.
fn reduction_error(rotor: &Rotor, spec: &Reduction, speeds_hz: &[f64]) -> (f64, usize) {
    let reduced = Reduced::new(rotor, spec).unwrap();
    let full = Linear::full(&rotor.matrices()).prepare().unwrap();
    let small = reduced.linear().prepare().unwrap();
    let cutoff = TAU * spec.cutoff_hz;
    let mut worst: f64 = 0.0;
    let mut compared = 0;
    for &hz in speeds_hz {
        let speed = TAU * hz;
        let of_full = full.modes(speed, 12).unwrap();
        let of_small = small.modes(speed, 12).unwrap();
        let nearest = |set: &[plant_physics::flex::Mode], f: f64| {
            set.iter().min_by(|a, b| (a.wd - f).abs().total_cmp(&(b.wd - f).abs())).cloned().unwrap()
        };
        let below: Vec<_> = of_small.iter().filter(|m| m.wd < cutoff).collect();
        for a in &below {
            // Of the same whirl where both have one (a forward and a backward mode may cross).
            let same: Vec<_> = of_full
                .iter()
                .filter(|b| hz == 0.0 || a.whirl == Whirl::Mixed || b.whirl == Whirl::Mixed || b.whirl == a.whirl)
                .cloned()
                .collect();
            let b = nearest(&same, a.wd);
            worst = worst.max((a.wd - b.wd).abs() / b.wd);
            // At rest the whirl is undefined (each mode a line, or a degenerate pair).
            if hz > 0.0 && a.whirl != Whirl::Mixed && b.whirl != Whirl::Mixed {
                assert_eq!(a.whirl, b.whirl, "at {hz} Hz, {} rad/s", b.wd);
            }
        }
        for b in of_full.iter().filter(|m| m.wd < 0.5 * cutoff) {
            let a = nearest(&of_small, b.wd);
            worst = worst.max((a.wd - b.wd).abs() / b.wd);
        }
        compared = compared.max(below.len());
    }
    (worst, compared)
}

/// The reduction's error: every whirl frequency below the cutoff within 0.1 % of the full
/// model's, with the static correction at the bearing nodes and the gyroscopic correction.
/// The AMB machine (cutoff 1500 Hz, 8 modes below it) at every speed from 0 to 500 Hz; ROSS's
/// example rotor (cutoff 150 Hz, 6 modes) from 0 to 400 Hz: at 500 Hz (3 times the speed of its
/// highest retained mode) the heavy disks' gyroscopic coupling to the modes above the cutoff
/// puts a retained backward mode 1.1 % off, which the second half of the test states.
#[test]
fn reduced_model_matches_the_full_model_below_the_cutoff() {
    let hz = [0.0, 100.0, 200.0, 300.0, 400.0, 500.0];
    for (name, cutoff_hz, force_nodes, speeds) in
        [("amb_machine", 1500.0, vec![2, 14], &hz[..]), ("rotor_example", 150.0, vec![0, 6], &hz[..5])]
    {
        let (rotor, _) = load(name);
        let spec = Reduction {
            cutoff_hz,
            force_nodes,
            static_correction: true,
            gyroscopic_correction: true,
            modal_damping: 0.0,
        };
        let (worst, compared) = reduction_error(&rotor, &spec, speeds);
        eprintln!("{name}: cutoff {cutoff_hz} Hz, {compared} modes below it, largest difference {worst:.2e}");
        assert!(compared >= 4, "{name}: {compared} modes below the cutoff");
        assert!(worst < 1e-3, "{name}: reduced against full {:.4} %", 100.0 * worst);
    }
    // The limit stated above, and what the gyroscopic correction buys.
    let (rotor, _) = load("rotor_example");
    let mut spec = Reduction {
        cutoff_hz: 150.0,
        force_nodes: vec![0, 6],
        static_correction: true,
        gyroscopic_correction: true,
        modal_damping: 0.0,
    };
    let (at_500, _) = reduction_error(&rotor, &spec, &[500.0]);
    spec.gyroscopic_correction = false;
    let (without, _) = reduction_error(&rotor, &spec, &hz[..5]);
    eprintln!("rotor_example: at 500 Hz {at_500:.2e}; without the gyroscopic correction, 0 to 400 Hz: {without:.2e}");
    assert!(at_500 > 1e-3 && at_500 < 0.02, "{at_500}");
    assert!(without > 1e-3, "{without}");
}

/// The static correction: with it, the reduced rotor's static deflection under a force at a
/// force node is the full model's (to round-off); without it, the retained modes alone miss
/// part of it.
#[test]
fn static_correction_restores_the_static_deflection_at_the_force_nodes() {
    let (rotor, _) = load("amb_machine");
    let full_k = rotor.matrices().stiffness;
    let force_nodes = vec![2, 14, 8];
    for corrected in [true, false] {
        let spec = Reduction {
            cutoff_hz: 1500.0,
            force_nodes: force_nodes.clone(),
            static_correction: corrected,
            gyroscopic_correction: false,
            modal_damping: 0.0,
        };
        let reduced = Reduced::new(&rotor, &spec).unwrap();
        assert_eq!(reduced.kinds.contains(&Kind::Correction), corrected);
        // Unit force along x at the mid-span node (8): the static state from the derivative's
        // zero, Λ η = Φ_jᵀ f (no rigid modes: the rotor sits on its bearings).
        let forces = [[0.0, 0.0], [0.0, 0.0], [1.0, 0.0]];
        let r = reduced.size();
        let mut dstate = vec![0.0; 2 * r];
        reduced.derivative(&vec![0.0; 2 * r], 0.0, &forces, [0.0, 0.0], &mut dstate);
        let mut state = vec![0.0; 2 * r];
        for k in 0..r {
            state[k] = dstate[r + k] / reduced.omega_sq[k];
        }
        let mut f = DVector::zeros(rotor.dof());
        f[4 * 8] = 1.0;
        let exact = full_k.clone().lu().solve(&f).unwrap();
        for node in force_nodes.iter().copied() {
            let ours = reduced.displacement(&state, node)[0];
            let err = (ours - exact[4 * node]).abs() / exact[4 * 8].abs();
            if corrected {
                assert!(err < 1e-9, "node {node}: {ours} against {}", exact[4 * node]);
            } else if node == 8 {
                assert!(err > 1e-6, "without the correction the modes alone are exact? {err}");
            }
        }
    }
}

/// A very stiff shaft: the reduced flexible rotor's four lowest whirl frequencies (the
/// rigid-body modes on the two bearings) against the rigid two-plane rotor's
/// (`two_plane::linear`, the same mass, centre, I_t and I_p, the same springs and dampers at
/// the same stations), from 0 to 500 Hz: they converge as the shaft stiffens.
#[test]
fn stiff_shaft_converges_to_the_rigid_two_plane_rotor() {
    let (mut rotor, _) = load("amb_machine");
    let mut errors = Vec::new();
    for factor in [1e2, 1e4] {
        for el in &mut rotor.elements {
            el.material.modulus = 211e9 * factor;
            el.material.shear_modulus = 81.2e9 * factor;
        }
        let body = rotor.rigid_body();
        eprintln!("the AMB machine as a rigid body: {body:?}");
        let z = rotor.node_positions();
        let plane = |b: &LinearBearing| PlaneLoop {
            station: z[b.node] - body.centre,
            sensor: z[b.node] - body.centre,
            stiffness: b.stiffness[0][0],
            damping: b.damping[0][0],
            negative_stiffness: 0.0,
        };
        let rigid = LinearRotor {
            mass: body.mass,
            transverse_inertia: body.transverse_inertia,
            polar_inertia: body.polar_inertia,
            planes: [plane(&rotor.bearings[0]), plane(&rotor.bearings[1])],
        };
        let spec = Reduction {
            cutoff_hz: 1000.0,
            force_nodes: vec![2, 14],
            static_correction: true,
            gyroscopic_correction: true,
            modal_damping: 0.0,
        };
        let reduced = Reduced::new(&rotor, &spec).unwrap().linear().prepare().unwrap();
        let mut worst: f64 = 0.0;
        for hz in [0.0, 250.0, 500.0] {
            let speed = TAU * hz;
            let mut theirs: Vec<(f64, Whirl)> = rigid
                .modes(speed)
                .unwrap()
                .iter()
                .map(|m| {
                    let w = match m.whirl {
                        plant_physics::two_plane::linear::Whirl::Forward => Whirl::Forward,
                        plant_physics::two_plane::linear::Whirl::Backward => Whirl::Backward,
                    };
                    (m.eigenvalue.im.abs(), w)
                })
                .collect();
            theirs.sort_by(|a, b| a.0.total_cmp(&b.0));
            let ours = reduced.modes(speed, 4).unwrap();
            for (a, (f, w)) in ours.iter().zip(&theirs) {
                worst = worst.max((a.wd - f).abs() / f);
                if hz > 0.0 {
                    assert_eq!(a.whirl, *w, "at {hz} Hz, {f} rad/s");
                }
            }
        }
        eprintln!("shaft {factor:e} times stiffer: rigid-body modes within {worst:.2e} of the two-plane rotor's");
        errors.push(worst);
    }
    assert!(errors[1] < errors[0], "no convergence: {errors:?}");
    assert!(errors[1] < 1e-4, "{errors:?}");
}

/// Bad ROSS files: each refused naming the element, key and value.
#[test]
fn bad_ross_files_are_refused_naming_the_element() {
    let text = std::fs::read_to_string(fixture("rotor_example.toml")).unwrap();
    let cases: Vec<(String, &str)> = vec![
        (text.replace("ross_version = \"3.1.0\"", "ross_version = \"4.0.0\""), "ross_version = \"4.0.0\""),
        (text.replace("ross_version = \"3.1.0\"", "ross_version = \"1.5.0\""), "files of ROSS 2.x and 3.x"),
        // What a version adds that this reader does not know: refused by element and key.
        (
            text.replacen("shear_method_calc = \"cowper\"", "shear_method_calc = \"cowper\"\nfoo = 3", 1),
            "element \"ShaftElement_Shaft Element 0\": key \"foo\" = 3 is not one this reader knows",
        ),
        (text.replacen("beta = 0.0\n", "beta = 0.0\nnew_damping = 1.0\n", 1), "[parameters]: key \"new_damping\""),
        (text.replacen("Ip = ", "offset = 0.1\nIp = ", 1), "key \"offset\" = 0.1"),
        (text.replacen("rho = 7810.0", "rho = 7810.0\nyield = 1e9", 1), ".material: key \"yield\""),
        (text.replacen("kxx = [ 1000000.0,]", "kxx = [ 1000000.0,]\nkzx = [ 1.0,]", 1), "key \"kzx\" = [1.0]"),
        (text.replacen("L = 0.25", "L = -0.25", 1), "L = -0.25 m must be positive"),
        (text.replacen("odl = 0.05", "odl = 0.0", 1), "odl = 0 m must be positive"),
        (text.replacen("rho = 7810.0", "", 1), "rho (density, kg/m³) is missing"),
        (text.replacen("E = 211000000000.0", "", 1), "needs E (modulus, Pa)"),
        (text.replacen("n = 4\nm =", "n = 40\nm =", 1), "node 40 is out of range"),
        (
            text.replacen("kxx = [ 1000000.0,]", "kxx = [ 1000000.0, 2000000.0,]", 1),
            "(node 0): kxx = [1000000.0, 2000000.0] N/m varies with frequency",
        ),
        // A coefficient that is not a number: named as such, not as one that varies.
        (
            text.replacen("kxx = [ 1000000.0,]", "kxx = [ nan,]", 1),
            "(node 0): kxx = [nan] N/m: NaN is not a finite coefficient",
        ),
        (
            text.replacen("kxx = [ 1000000.0,]", "kxx = [ inf, inf,]", 1),
            "kxx = [inf, inf] N/m: inf is not a finite coefficient",
        ),
        (
            text.replacen("kxx = [ 1000000.0,]", "kxx = [ 1000000.0, 2000000.0,]\nfrequency = [ 0.0, 100.0,]", 1),
            "(node 0): frequency = [0.0, 100.0]: its coefficients vary with frequency",
        ),
        // ROSS's AMB element (a BearingElement table with its parameters) with some missing.
        (
            text.replacen("kxx = [ 1000000.0,]", "kxx = [ 1000000.0,]\ng0 = 0.001\ni0 = 1.0", 1),
            "element \"BearingElement_Bearing 0\": ag (m²) is missing",
        ),
        (
            text.clone() + "\n[\"PointMass_0\"]\nn = 1\nm = 2.0\n",
            "\"PointMass_0\" is a PointMass, which this model cannot represent",
        ),
        (text.replacen("n = 5\naxial_force = 0", "n = 4\naxial_force = 0", 1), "a layered shaft"),
    ];
    for (bad, expect) in cases {
        let err = ross::parse(&bad, "bad.toml").expect_err(expect).to_string();
        assert!(err.contains(expect), "{err}\nshould contain: {expect}");
    }
}

/// A cutoff that leaves out rigid-body modes, and a force node beyond the shaft.
#[test]
fn cutoff_below_the_rigid_body_modes_and_nodes_out_of_range_are_refused() {
    let (rotor, _) = load("rotor_example");
    let spec = Reduction {
        cutoff_hz: 10.0,
        force_nodes: vec![0, 6],
        static_correction: true,
        gyroscopic_correction: true,
        modal_damping: 0.0,
    };
    let err = Reduced::new(&rotor, &spec).unwrap_err();
    assert!(matches!(err, FlexError::CutoffBelowRigidModes { .. }), "{err}");
    assert!(err.to_string().contains("cutoff_hz = 10 Hz is below the rigid-body modes"), "{err}");
    let spec = Reduction {
        cutoff_hz: 100.0,
        force_nodes: vec![0, 7],
        static_correction: true,
        gyroscopic_correction: true,
        modal_damping: 0.0,
    };
    let err = Reduced::new(&rotor, &spec).unwrap_err().to_string();
    assert!(err.contains("node 7 is out of range (the shaft has nodes 0 to 6)"), "{err}");
}

/// The file's plain bearings and the scene's AMBs (issue 38 item 4): the AMB machine's file
/// models each AMB as a 1e6 N/m spring at nodes 2 and 14. With AMBs there and no choice, the
/// file is refused naming both bearings (element, node, stiffness) and the choices; "ignore"
/// drops them, "parallel" keeps them; with the AMBs elsewhere they are added.
#[test]
fn the_files_bearings_at_the_amb_nodes_need_a_choice() {
    let text = std::fs::read_to_string(fixture("amb_machine.toml")).unwrap();
    let file = ross::parse_file(&text, "amb_machine.toml").unwrap();
    assert_eq!(file.version, "3.1.0");
    assert!(file.rotor.bearings.is_empty(), "the bearings are apart");
    assert_eq!(file.bearings.len(), 2);
    let err = file.bearings_with_ambs([2, 14], None).unwrap_err();
    for part in [
        "\"BearingElement_AMB A\" at node 2 (k_xx = 1e6 N/m, k_yy = 1e6 N/m)",
        "\"BearingElement_AMB B\" at node 14 (k_xx = 1e6 N/m, k_yy = 1e6 N/m)",
        "rotor.ross_bearings = \"ignore\"",
        "\"parallel\"",
    ] {
        assert!(err.contains(part), "{err}\nshould contain: {part}");
    }
    let (ignored, used) = file.bearings_with_ambs([2, 14], Some(AtAmbs::Ignore)).unwrap();
    assert!(ignored.bearings.is_empty());
    assert!(used.iter().all(|u| u.used == BearingUse::Ignored), "{used:?}");
    let (parallel, used) = file.bearings_with_ambs([2, 14], Some(AtAmbs::Parallel)).unwrap();
    assert_eq!(parallel.bearings.iter().map(|b| b.node).collect::<Vec<_>>(), [2, 14]);
    assert_eq!(parallel.bearings[0].stiffness, [[1e6, 0.0], [0.0, 1e6]]);
    assert_eq!(parallel.bearings[0].damping, [[68.0, 0.0], [0.0, 68.0]]);
    assert!(used.iter().all(|u| u.used == BearingUse::Parallel), "{used:?}");
    // One AMB at a bearing's node, the other elsewhere: that one needs the choice, the other
    // bearing is added whatever the choice.
    let err = file.bearings_with_ambs([2, 13], None).unwrap_err();
    assert!(err.contains("AMB A") && !err.contains("AMB B"), "{err}");
    let (rotor, used) = file.bearings_with_ambs([2, 13], Some(AtAmbs::Ignore)).unwrap();
    assert_eq!(rotor.bearings.iter().map(|b| b.node).collect::<Vec<_>>(), [14]);
    assert_eq!(used.iter().map(|u| u.used).collect::<Vec<_>>(), [BearingUse::Ignored, BearingUse::Added]);
    // The AMBs elsewhere: both bearings are supports, added with no choice asked.
    let (rotor, used) = file.bearings_with_ambs([3, 13], None).unwrap();
    assert_eq!(rotor.bearings.len(), 2);
    assert!(used.iter().all(|u| u.used == BearingUse::Added), "{used:?}");
    // What `parse` (every bearing kept, as ROSS has the rotor) reads is the "parallel" rotor.
    assert_eq!(ross::parse(&text, "amb_machine.toml").unwrap(), parallel);
}

/// ROSS's MagneticBearingElement (issue 38 item 1, not yet the plane's AMB; MODEL.md §13.8): its
/// parameters read and checked, and its constants by ROSS's formulas against the equivalent
/// coefficients ROSS itself wrote into the file (`kxx`, `cxx` over `frequency`, from `k_i`,
/// `k_s`, the gains and the PID with its derivative filter), for ROSS 3.1 and 2.3; the element
/// is refused naming it with what it stands for; bad parameters are refused naming the element,
/// key, value and unit.
#[test]
fn ross_magnetic_bearing_element_is_read_by_rosss_formulas_and_refused_with_its_constants() {
    use plant_physics::flex::ross_amb::magnetic;
    for dir in ["", V23] {
        let text = std::fs::read_to_string(fixture(&format!("{dir}amb_element.toml"))).unwrap();
        let table: toml::Table = text.parse().unwrap();
        let el = table["BearingElement_AMB"].as_table().unwrap();
        let amb = magnetic(el, "BearingElement_AMB", "element", "amb_element.toml").unwrap();
        assert_eq!((amb.node, amb.sensor_node), (1, 1), "{dir}");
        // The closed forms by hand: μ₀ nw² ag i0 cos(22.5°) / g0² and / g0³.
        // The file's alpha, ROSS's decimals (not π/8 exactly).
        let alpha = el["alpha"].as_float().unwrap();
        assert_eq!(alpha.to_string(), "0.39269908");
        let k = 4e-7 * std::f64::consts::PI * 200.0 * 200.0 * 1e-4 * alpha.cos();
        assert!((amb.ki_n_per_a() - k / 1e-6).abs() < 1e-12 * k / 1e-6, "{}", amb.ki_n_per_a());
        assert!((amb.ks_n_per_m() - k / 1e-9).abs() < 1e-12 * k / 1e-9, "{}", amb.ks_n_per_m());
        // ROSS's own equivalent coefficients, at each of its 50 frequencies.
        let list = |key: &str| floats(&serde_json::to_value(&el[key]).unwrap());
        let (w, kxx, cxx) = (list("frequency"), list("kxx"), list("cxx"));
        assert_eq!(w.len(), 50);
        let c_scale = cxx.iter().fold(0.0_f64, |m, c| m.max(c.abs()));
        for i in 0..w.len() {
            let (k_eq, c_eq) = amb.equivalent_at(w[i]);
            assert!(
                (k_eq - kxx[i]).abs() < 1e-9 * kxx[i].abs(),
                "{dir} at {} rad/s: k {k_eq} against ROSS's {}",
                w[i],
                kxx[i]
            );
            assert!(
                (c_eq - cxx[i]).abs() < 1e-9 * c_scale,
                "{dir} at {} rad/s: c {c_eq} against ROSS's {}",
                w[i],
                cxx[i]
            );
            // Isotropic: ROSS's rotation of the axes changes nothing in them (to its round-off).
            let (kyy, kxy) = (list("kyy")[i], list("kxy")[i]);
            assert!((kyy - kxx[i]).abs() < 1e-12 * kxx[i].abs() && kxy.abs() < 1e-12 * kxx[i].abs(), "{kyy} {kxy}");
        }
        // The file is refused naming the element and what it stands for.
        let err = ross::parse(&text, "amb_element.toml").unwrap_err().to_string();
        for part in [
            "element \"BearingElement_AMB\" (node 1) is ROSS's MagneticBearingElement",
            "k_i = 4.643925e0 N/A",
            "k_s = 4.643925e3 N/m",
            "sensor at node 1",
            "amplifier gain 1.5 A/V and sensor gain 2000 V/m",
            "kp = 2, ki = 30 1/s, kd = 0.003 s",
            "n_f = 5000 rad/s",
            "axes turned by 45.0°",
        ] {
            assert!(err.contains(part), "{dir}: {err}\nshould contain: {part}");
        }
    }
    // Bad parameters, each named with its element, key, value and unit.
    let text = std::fs::read_to_string(fixture("amb_element.toml")).unwrap();
    let cases = [
        ("g0 = 0.001", "g0 = 0.0", "element \"BearingElement_AMB\": g0 = 0 m must be positive"),
        ("i0 = 1.0", "i0 = -1.0", "i0 = -1 A must be positive"),
        ("ag = 0.0001", "ag = 0", "ag = 0 m² must be positive"),
        ("nw = 200", "nw = 0", "nw = 0 turns must be positive"),
        ("alpha = 0.39269908", "alpha = 1.6", "alpha = 1.6 rad (91.7°): the pole angle must be between 0 and 90°"),
        ("alpha = 0.39269908", "alpha = 0.0", "alpha = 0 rad"),
        ("sensor_node = 1", "sensor_node = 9", "element \"BearingElement_AMB\" sensor_node: node 9 is out of range"),
        ("kp_pid = 2.0", "kp_pid = \"high\"", "kp_pid = \"high\" is not a number"),
        ("i0 = 1.0", "i0 = [ 1.0, 2.0,]", "i0 = [1.0, 2.0] A: one value per axis, which differ"),
    ];
    for (from, to, expect) in cases {
        assert!(text.contains(from), "{from}");
        let err = ross::parse(&text.replacen(from, to, 1), "amb_element.toml").unwrap_err().to_string();
        assert!(err.contains(expect), "{to}: {err}\nshould contain: {expect}");
    }
}

/// Issue 38 item 6: ROSS's UFU AMB rig and the AMB machine with ROSS `MagneticBearingElement`s
/// (`scripts/ross/amb_compare.py`, ROSS 3.1.0, committed `amb_compare.json` and the two files):
/// each element read from the file, its equivalent stiffness and damping at ROSS's evaluation
/// whirl frequency by the reader's constants (`MagneticBearing::equivalent_at`) put at its node
/// as a linear bearing, and the natural frequencies at rest and at speed against ROSS's
/// `run_modal(speed, frequency = f_eval)`, one for one, within 0.5 %.
#[test]
fn amb_machines_natural_frequencies_match_rosss_run_modal() {
    let text = std::fs::read_to_string(fixture("amb_compare.json")).expect("ROSS's figures");
    let ross: Value = serde_json::from_str(&text).expect("JSON");
    let f_eval = ross["f_eval_rad_s"].as_f64().unwrap();
    for (name, machine) in ross["machines"].as_object().expect("machines") {
        let path = fixture(machine["rotor_file"].as_str().unwrap());
        let file = ross::parse_file_with_ambs(&std::fs::read_to_string(&path).unwrap(), name).expect("the file reads");
        assert!(file.bearings.is_empty(), "{name}: plain bearings {:?}", file.bearings.len());
        assert_eq!(file.magnetics.len(), 2, "{name}");
        let mut rotor = file.rotor.clone();
        for m in &file.magnetics {
            let (k, c) = m.equivalent_at(f_eval);
            let (rk, rc) = (machine["kxx_at_f_eval"].as_f64().unwrap(), machine["cxx_at_f_eval"].as_f64().unwrap());
            assert!((k - rk).abs() <= 1e-9 * rk.abs().max(1.0), "{name}: k_eq {k} against ROSS's {rk}");
            assert!((c - rc).abs() <= 1e-9 * rc.abs().max(1.0), "{name}: c_eq {c} against ROSS's {rc}");
            rotor.bearings.push(LinearBearing {
                node: m.node,
                stiffness: [[k, 0.0], [0.0, k]],
                damping: [[c, 0.0], [0.0, c]],
                mass: [[0.0; 2]; 2],
            });
        }
        let mass = machine["mass_kg"].as_f64().unwrap();
        assert!((rotor.mass() - mass).abs() < 1e-9 * mass, "{name}: mass {} against ROSS's {mass}", rotor.mass());
        let full = Linear::full(&rotor.matrices()).prepare().unwrap();
        for entry in machine["modal"].as_array().unwrap() {
            let speed = entry["speed_rad_s"].as_f64().unwrap();
            let (wd, whirl) = (floats(&entry["wd_rad_s"]), whirls(&entry["whirl"]));
            let lateral: Vec<f64> = wd.iter().zip(&whirl).filter(|(_, w)| w.is_some()).map(|(f, _)| *f).collect();
            let ours = full.modes(speed, lateral.len() + 2).unwrap();
            eprintln!("{name} at {:.0} Hz: | mode | ROSS (Hz) | ours (Hz) | difference |", speed / TAU);
            for (k, (mode, f)) in ours.iter().zip(&lateral).enumerate() {
                let err = (mode.wd - f) / f;
                eprintln!("| {} | {:.4} | {:.4} | {:.1e} % |", k + 1, f / TAU, mode.wd / TAU, 100.0 * err);
                assert!(
                    err.abs() < 5e-3,
                    "{name} at {speed} rad/s, mode {}: ours {} against ROSS's {f} rad/s",
                    k + 1,
                    mode.wd
                );
            }
        }
    }
}
