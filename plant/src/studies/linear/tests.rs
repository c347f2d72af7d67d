//! The linear plant against closed forms derived by hand from the scenes' figures and the
//! two-plane rotor's linearisation (`plant_physics::two_plane::linear`). Against `plant
//! assess`'s closed forms: `assess::linear_check` (assess reads this module, not the reverse).

use super::law::{self, LinearLaw};
use super::{build, Built};
use crate::shipped;
use nalgebra::{Complex, DMatrix, Matrix2};
use std::f64::consts::{SQRT_2, TAU};

type C64 = Complex<f64>;

/// The study's figures as the shipped planar scenes write them (config/paper-10g.toml):
/// m (kg), k_s (N/m), k_i (N/A), A_s (V/m).
const M: f64 = 11.5;
const KS: f64 = 4.32e5;
const KI: f64 = 216.0;
const AS: f64 = 25_000.0;

/// Frequencies (Hz) the responses are compared at: 1 Hz to 9 kHz, log spaced.
pub(crate) fn freqs() -> Vec<f64> {
    (0..120).map(|i| 10f64.powf(i as f64 * 3.95 / 119.0)).collect()
}

pub(crate) fn rel(a: C64, b: C64) -> f64 {
    (a - b).norm() / b.norm()
}

pub(crate) fn model(file: &str, sets: &[&str], speed_hz: f64) -> Built {
    build(&shipped(file, sets), speed_hz).expect("linear model")
}

#[test]
fn the_planar_plant_is_the_hand_derived_one() {
    let b = model("paper-10g.toml", &[], 0.0);
    let s = &b.plant.system;
    assert_eq!((s.a.nrows(), s.b.ncols(), s.c.nrows()), (4, 2, 2));
    // Open loop without amplifier: poles ±√(k_s / m), twice.
    let mut poles: Vec<f64> = s.a.complex_eigenvalues().iter().map(|l| l.re).collect();
    poles.sort_by(f64::total_cmp);
    let p = (KS / M).sqrt();
    for (got, want) in poles.iter().zip([-p, -p, p, p]) {
        assert!((got - want).abs() < 1e-9 * p, "{poles:?} against ±{p}");
    }
    // P(s) = A_s k_i / (m s² − k_s), diagonal; the DC gain −A_s k_i / k_s = −12.5 V/A.
    for f in freqs() {
        let w = C64::new(0.0, TAU * f);
        let r = law::response(s, w);
        let want = C64::new(AS * KI, 0.0) / (w * w * M - KS);
        assert!(rel(r[(0, 0)], want) < 1e-12 && rel(r[(1, 1)], want) < 1e-12, "{f} Hz: {r} against {want}");
        assert!(r[(0, 1)].norm() == 0.0 && r[(1, 0)].norm() == 0.0);
    }
    assert!((law::response(s, C64::new(0.0, 0.0))[(0, 0)].re + 12.5).abs() < 1e-12);
    let names: Vec<&str> = b.plant.inputs.iter().map(|i| i.name.as_str()).collect();
    assert_eq!(names, ["i_ref_x", "i_ref_y"]);
    assert_eq!(b.plant.outputs[1].name, "v_y");
    assert_eq!((b.plant.inputs[0].unit.as_str(), b.plant.outputs[0].unit.as_str()), ("A", "V"));
}

/// realistic-10g: the amplifier's PI loop and coil with its back-EMF, and the second-order
/// sensor filter, in series with the rotor:
/// `X/R = k_i (K_p + K_I/s) / ((m s² − k_s)(L s + K_p + R + K_I/s) + k_b k_i s)`,
/// `V = A_s H(s) X`, `H = ω² / (s² + √2 ω s + ω²)`; `K_p = L ω_c`, `K_I = R ω_c`.
#[test]
fn the_amplifier_and_the_sensor_filter_are_the_hand_derived_ones() {
    let (l, r, wc, kb, wf) = (0.058, 1.0, TAU * 1500.0, 216.0, TAU * 5000.0);
    let (kp, kii) = (l * wc, r * wc);
    let b = model("realistic-10g.toml", &[], 500.0);
    let s = &b.plant.system;
    assert_eq!(s.a.nrows(), 4 + 2 + 2 + 4, "rotor, coil currents, PI integrals, filter (second order)");
    for f in freqs() {
        let w = C64::new(0.0, TAU * f);
        let x = (w.inv() * kii + kp) * KI / ((w * w * M - KS) * (w * l + kp + r + w.inv() * kii) + w * kb * KI);
        let h = C64::new(wf * wf, 0.0) / (w * w + w * (SQRT_2 * wf) + wf * wf);
        let want = x * h * AS;
        let got = law::response(s, w);
        assert!(rel(got[(0, 0)], want) < 1e-10 && rel(got[(1, 1)], want) < 1e-10, "{f} Hz: {got} against {want}");
    }
    // Without a filter of the second order: the first order's H = ω / (s + ω).
    let b = model("realistic-10g.toml", &["sensor.filter_order=1", "amb.back_emf_v_s_per_m=0.0"], 0.0);
    for f in [3.0, 300.0, 3000.0] {
        let w = C64::new(0.0, TAU * f);
        let amp = C64::new(wc, 0.0) / (w + wc);
        let want = amp * KI / (w * w * M - KS) * (C64::new(wf, 0.0) / (w + wf)) * AS;
        let got = law::response(&b.plant.system, w)[(1, 1)];
        assert!(rel(got, want) < 1e-10, "{f} Hz: {got} against {want}");
    }
}

/// The zero-order hold of `m ẍ = k_s x + k_i i` by hand (`a = √(k_s/m)`): `Φ = [[ch, sh/a],
/// [a sh, ch]]`, `Γ = k_i/m [(ch − 1)/a², sh/a]`; the delay line as docs/guide/linear.md says.
#[test]
fn the_discrete_plant_is_the_hand_derived_zero_order_hold_with_its_delay() {
    let t = 1.0 / 20_000.0;
    let a = (KS / M).sqrt();
    let (ch, sh) = ((a * t).cosh(), (a * t).sinh());
    let phi = [[ch, sh / a], [a * sh, ch]];
    let gamma = [KI / M * (ch - 1.0) / (a * a), KI / M * sh / a];
    let close = |got: f64, want: f64| (got - want).abs() <= 1e-12 * want.abs().max(1e-300);
    for delay in [0u32, 1, 3] {
        let b = model("cosim-10g.toml", &[&format!("controller.delay_samples={delay}")], 0.0);
        let (d, states) = &b.discrete;
        let n = 4 + 2 * delay as usize;
        assert_eq!((d.a.nrows(), states.len()), (n, n));
        for axis in 0..2 {
            let (x, v) = (axis, 2 + axis);
            for (i, row) in [x, v].iter().enumerate() {
                for (j, col) in [x, v].iter().enumerate() {
                    assert!(
                        close(d.a[(*row, *col)], phi[i][j]),
                        "Φ[{i}][{j}] = {} against {}",
                        d.a[(*row, *col)],
                        phi[i][j]
                    );
                }
            }
            let g_col =
                |r: usize| if delay == 0 { d.b[(r, axis)] } else { d.a[(r, 4 + 2 * (delay as usize - 1) + axis)] };
            assert!(close(g_col(x), gamma[0]) && close(g_col(v), gamma[1]), "Γ, delay {delay}");
        }
        if delay > 0 {
            assert_eq!(d.b.view((4, 0), (2, 2)).clone_owned(), DMatrix::identity(2, 2));
            assert_eq!(states[4].name, "i_ref_x_delay_1");
            assert_eq!(d.b.rows(0, 4).iter().filter(|v| **v != 0.0).count(), 0, "the plant sees the command late");
        }
        assert_eq!(d.c.columns(4, n - 4).iter().filter(|v| **v != 0.0).count(), 0);
    }
}

/// The diagonal of the exported model's `S` against `want` at every frequency of [`freqs`]
/// below `f_max`: the largest relative difference.
pub(crate) fn worst_difference(b: &Built, law: &LinearLaw, f_max: f64, want: &dyn Fn(f64, usize) -> C64) -> f64 {
    let m = b.plant.inputs.len();
    let mut worst: f64 = 0.0;
    for f in freqs().into_iter().filter(|f| *f < f_max) {
        let s = law::sensitivity(law, &b.plant.system, &b.discrete.0, f);
        for k in 0..m {
            worst = worst.max(rel(s[(k, k)], want(f, k)));
        }
    }
    worst
}

/// The planar scenes' closed form (`assess::closed_form`: continuous PD, and the sampled PD
/// with its delay on the exactly discretised axis) is the exported model's: to 1e-12 for the
/// continuous loop (measured 1e-15), 3e-11 for the sampled (measured 1.3e-11: the closed
/// form's pulse transfer loses that much near `z = 1`, 6e-12 at 1.5 Hz and 5e-12 at 29 Hz
/// against the exact arithmetic, where the exported model's is within 2e-14: next test).
#[test]
fn the_two_plane_linearisation_is_the_exported_model() {
    let scene = shipped("two-plane-asymmetric-10g.toml", &[]);
    let crate::config::Rotor::TwoPlane(machine) = &scene.rotor else { panic!("two-plane scene") };
    let gains = crate::run::plane_gains(&scene).expect("gains");
    let rotor = plant_physics::two_plane::linear::LinearRotor::from_gains(machine, &[gains[0], gains[1]]);
    let law = law::of(&scene).expect("a linear law");
    for speed_hz in [0.0, 300.0] {
        let b = build(&scene, speed_hz).expect("model");
        let omega = TAU * speed_hz;
        let worst = worst_difference(&b, &law, 1e4, &|f, k| {
            let s = C64::new(0.0, TAU * f);
            let i = k / 2;
            let plane = &machine.planes[i];
            let lc = &plane.params.loop_constants;
            let c = -(C64::new(gains[i].kp, 0.0) + s * gains[i].kd) * gains[i].amp_gain_a_per_v;
            let inv = |m: Matrix2<C64>| m.try_inverse().expect("regular");
            let mean = (inv(rotor.dynamic(omega, s)) + inv(rotor.dynamic(-omega, s))) * C64::new(0.5, 0.0);
            let f_vec = nalgebra::Vector2::new(C64::new(1.0, 0.0), C64::new(plane.station, 0.0)) * (c * lc.ki_n_per_a);
            let q = mean * f_vec;
            let u = (q[0] + q[1] * plane.sensor) * lc.sensor_gain_v_per_m;
            C64::new(1.0, 0.0) + u
        });
        eprintln!("two-plane-asymmetric-10g at {speed_hz} Hz: |ΔS|/|S| up to {worst:.1e}");
        assert!(worst < 1e-12, "at {speed_hz} Hz: |ΔS|/|S| up to {worst:e}");
    }
}

/// Bad input: a negative or non-finite speed, named.
#[test]
fn a_bad_speed_is_refused_by_name() {
    let scene = shipped("paper-10g.toml", &[]);
    for v in [-1.0, f64::NAN, f64::INFINITY, 2e5] {
        let e = build(&scene, v).err().expect("refused").to_string();
        assert!(e.contains("--speed-hz") && e.contains("Hz"), "{e}");
    }
}

/// A unipolar drive about its bias is the bipolar one on the differential current with each
/// magnet's half of `k_b` (MODEL.md §12.3; tests/tests/unipolar.rs runs the two to 1e-6 of each
/// other): the unipolar scene at `k_b = 432` is the bipolar one at 216, matrix for matrix.
#[test]
fn a_unipolar_drive_is_the_bipolar_one_with_half_the_back_emf() {
    let common = ["amb.force_law=\"nonlinear\""];
    let bipolar = model("realistic-10g.toml", &[common[0], "amb.back_emf_v_s_per_m=216"], 500.0);
    let unipolar = model(
        "realistic-10g.toml",
        &[common[0], "amb.amplifier_topology=\"unipolar\"", "amb.back_emf_v_s_per_m=432"],
        500.0,
    );
    assert_eq!(unipolar.plant.system, bipolar.plant.system);
    assert!(unipolar.plant.parts.iter().any(|p| p.contains("unipolar")), "{:?}", unipolar.plant.parts);
    let other = model("realistic-10g.toml", &[common[0], "amb.back_emf_v_s_per_m=432"], 500.0);
    assert_ne!(other.plant.system, bipolar.plant.system, "k_b is in the model");
}

/// The linear forms of `transfer_function` and `state_space` (their margins computed, not only
/// measured): without `num`/`den` (`a` … `c`) each law is the design's PD as `pd` samples it
/// (controller/src/transfer_function.rs, state_space.rs), a second reading of the same law by
/// another path (`DiscreteTf`'s coefficients, the state-space system's response), so its
/// sensitivity on the linear plant is `pd`'s: on the planar rotor and on the two-plane one at
/// speed (the state-space law as the full matrix `C(z)` of every axis at once).
#[test]
fn transfer_function_and_state_space_laws_have_the_pds_linear_form() {
    for (file, speed_hz) in [("paper-10g.toml", 0.0), ("two-plane-asymmetric-10g.toml", 300.0)] {
        let scene_of = |law: &str| {
            let l = format!("controller.law=\"{law}\"");
            shipped(file, &["controller.mode=\"sampled\"", &l])
        };
        let pd = scene_of("pd");
        let b = build(&pd, speed_hz).expect("model");
        let reference = law::of(&pd).expect("pd's linear form");
        for name in ["transfer_function", "state_space"] {
            let scene = scene_of(name);
            let form = law::of(&scene).unwrap_or_else(|| panic!("{file}: {name} has no linear form"));
            assert_eq!(form.period(), reference.period());
            let mut worst: f64 = 0.0;
            for f in freqs().into_iter().filter(|f| *f < 9e3) {
                let want = law::sensitivity(&reference, &b.plant.system, &b.discrete.0, f);
                let got = law::sensitivity(&form, &b.plant.system, &b.discrete.0, f);
                for k in 0..want.nrows() {
                    worst = worst.max(rel(got[(k, k)], want[(k, k)]));
                }
                if matches!(form, LinearLaw::StateSpace { .. }) {
                    // The PD per axis: no coupling between the axes' laws.
                    let c = form.matrix_at(f);
                    assert!((0..c.nrows()).all(|i| (0..c.ncols()).all(|j| i == j || c[(i, j)].norm() == 0.0)));
                }
            }
            eprintln!("{file} {name}: |ΔS|/|S| up to {worst:.1e} against pd");
            assert!(worst < 1e-9, "{file} {name}: |ΔS|/|S| up to {worst:e} against pd");
        }
    }
}

/// An unstable controller is allowed and said: a `transfer_function` law `1/(1 − 1.5 z⁻¹)`
/// (its pole at z = 1.5) has one unstable pole per axis; the design's PD none; a `state_space`
/// law with `A_d = diag(1.5, 0.5)`, one.
#[test]
fn a_laws_unstable_poles_are_counted() {
    let tf = shipped(
        "paper-10g.toml",
        &[
            "controller.mode=\"sampled\"",
            "controller.law=\"transfer_function\"",
            "controller.params.num=[1.0, 0.0]",
            "controller.params.den=[1.0, -1.5]",
            "controller.params.domain=\"z\"",
            "controller.params.dt_s=5e-5",
        ],
    );
    assert_eq!(law::of(&tf).expect("linear form").unstable_poles(), 2, "one per axis, x and y");
    let pd = shipped("paper-10g.toml", &["controller.mode=\"sampled\"", "controller.law=\"transfer_function\""]);
    assert_eq!(law::of(&pd).expect("linear form").unstable_poles(), 0);
    let ss = shipped(
        "paper-10g.toml",
        &[
            "controller.mode=\"sampled\"",
            "controller.law=\"state_space\"",
            "controller.params.a=[[1.5, 0.0], [0.0, 0.5]]",
            "controller.params.b=[[1.0, 0.0], [0.0, 1.0]]",
            "controller.params.c=[[-1.0, 0.0], [0.0, -1.0]]",
            "controller.params.domain=\"z\"",
            "controller.params.dt_s=5e-5",
        ],
    );
    assert_eq!(law::of(&ss).expect("linear form").unstable_poles(), 1);
}

/// The closed loop's state matrix of a one-state plant with a feedthrough and a one-state law,
/// worked by hand: `v = 2x + 0.5 i`, `i = −0.3 x_k − 0.2 v` give `i = (−0.4 x − 0.3 x_k)/1.1`;
/// `x⁺ = 1.1 x + i`, `x_k⁺ = 0.5 x_k + v = 0.5 x_k + 2 x + 0.5 i`. Sizes that disagree: `None`.
#[test]
fn a_state_space_law_closes_the_loop_as_worked_by_hand() {
    let m = |r: usize, c: usize, v: &[f64]| DMatrix::from_row_slice(r, c, v);
    let plant = super::model::System { a: m(1, 1, &[1.1]), b: m(1, 1, &[1.0]), c: m(1, 1, &[2.0]), d: m(1, 1, &[0.5]) };
    let law_sys =
        super::model::System { a: m(1, 1, &[0.5]), b: m(1, 1, &[1.0]), c: m(1, 1, &[-0.3]), d: m(1, 1, &[-0.2]) };
    let a = law::closed_loop(&plant, &law_sys).expect("a loop");
    let (ix, ik) = (-0.4 / 1.1, -0.3 / 1.1);
    let want = m(2, 2, &[1.1 + ix, ik, 2.0 + 0.5 * ix, 0.5 + 0.5 * ik]);
    assert!((&a - &want).abs().max() < 1e-15, "{a} against {want}");
    let two_axes = super::model::System {
        a: m(1, 1, &[0.5]),
        b: m(1, 2, &[1.0, 0.0]),
        c: m(2, 1, &[1.0, 0.0]),
        d: DMatrix::zeros(2, 2),
    };
    assert!(law::closed_loop(&plant, &two_axes).is_none());
}
