use super::*;
use crate::design::Design;
use crate::law::{AnyLaw, Sample};

fn planar() -> RotorDesign {
    RotorDesign::Planar(Design::study())
}

fn build_with(design: &RotorDesign, text: &str) -> Result<Box<dyn RotorLaw>, LawError> {
    (LAW.build)(design, &Params::parse(text).unwrap())
}

fn system(design: &RotorDesign, text: &str) -> DiscreteSs {
    let params = Params::parse(text).unwrap();
    let mut p = params.reader(LAW.name);
    read(&mut p, design).unwrap()
}

/// A first-order lag on x (`ẋ = −x/τ + u_x`, `i_x = c x + d u_x`), y untouched, discretised by
/// hand: zero-order hold `A_d = e^{−T/τ}`, `B_d = τ (1 − e^{−T/τ})`; Tustin `A_d = (1 − h)/(1 + h)`,
/// `B_d = T/(1 + h)`, `C_d = c/(1 + h)`, `D_d = d + c B_d/2`, `h = T/(2τ)`.
#[test]
fn a_first_order_lag_discretises_as_by_hand() {
    let (tau, c, d): (f64, f64, f64) = (4e-4, -3.0, -0.5);
    let t = Design::study().period_s;
    let text = |method: &str| {
        format!(
            "a = [[{}]]\nb = [[1.0, 0.0]]\nc = [[{c:e}], [0.0]]\nd = [[{d:e}, 0.0], [0.0, 0.0]]\ndiscretisation = \"{method}\"",
            -1.0 / tau
        )
    };
    let z = system(&planar(), &text("zoh"));
    let p = (-t / tau).exp();
    assert!((z.a[(0, 0)] - p).abs() < 1e-15, "{}", z.a);
    assert!((z.b[(0, 0)] - tau * (1.0 - p)).abs() < 1e-15 * tau && z.b[(0, 1)] == 0.0, "{}", z.b);
    assert_eq!((z.c[(0, 0)], z.d[(0, 0)]), (c, d));
    let s = system(&planar(), &text("tustin"));
    let h = t / (2.0 * tau);
    assert!((s.a[(0, 0)] - (1.0 - h) / (1.0 + h)).abs() < 1e-15, "{}", s.a);
    assert!((s.b[(0, 0)] - t / (1.0 + h)).abs() < 1e-15 * t, "{}", s.b);
    assert!((s.c[(0, 0)] - c / (1.0 + h)).abs() < 1e-15 * c.abs(), "{}", s.c);
    assert!((s.d[(0, 0)] - (d + c * t / (1.0 + h) / 2.0)).abs() < 1e-15, "{}", s.d);
}

/// Without a, b, c the law is the design's PD per axis: `pd`'s currents on every axis from rest,
/// on the planar model and on a two-plane rotor whose planes differ, within round-off.
#[test]
fn the_default_is_pd_on_every_axis() {
    let a = Design::study();
    let b = Design {
        stiffness_n_per_m: 2e6,
        damping_ratio: 0.1,
        constants: crate::design::LoopConstants { rotor_mass_kg: 7.0, ..a.constants },
        ..a
    };
    let two = RotorDesign::TwoPlane { planes: [a, b], geometry: crate::design::Geometry::symmetric_study() };
    for design in [planar(), two] {
        let mut ss = build_with(&design, "").unwrap();
        let mut pd =
            crate::law::build_among(&[AnyLaw::from(crate::pd::LAW)], "pd", &design, &Params::default()).unwrap();
        for k in 0..300u64 {
            let x = k as f64;
            let v = if k == 0 { 0.0 } else { 1.0 };
            let s = RotorSample {
                seq: k,
                axes: design.axes(),
                sensor_v: [v * 0.2 * (0.1 * x).sin(), v * -0.1, v * 0.05 * (0.7 * x).cos(), v * 0.3],
                ..Default::default()
            };
            let (i, r) = (ss.update(&s), pd.update(&s));
            for axis in 0..design.axes() as usize {
                assert!((i[axis] - r[axis]).abs() < 1e-13, "{k} axis {axis}: {i:?} against {r:?}");
            }
        }
    }
}

/// The same SISO law on each axis as `transfer_function` (its controllable canonical form, Tustin)
/// and as `state_space` (the same realisation, diagonal in the axes): the same currents within
/// round-off.
#[test]
fn a_siso_law_is_the_same_as_state_space_and_as_transfer_function() {
    // C(s) = (b1 s + b2)/(s² + a1 s + a2): A = [[−a1, −a2], [1, 0]], B = e1, C = [b1, b2].
    let (b1, b2, a1, a2) = (-30.0, -2.0e5, 6000.0, 2.0e7);
    let tf = format!("num = [{b1:e}, {b2:e}]\nden = [1.0, {a1:e}, {a2:e}]");
    let ss = format!(
        "a = [[{}, {}, 0, 0], [1, 0, 0, 0], [0, 0, {}, {}], [0, 0, 1, 0]]\nb = [[1, 0], [0, 0], [0, 1], [0, 0]]\n\
         c = [[{b1:e}, {b2:e}, 0, 0], [0, 0, {b1:e}, {b2:e}]]",
        -a1, -a2, -a1, -a2
    );
    let design = Design::study();
    let mut t = (crate::transfer_function::LAW.build)(&design, &Params::parse(&tf).unwrap()).unwrap();
    let mut s = build_with(&RotorDesign::Planar(design), &ss).unwrap();
    for k in 0..400u64 {
        let u = [0.1 * (0.03 * k as f64).sin(), 0.05 * (0.2 * k as f64).cos()];
        let i = t.update(&Sample { seq: k, sensor_v: u, ..Default::default() });
        let j = s.update(&RotorSample { seq: k, axes: 2, sensor_v: [u[0], u[1], 0.0, 0.0], ..Default::default() });
        for axis in 0..2 {
            assert!((i[axis] - j[axis]).abs() < 1e-10 * (i[axis].abs() + 1e-3), "{k}: {i:?} against {j:?}");
        }
    }
}

/// Bad input, each refused naming the key, the value and what was expected.
#[test]
fn bad_input_is_refused_by_key_and_value() {
    let one = "a = [[-1.0]]\nb = [[1.0, 0.0]]\nc = [[1.0], [0.0]]";
    let cases: Vec<(String, &[&str])> = vec![
        (
            "a = [[-1.0]]\nb = [[1.0, 0.0, 0.0]]\nc = [[1.0], [0.0]]".into(),
            &["controller.params.b", "is 1 × 3: expected 1 × 2", "2 axes"],
        ),
        (
            "a = [[-1.0, 0.0]]\nb = [[1.0, 0.0]]\nc = [[1.0], [0.0]]".into(),
            &["controller.params.a", "is 1 × 2: expected 1 × 1"],
        ),
        (
            "a = [[-1.0]]\nb = [[1.0, 0.0]]\nc = [[1.0], [0.0], [0.0]]".into(),
            &["controller.params.c", "is 3 × 1: expected 2 × 1"],
        ),
        (format!("{one}\nd = [[1.0]]"), &["controller.params.d", "is 1 × 1: expected 2 × 2"]),
        (
            "a = [[-1.0], [1.0, 2.0]]\nb = [[1.0, 0.0]]\nc = [[1.0], [0.0]]".into(),
            &["controller.params.a", "row 2 has 2 columns, row 1 has 1"],
        ),
        (
            "a = [[nan]]\nb = [[1.0, 0.0]]\nc = [[1.0], [0.0]]".into(),
            &["controller.params.a", "row 1 column 1 = NaN", "finite"],
        ),
        ("a = [[-1.0]]\nb = [[1.0, 0.0]]".into(), &["controller.params.c", "c not set"]),
        (
            format!("{one}\ndomain = \"z\"\ndt_s = 1e-4"),
            &["controller.params.dt_s = 0.0001 s", "controller period, 0.00005 s"],
        ),
        (format!("{one}\nprewarp_hz = 10000"), &["controller.params.prewarp_hz = 10000 Hz", "Nyquist"]),
        (format!("{one}\ndiscretisation = \"foh\""), &["controller.params.discretisation = \"foh\""]),
        ("d = [[1.0, 0.0], [0.0, 1.0]]".into(), &["controller.params.d", "only with a, b and c"]),
        (
            format!("a = [[{}]]\nb = [[1.0, 0.0]]\nc = [[1.0], [0.0]]", 2.0 / Design::study().period_s),
            &["controller.params.a", "singular"],
        ),
    ];
    for (text, needles) in &cases {
        let e = build_with(&planar(), text).err().unwrap_or_else(|| panic!("{text:?} was accepted")).to_string();
        assert!(e.starts_with("law state_space"), "{e}");
        for n in *needles {
            assert!(e.contains(n), "{text:?}: no {n:?} in {e}");
        }
    }
    // On the two-plane rotor the sizes are 4 axes'.
    let e = build_with(&RotorDesign::symmetric_study(), one).err().unwrap().to_string();
    assert!(e.contains("controller.params.b") && e.contains("expected 1 × 4") && e.contains("4 axes"), "{e}");
}

/// An unstable controller builds and runs (it grows, as it should).
#[test]
fn an_unstable_system_is_allowed() {
    let mut law =
        build_with(&planar(), "a = [[1.0]]\nb = [[1.0, 0.0]]\nc = [[1.0], [0.0]]\ndomain = \"z\"\ndt_s = 5e-5")
            .unwrap();
    let mut last = 0.0;
    for k in 0..5 {
        last = law.update(&RotorSample { seq: k, axes: 2, sensor_v: [1.0, 0.0, 0.0, 0.0], ..Default::default() })[0];
    }
    assert_eq!(last, 4.0);
}

/// From a JSON file (python-control's `StateSpace` fields, `D` optional): the law of the same
/// parameters; sizes from the file checked against the axes.
#[test]
fn a_law_from_a_json_file_is_the_law_from_its_parameters() {
    let path = std::env::temp_dir().join(format!("ss-{}-law.json", std::process::id()));
    std::fs::write(&path, br#"{"A": [[-100.0]], "B": [[1.0, 0.5]], "C": [[-2.0], [0.3]], "dt": 0.0}"#).unwrap();
    let file = format!("file = {:?}\ndiscretisation = \"zoh\"", path.display().to_string());
    let inline = "a = [[-100.0]]\nb = [[1.0, 0.5]]\nc = [[-2.0], [0.3]]\ndiscretisation = \"zoh\"";
    let (mut x, mut y) = (build_with(&planar(), &file).unwrap(), build_with(&planar(), inline).unwrap());
    for k in 0..50u64 {
        let s = RotorSample { seq: k, axes: 2, sensor_v: [0.01 * k as f64, -0.02, 0.0, 0.0], ..Default::default() };
        assert_eq!(x.update(&s), y.update(&s));
    }
    let e = build_with(&RotorDesign::symmetric_study(), &file).err().unwrap().to_string();
    // From a file: the file named, and the variable as it is called there.
    assert!(e.contains("controller.params.file") && e.contains("its `B` is 1 × 2: expected 1 × 4"), "{e}");
    std::fs::write(&path, br#"{"A": [[-100.0]], "B": [[1.0, 0.5]]}"#).unwrap();
    let e = build_with(&planar(), &file).err().unwrap().to_string();
    assert!(e.contains("controller.params.file") && e.contains("its `C` is missing"), "{e}");
    let _ = std::fs::remove_file(&path);
}
