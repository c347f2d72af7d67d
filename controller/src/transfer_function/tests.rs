use super::*;
use crate::pd::SampledPd;

fn design() -> Design {
    Design::study()
}

fn build_with(text: &str) -> Result<Box<dyn ControlLaw>, LawError> {
    (LAW.build)(&design(), &Params::parse(text).unwrap())
}

fn close(a: &[f64], b: &[f64], rel: f64) -> bool {
    let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= rel * scale)
}

/// Tustin of `g/(τ s + 1)` by hand: `(τK + 1) z + (1 − τK)` over `g (z + 1)`, with `K = 2/T`, or
/// `ω/tan(ωT/2)` prewarped.
#[test]
fn tustin_of_a_first_order_lag_is_the_hand_result() {
    let (g, tau, t): (f64, f64, f64) = (-3.0, 2e-4, 5e-5);
    for k in [2.0 / t, 3000.0 / (3000.0 * t / 2.0).tan()] {
        let prewarp = (k != 2.0 / t).then_some(3000.0);
        let got = discretise(&[g], &[tau, 1.0], t, Method::Tustin { prewarp_rad_s: prewarp });
        let (d0, d1) = (tau * k + 1.0, 1.0 - tau * k);
        assert!(close(&got.b, &[g / d0, g / d0], 1e-15), "{got:?}");
        assert!(close(&got.a, &[1.0, d1 / d0], 1e-15), "{got:?}");
    }
}

/// Zero-order hold by hand: `g/(τ s + 1)` holds to `g (1 − e^{−T/τ}) / (z − e^{−T/τ})`; the double
/// integrator `1/s²` to `T² (z + 1) / (2 (z − 1)²)`.
#[test]
fn zoh_of_a_lag_and_a_double_integrator_are_the_hand_results() {
    let (g, tau, t): (f64, f64, f64) = (2.5, 3e-4, 5e-5);
    let p = (-t / tau).exp();
    let got = discretise(&[g], &[tau, 1.0], t, Method::Zoh);
    assert!(close(&got.b, &[0.0, g * (1.0 - p)], 1e-13), "{got:?}");
    assert!(close(&got.a, &[1.0, -p], 1e-15), "{got:?}");
    let got = discretise(&[1.0], &[1.0, 0.0, 0.0], t, Method::Zoh);
    assert!(close(&got.b, &[0.0, t * t / 2.0, t * t / 2.0], 1e-13), "{got:?}");
    assert!(close(&got.a, &[1.0, -2.0, 1.0], 1e-15), "{got:?}");
    // A static gain stays one.
    assert_eq!(discretise(&[4.0], &[2.0], t, Method::Zoh), DiscreteTf { b: vec![2.0], a: vec![1.0] });
}

/// The study's PD written in z, from the closed forms (MODEL.md §3: `k_p = (k_e + k_s)/(k_i A_a
/// A_s)`, `k_d = 2 ξ √(k_e m)/(k_i A_a A_s)`, computed here, not by the law): the same currents as
/// `pd` sample by sample from rest, within round-off (the law sums `b₀ u_k + b₁ u_{k−1}` where
/// `pd` sums `k_p u_k + k_d (u_k − u_{k−1})/T`: a few ulps of the largest term).
#[test]
fn the_studys_pd_in_z_answers_as_pd() {
    let d = design();
    let c = d.constants;
    let loop_gain = c.ki_n_per_a * c.amp_gain_a_per_v * c.sensor_gain_v_per_m;
    let kp = (d.stiffness_n_per_m + c.ks_n_per_m) / loop_gain;
    let kd = 2.0 * d.damping_ratio * (d.stiffness_n_per_m * c.rotor_mass_kg).sqrt() / loop_gain;
    let (a, t) = (c.amp_gain_a_per_v, d.period_s);
    let text =
        format!("num = [{:e}, {:e}]\nden = [1.0, 0.0]\ndomain = \"z\"\ndt_s = {t:e}", -a * (kp + kd / t), a * kd / t);
    let mut tf = build_with(&text).unwrap();
    let mut default = build_with("").unwrap();
    let mut pd = SampledPd::new(PdGains::from_design(&d.pd(), &c).unwrap(), t);
    for k in 0..500u64 {
        let x = k as f64;
        let u = if k == 0 { [0.0; 2] } else { [0.3 * (0.05 * x).sin(), 0.1 * (0.31 * x).cos() - 0.1] };
        let s = Sample { seq: k, t_s: x * t, sensor_v: u, ..Default::default() };
        let (i, j, r) = (tf.update(&s), default.update(&s), pd.update(&s));
        for axis in 0..2 {
            let scale = a * (kp + kd / t) * (u[axis].abs() + 0.4) + r[axis].abs();
            assert!((i[axis] - r[axis]).abs() <= 1e-14 * scale, "sample {k}: {i:?} against pd's {r:?}");
            assert!((j[axis] - r[axis]).abs() <= 1e-14 * scale, "sample {k}: default {j:?} against pd's {r:?}");
        }
    }
}

/// Transposed direct form II is the difference equation `Σ a_j y_{k−j} = Σ b_j u_{k−j}`, from
/// rest, on a third-order transfer (checked against the equation written out), and `reset` goes
/// back to rest.
#[test]
fn the_law_runs_the_difference_equation_from_rest() {
    let b = [0.2, -0.1, 0.05, 0.01];
    let a = [1.0, -0.5, 0.2, -0.1];
    let mut law = TransferFunction::new(DiscreteTf { b: b.to_vec(), a: a.to_vec() }, [0.0, 0.5]);
    let (mut us, mut ys) = (vec![0.0; 3], vec![0.0; 3]);
    let mut first = None;
    for k in 0..60 {
        let u = ((k * 7 % 11) as f64 - 5.0) * 0.1;
        let y = b[0] * u + b[1] * us[0] + b[2] * us[1] + b[3] * us[2] - a[1] * ys[0] - a[2] * ys[1] - a[3] * ys[2];
        let i = law.update(&Sample { sensor_v: [u, u], ..Default::default() });
        assert!((i[0] - y).abs() < 1e-14 && (i[1] - 0.5 - y).abs() < 1e-14, "{k}: {i:?} against {y}");
        first.get_or_insert(i);
        us.rotate_right(1);
        ys.rotate_right(1);
        (us[0], ys[0]) = (u, y);
    }
    law.reset();
    assert_eq!(Some(law.update(&Sample { sensor_v: [-0.5, -0.5], ..Default::default() })), first);
}

/// Bad input, each refused naming the key, the value and what was expected.
#[test]
fn bad_input_is_refused_by_key_and_value() {
    let t = design().period_s;
    let cases: &[(&str, &[&str])] = &[
        (
            "num = [1.0, 2.0, 3.0]\nden = [1.0, 1.0]",
            &["controller.params.num", "[1.0, 2.0, 3.0]", "improper", "degree 2"],
        ),
        ("num = [1.0]\nden = [0.0, 1.0]", &["controller.params.den", "[0.0, 1.0]", "leading coefficient"]),
        ("num = [1.0, nan]\nden = [1.0, 1.0]", &["controller.params.num", "element 2", "finite"]),
        ("num = [1.0]\nden = [1.0, inf]", &["controller.params.den", "element 2 = inf", "finite"]),
        ("num = [1.0]\nden = [1.0, \"x\"]", &["controller.params.den", "element 2", "not a number"]),
        ("num = 1.0\nden = [1.0]", &["controller.params.num = 1.0", "array of numbers"]),
        ("num = []\nden = [1.0]", &["controller.params.num", "at least one"]),
        ("num = [1.0]", &["controller.params.den", "must be too"]),
        (
            "num = [1.0]\nden = [1.0, 0.5]\ndomain = \"z\"\ndt_s = 1e-4",
            &["controller.params.dt_s = 0.0001 s", "controller period, 0.00005 s"],
        ),
        ("num = [1.0]\nden = [1.0, 0.5]\ndomain = \"z\"", &["controller.params.dt_s", "not set"]),
        (
            "num = [1.0]\nden = [1e-3, 1.0]\nprewarp_hz = 10000.0",
            &["controller.params.prewarp_hz = 10000 Hz", "Nyquist", "10000 Hz"],
        ),
        (
            "num = [1.0]\nden = [1e-3, 1.0]\nprewarp_hz = 1e3\ndiscretisation = \"zoh\"",
            &["controller.params.prewarp_hz", "tustin"],
        ),
        (
            "num = [1.0]\nden = [1e-3, 1.0]\ndiscretisation = \"euler\"",
            &["controller.params.discretisation = \"euler\"", "\"zoh\""],
        ),
        ("num = [1.0]\nden = [1e-3, 1.0]\ndomain = \"w\"", &["controller.params.domain = \"w\"", "\"s\" or \"z\""]),
        ("num = [1.0]\nden = [1e-3, 1.0]\ndt_s = 5e-5", &["controller.params.dt_s", "only for domain"]),
        ("domain = \"z\"", &["controller.params.domain", "only with num and den"]),
        (
            "num = [1.0]\nden = [1e-300, 1.0]\ndiscretisation = \"tustin\"\nprewarp_hz = 1.0\nno = 1",
            &["controller.params.no"],
        ),
    ];
    let _ = t;
    for (text, needles) in cases {
        let e = build_with(text).err().unwrap_or_else(|| panic!("{text:?} was accepted")).to_string();
        assert!(e.starts_with("law transfer_function"), "{e}");
        for n in *needles {
            assert!(e.contains(n), "{text:?}: no {n:?} in {e}");
        }
    }
    // Too high an order.
    let den = vec!["1.0"; MAX_ORDER + 2].join(", ");
    let e = build_with(&format!("num = [1.0]\nden = [{den}]")).err().unwrap().to_string();
    assert!(e.contains("controller.params.den") && e.contains(&format!("above {MAX_ORDER}")), "{e}");
}

/// An unstable controller is allowed, and leading zeros of the numerator lower its degree.
#[test]
fn an_unstable_law_builds_and_leading_zeros_are_harmless() {
    let mut law = build_with("num = [0.0, 0.0, 1.0]\nden = [1.0, -1.0]\ndomain = \"z\"\ndt_s = 5e-5").unwrap();
    let mut last = 0.0;
    for k in 0..5 {
        last = law.update(&Sample { seq: k, sensor_v: [1.0, 0.0], ..Default::default() })[0];
    }
    assert_eq!(last, 4.0); // an accumulator: 0, 1, 2, 3, 4 (one sample late)
}

/// A file in the temporary folder, removed when dropped.
struct Temp(std::path::PathBuf);

impl Temp {
    fn new(name: &str, text: &[u8]) -> Self {
        let path = std::env::temp_dir().join(format!("tf-{}-{name}", std::process::id()));
        std::fs::write(&path, text).unwrap();
        Temp(path)
    }
    fn param(&self) -> String {
        format!("file = {:?}", self.0.display().to_string())
    }
}

impl Drop for Temp {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

/// From a JSON file (python-control's fields): the same law as from the parameters, in s
/// (with the discretisation keys beside the file) and in z; bad files refused naming `file`.
#[test]
fn a_law_from_a_json_file_is_the_law_from_its_parameters() {
    let s = Temp::new("s.json", br#"{"num": [-1e-3, -1.2], "den": [1e-4, 1.0], "dt": 0}"#);
    let z = Temp::new("z.json", br#"{"num": [[-5.0, 4.0]], "den": [[1.0, -0.3]], "dt": 5e-05}"#);
    let pairs = [
        (
            format!("{}\nprewarp_hz = 150.0", s.param()),
            "num = [-1e-3, -1.2]\nden = [1e-4, 1.0]\nprewarp_hz = 150.0".to_string(),
        ),
        (
            format!("{}\ndiscretisation = \"zoh\"", s.param()),
            "num = [-1e-3, -1.2]\nden = [1e-4, 1.0]\ndiscretisation = \"zoh\"".into(),
        ),
        (z.param(), "num = [-5.0, 4.0]\nden = [1.0, -0.3]\ndomain = \"z\"\ndt_s = 5e-5".into()),
    ];
    for (file, inline) in &pairs {
        let (mut a, mut b) = (build_with(file).unwrap(), build_with(inline).unwrap());
        for k in 0..50u64 {
            let sample = Sample { seq: k, sensor_v: [0.01 * k as f64, -0.02], ..Default::default() };
            assert_eq!(a.update(&sample), b.update(&sample), "{file}");
        }
    }
    let npz = Temp::new("x.npz", b"PK\x03\x04binary");
    let mat = Temp::new("x.mat", b"MATLAB 5.0 MAT-file, Platform: GLNXA64\x00\xff\xfe");
    let array = Temp::new("array.json", b"[1, 2]");
    let no_den = Temp::new("no-den.json", br#"{"num": [1.0]}"#);
    let bad_dt = Temp::new("dt.json", br#"{"num": [1.0], "den": [1.0, 0.5], "dt": 1e-4}"#);
    let nan = Temp::new("nan.json", br#"{"num": ["x"], "den": [1.0]}"#);
    let cases: Vec<(String, Vec<&str>)> = vec![
        (npz.param(), vec!["controller.params.file", "x.npz", "is not a numpy .npz of float64 arrays"]),
        (mat.param(), vec!["controller.params.file", "x.mat", "is not a readable .mat file", "128-byte header"]),
        (array.param(), vec!["controller.params.file", "holds a JSON array: expected an object"]),
        (no_den.param(), vec!["controller.params.file", "its `den` is missing"]),
        (bad_dt.param(), vec!["controller.params.file", "its `dt` = 0.0001 s", "controller period, 0.00005 s"]),
        (nan.param(), vec!["controller.params.file", "its `num` element 1 = \"x\" is not a finite number"]),
        (format!("{}\nnum = [1.0]", s.param()), vec!["controller.params.file", "not also in [controller.params]"]),
        (format!("{}\ndomain = \"z\"", s.param()), vec!["controller.params.domain", "the file", "gives it"]),
        (
            "file = \"/no/such/law.json\"".into(),
            vec!["controller.params.file = \"/no/such/law.json\"", "cannot be read"],
        ),
        ("file = \"/\"".into(), vec!["controller.params.file = \"/\"", "not a regular file"]),
    ];
    for (text, needles) in &cases {
        let e = build_with(text).err().unwrap_or_else(|| panic!("{text:?} was accepted")).to_string();
        for n in needles {
            assert!(e.contains(n), "{text:?}: no {n:?} in {e}");
        }
    }
    // A FIFO is refused at once, never waited on.
    let fifo = std::env::temp_dir().join(format!("tf-{}-fifo.json", std::process::id()));
    let made = std::process::Command::new("mkfifo").arg(&fifo).status().map(|s| s.success()).unwrap_or(false);
    if made {
        let e = build_with(&format!("file = {:?}", fifo.display().to_string())).err().unwrap().to_string();
        let _ = std::fs::remove_file(&fifo);
        assert!(e.contains("controller.params.file") && e.contains("not a regular file"), "{e}");
    }
}
