//! `plant linear` (docs/guide/linear.md): the linear plant of the shipped scenes loaded by
//! numpy, scipy and python-control as a user would (`np.load`, `json.load`, `scipy.io.loadmat`
//! of `linear.mat`, the same matrices bit for bit, `control.ss`), checked
//! against figures worked by hand from the scene files (read by Python's `tomllib`, not by the
//! plant): the planar rotor's poles `±√(k_s/m)` and DC gain `−A_s k_i/k_s`, its frequency
//! response with the amplifier, coil, back-EMF and sensor filter of realistic-10g, the
//! two-plane rotor's poles from its stations and inertias; and python-control's own
//! zero-order hold (`sample_system(sys, Ts, 'zoh')`) against the exported discrete system
//! (relative 1e-12, the delay states aside). Bad input: exit 2, named, nothing written.

mod common;

use common::{assert_exit, output_within, plant_bin, scene, stderr, workspace_root, TempDir};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;
use std::time::Duration;

/// python-control and what it needs, pinned (the releases these checks were written with).
const PACKAGES: [&str; 3] = ["control==0.10.2", "numpy==2.4.6", "scipy==1.17.1"];

/// `target/control-venv` with [`PACKAGES`]: made if absent or stale, under a file lock.
fn venv() -> &'static Path {
    static VENV: OnceLock<PathBuf> = OnceLock::new();
    VENV.get_or_init(|| {
        let target = Path::new(env!("CARGO_TARGET_TMPDIR")).parent().expect("CARGO_TARGET_TMPDIR is target/tmp");
        let dir = target.join("control-venv");
        let stamp = PACKAGES.join("\n");
        let lock = std::fs::File::create(target.join("control-venv.lock")).expect("venv lock file");
        lock.lock().expect("locking the venv");
        let stamp_file = dir.join("amb-testbed.stamp");
        if dir.join("bin/python").exists() && std::fs::read_to_string(&stamp_file).ok().as_deref() == Some(&stamp) {
            return dir;
        }
        let _ = std::fs::remove_dir_all(&dir);
        let made = output_within(Command::new("python3").arg("-m").arg("venv").arg(&dir), Duration::from_secs(120));
        assert_exit(&made, 0);
        let install = output_within(
            Command::new(dir.join("bin/python"))
                .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check"])
                .args(PACKAGES),
            Duration::from_secs(600),
        );
        assert_exit(&install, 0);
        std::fs::write(&stamp_file, stamp).expect("venv stamp");
        dir
    })
}

fn plant_linear(file: &Path, out: &Path, extra: &[&str]) -> Command {
    let mut c = Command::new(plant_bin());
    c.arg("linear").arg(file).arg("--out").arg(out).args(extra);
    c
}

/// The shipped scenes exported: planar (continuous, co-simulated with its delay, with the
/// amplifier and sensor filter), two-plane, flexible (continuous, sampled).
const SCENES: [&str; 6] =
    ["paper-10g", "cosim-10g", "realistic-10g", "two-plane-asymmetric-10g", "flexible-10g", "flexible-noncollocated"];

const CHECK: &str = r#"
import json, sys, tomllib
import numpy as np
import scipy.io
import control

out, config = sys.argv[1], sys.argv[2]
TAU = 2 * np.pi

def load(name):
    z = np.load(f"{out}/{name}/linear.npz")
    with open(f"{out}/{name}/linear.json") as f:
        j = json.load(f)
    with open(f"{config}/{name}.toml", "rb") as f:
        scene = tomllib.load(f)
    for key, path in [("A", ("continuous", "A")), ("B", ("continuous", "B")), ("C", ("continuous", "C")),
                      ("D", ("continuous", "D")), ("Ad", ("discrete", "A")), ("Bd", ("discrete", "B")),
                      ("Cd", ("discrete", "C")), ("Dd", ("discrete", "D"))]:
        assert np.array_equal(z[key], np.array(j[path[0]][path[1]], dtype=float).reshape(z[key].shape)), (name, key)
    assert list(z["inputs"]) == [s["name"] for s in j["inputs"]]
    assert list(z["states"]) == [s["name"] for s in j["continuous"]["states"]]
    assert list(z["states_d"]) == [s["name"] for s in j["discrete"]["states"]]
    assert float(z["dt"]) == j["discrete"]["dt"] and int(z["delay_samples"]) == j["discrete"]["delay_samples"]
    assert j["format"] == "plant-linear" and j["version"] == 1
    assert set(z["input_units"]) == {"A"} and set(z["output_units"]) == {"V"}
    # linear.mat as scipy reads it in MATLAB's classes (`mat_dtype=True`: what MATLAB's `load`
    # gives; a matrix of whole numbers is stored as integers, as MATLAB's `save` does, its class
    # double): the same matrices bit for bit, the numbers as 1 x 1, the names and units as n x 1
    # cell arrays of text.
    m = scipy.io.loadmat(f"{out}/{name}/linear.mat", mat_dtype=True)
    for key in ["A", "B", "C", "D", "Ad", "Bd", "Cd", "Dd"]:
        assert m[key].dtype == np.float64 and m[key].shape == z[key].shape, (name, key, m[key].shape)
        assert np.ascontiguousarray(m[key]).tobytes() == np.ascontiguousarray(z[key]).tobytes(), (name, key)
    for key in ["dt", "delay_samples", "speed_hz"]:
        assert m[key].shape == (1, 1) and m[key][0, 0].tobytes() == z[key].tobytes(), (name, key)
    for key in ["inputs", "input_units", "outputs", "output_units", "states", "state_units", "states_d",
                "state_units_d", "format"]:
        assert m[key].shape == (len(z[key]), 1), (name, key, m[key].shape)
        assert [str(c[0]) for c in m[key][:, 0]] == [str(v) for v in z[key]], (name, key)
    return z, j, scene

def close(a, b, tol):
    return np.max(np.abs(np.asarray(a) - np.asarray(b))) <= tol * np.max(np.abs(b))

report = []
for name in sys.argv[3:]:
    z, j, scene = load(name)
    sys_c = control.ss(z["A"], z["B"], z["C"], z["D"])
    n, m = z["A"].shape[0], z["B"].shape[1]
    # (b) python-control's zero-order hold is the exported one, the delay states aside.
    dt, d = float(z["dt"]), int(z["delay_samples"])
    sd = control.sample_system(sys_c, dt, "zoh")
    phi = z["Ad"][:n, :n]
    gamma = z["Bd"][:n] if d == 0 else z["Ad"][:n, n + m * (d - 1):n + m * d]
    e_phi = np.max(np.abs(phi - sd.A)) / np.max(np.abs(sd.A))
    e_gamma = np.max(np.abs(gamma - sd.B)) / np.max(np.abs(sd.B))
    assert e_phi < 1e-12 and e_gamma < 1e-12, (name, e_phi, e_gamma)
    assert np.array_equal(z["Cd"][:, :n], z["C"]) and not z["Cd"][:, n:].any()
    if d > 0:
        assert np.array_equal(z["Bd"][n:n + m], np.eye(m)) and not z["Bd"][:n].any()
    report.append(f"{name}: {n} states, zoh against python-control: Phi {e_phi:.1e}, Gamma {e_gamma:.1e}")
    amb, rotor = scene["amb"], scene["rotor"]
    ks, ki, a_s = amb["ks_n_per_m"], amb["ki_n_per_a"], amb["sensor_gain_v_per_m"]
    # (a) by hand from the scene file.
    if name in ("paper-10g", "cosim-10g"):
        mass = rotor["mass_kg"]
        p = np.sqrt(ks / mass)
        poles = np.sort(control.poles(sys_c).real)
        assert close(poles, [-p, -p, p, p], 1e-12), (name, poles)
        dc = control.dcgain(sys_c)
        assert close(np.diag(dc), [-a_s * ki / ks] * 2, 1e-12) and abs(dc[0, 1]) == 0, dc
        # python-control's own evaluation of (sI - A)^-1 (an LU solve without refinement) loses
        # about 3e-12 at 3 kHz where the position follows from the velocity: 1e-10 allowed.
        for f in [1.0, 30.0, 300.0, 3000.0]:
            s = 1j * TAU * f
            want = a_s * ki / (mass * s * s - ks)
            got = sys_c(s)
            assert abs(got[0, 0] - want) <= 1e-10 * abs(want) and abs(got[1, 1] - want) <= 1e-10 * abs(want), (f, got, want)
    if name == "realistic-10g":
        mass = rotor["mass_kg"]
        L, R = amb["coil_inductance_mh"] * 1e-3, amb["coil_resistance_ohm"]
        wc, kb = TAU * amb["current_loop_hz"], amb["back_emf_v_s_per_m"]
        wf = TAU * scene["sensor"]["bandwidth_hz"]
        kp, kI = L * wc, R * wc
        # (L s^2 + (K_p + R) s + K_I)(m s^2 - k_s) + k_b k_i s^2 = 0, and the filter's
        # s^2 + sqrt(2) w s + w^2 = 0: each twice (x and y).
        rotor_coil = np.polymul([L, kp + R, kI], [mass, 0.0, -ks]) + np.array([0, 0, kb * ki, 0, 0])
        want = np.concatenate([np.roots(rotor_coil), np.roots([1.0, np.sqrt(2) * wf, wf * wf])] * 2)
        got = control.poles(sys_c)
        for w in want:
            assert np.min(np.abs(got - w)) <= 1e-9 * abs(w), (w, got)
        assert close(np.diag(control.dcgain(sys_c)), [-a_s * ki / ks] * 2, 1e-12)
        for f in [3.0, 47.0, 500.0, 4000.0]:
            s = 1j * TAU * f
            x = ki * (kp + kI / s) / ((mass * s * s - ks) * (L * s + kp + R + kI / s) + kb * ki * s)
            want = a_s * x * wf * wf / (s * s + np.sqrt(2) * wf * s + wf * wf)
            got = sys_c(s)[0, 0]
            assert abs(got - want) <= 1e-10 * abs(want), (f, got, want)
        report.append(f"{name}: poles and response by hand (rotor, PI loop and coil with back-EMF, 2nd-order filter)")
    if name == "two-plane-asymmetric-10g":
        # At rest each direction's (translation, slope) pair: M q'' = sum_i k_s [1, z_i]^T [1, z_i] q.
        z_i = [rotor["bearing_a_mm"] * 1e-3, rotor["bearing_b_mm"] * 1e-3]
        K = sum(ks * np.outer([1.0, z], [1.0, z]) for z in z_i)
        lam = np.linalg.eigvals(np.linalg.solve(np.diag([rotor["mass_kg"], rotor["transverse_inertia_kg_m2"]]), K))
        want = np.concatenate([np.sqrt(lam), -np.sqrt(lam)] * 2)
        rest = np.load(f"{out}/{name}-rest/linear.npz")
        got = control.poles(control.ss(rest["A"], rest["B"], rest["C"], rest["D"]))
        assert close(np.sort(got.real), np.sort(want), 1e-10) and np.max(np.abs(got.imag)) < 1e-6, (got, want)
        report.append(f"{name}: poles at rest by hand {np.sort(want)[-2:]} 1/s")
    # Item 3's computed margins: python-control's stability_margins of G_o = -P C on one axis
    # of the planar rotor (the axes decouple), the law's transfer as linear.json gives it.
    # (Not realistic-10g: python-control's transfer function of its 12-state axis is badly
    # conditioned, scipy says, and its crossings near DC, where G_o hugs the real axis, differ.)
    if name in ("paper-10g", "cosim-10g"):
        law = j["law"]
        t = law["axes"][0]
        if law["form"] == "sampled":
            plant_x = control.ss(z["Ad"], z["Bd"], z["Cd"], z["Dd"], dt)[0, 0]
            ctl = control.tf(t["num"], t["den"], dt)
        else:
            plant_x = sys_c[0, 0]
            ctl = control.tf(t["num"], t["den"])
        g_o = -control.tf(plant_x) * ctl
        # Every crossing python-control finds (on its own frequency grid: not the DC end, where
        # a PD's G_o is real, which linear.json lists first) is one of ours, its margin the same.
        gms, pms, sms, w180, wc, ws = control.stability_margins(g_o, returnall=True)
        ours = j["margins"][0]
        def find(crossings, f):
            hit = [c for c in crossings if abs(c["f_hz"] / f - 1) < 1e-4]
            assert hit, (name, f, crossings)
            return hit[0]
        for w, g in zip(w180, gms):
            if w > 0:
                c = find(ours["phase_crossovers"], w / TAU)
                assert abs(20 * np.log10(g) - 20 * np.log10(c["margin"])) < 0.01, (name, w, g, c)
        for w, p in zip(wc, pms):
            c = find(ours["gain_crossovers"], w / TAU)
            assert abs(p - c["margin"]) < 0.01, (name, w, p, c)
        pm = pms[np.argmin(np.abs(pms))]
        assert abs(pm - ours["phase_margin_deg"]) < 0.01, (name, pm, ours)
        assert len(w180[w180 > 0]) + 1 >= len(ours["phase_crossovers"]) and len(wc) == len(ours["gain_crossovers"])
        report.append(f"{name}: margins, python-control against linear.json: PM {pm:.4f} / {ours['phase_margin_deg']:.4f} deg; "
                      f"phase crossovers {[round(20 * np.log10(g), 3) for g in gms]} dB / "
                      f"{[round(20 * np.log10(c['margin']), 3) for c in ours['phase_crossovers']]} dB")
print("\n".join(report))
"#;

#[test]
fn python_control_loads_the_linear_plants_and_finds_the_hand_figures() {
    let dir = TempDir::new("linear-python");
    let out = dir.join("out");
    for name in SCENES {
        let o = output_within(
            &mut plant_linear(&scene(&format!("{name}.toml")), &out.join(name), &[]),
            Duration::from_secs(60),
        );
        assert_exit(&o, 0);
        assert!(stderr(&o).contains("linear.npz"), "{}", stderr(&o));
    }
    let rest = out.join("two-plane-asymmetric-10g-rest");
    let o = output_within(
        &mut plant_linear(&scene("two-plane-asymmetric-10g.toml"), &rest, &["--speed-hz", "0"]),
        Duration::from_secs(60),
    );
    assert_exit(&o, 0);
    let script = dir.join("check.py");
    std::fs::write(&script, CHECK).unwrap();
    let o = output_within(
        Command::new(venv().join("bin/python"))
            .arg(&script)
            .arg(&out)
            .arg(workspace_root().join("config"))
            .args(SCENES),
        Duration::from_secs(300),
    );
    eprintln!("{}", String::from_utf8_lossy(&o.stdout));
    assert_exit(&o, 0);
}

/// Bad input: a negative or non-finite speed, an unknown scene, a bad key, an output folder
/// that is a file or a link: exit 2, the value named, nothing written.
#[test]
fn bad_input_is_refused_by_name_and_nothing_is_written() {
    let dir = TempDir::new("linear-bad");
    let paper = scene("paper-10g.toml");
    let out = dir.join("out");
    let cases: [(&[&str], &[&str]); 6] = [
        (&["--speed-hz", "-5"], &["--speed-hz", "`-5`", "from 0 to 100000 Hz"]),
        (&["--speed-hz", "1e300"], &["--speed-hz", "`1e300`", "from 0 to 100000 Hz"]),
        (&["--speed-hz", "NaN"], &["--speed-hz", "`NaN`", "from 0 to 100000 Hz"]),
        (&["--speed-hz", "inf"], &["--speed-hz", "`inf`", "from 0 to 100000 Hz"]),
        (&["--set", "rotor.speed_hz=-3"], &["speed_hz"]),
        (&["--set", "amb.no_such_key=1"], &["no_such_key"]),
    ];
    for (extra, needles) in cases {
        let o = output_within(&mut plant_linear(&paper, &out, extra), Duration::from_secs(30));
        let err = stderr(&o);
        assert_exit(&o, 2);
        assert!(!err.contains("panicked"), "{extra:?}: {err}");
        for n in needles {
            assert!(err.contains(n), "{extra:?}: no {n:?} in {err}");
        }
        assert!(!out.exists(), "{extra:?}: bad input created {}", out.display());
    }
    // An unknown scene.
    let missing = dir.join("no-such-scene.toml");
    let o = output_within(&mut plant_linear(&missing, &out, &[]), Duration::from_secs(30));
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("no-such-scene.toml"), "{}", stderr(&o));
    assert!(!out.exists());
    // The output folder is a file: refused, the file untouched.
    let file = dir.join("a-file");
    std::fs::write(&file, "mine").unwrap();
    let o = output_within(&mut plant_linear(&paper, &file, &[]), Duration::from_secs(30));
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("a file, not a folder"), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "mine");
    // Inside a file.
    let o = output_within(&mut plant_linear(&paper, &file.join("sub"), &[]), Duration::from_secs(30));
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("is a file, not a folder"), "{}", stderr(&o));
    // A link to a folder: refused, nothing written in the folder it points to.
    let target = dir.join("elsewhere");
    std::fs::create_dir(&target).unwrap();
    let link = dir.join("link");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let o = output_within(&mut plant_linear(&paper, &link, &[]), Duration::from_secs(30));
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("symbolic link"), "{}", stderr(&o));
    assert_eq!(std::fs::read_dir(&target).unwrap().count(), 0);
}

// ---- Law `transfer_function` (issue 39 item 2) ----

use controller::transfer_function::{discretise, Method};

/// python-control's `sample_system` on the cases the Rust side discretised, coefficient by
/// coefficient, relative 1e-12: the denominator to its largest coefficient, the numerator to the
/// terms python-control subtracted to get it. python-control (scipy's `ss2tf`, for every
/// method) takes the numerator as `poly(Φ − ΓC) + (D − 1) poly(Φ)`, a difference that cancels
/// when the gain is small against 1 (8e-8 relative on 1/s² at 20 kHz, 1.5e-12 on an unstable
/// first order prewarped), where the law's arithmetic is exact to round-off (the unit tests
/// `zoh_of_a_lag_and_a_double_integrator_are_the_hand_results`,
/// `tustin_of_a_first_order_lag_is_the_hand_result`).
const TF_CHECK: &str = r#"
import json, sys
import numpy as np
import control as ct
from scipy.signal import tf2ss, cont2discrete
cases = json.load(open(sys.argv[1]))
worst = {}
for c in cases:
    sys_c = ct.tf(c["num"], c["den"])
    kw = {}
    if c["prewarp_rad_s"] is not None:
        kw["prewarp_frequency"] = c["prewarp_rad_s"]
    d = ct.sample_system(sys_c, c["period_s"], c["method"], **kw)
    num, den = np.array(d.num[0][0], float), np.array(d.den[0][0], float)
    num = np.concatenate([np.zeros(len(den) - len(num)), num])
    b, a = np.array(c["b"]), np.array(c["a"])
    assert len(b) == len(num) and len(a) == len(den), (c["name"], b, num, a, den)
    scale_a = np.max(np.abs(den))
    # What python-control does inside (scipy): tf2ss, cont2discrete (at the period shrunk for a
    # prewarp), then ss2tf's difference poly(A - BC) + (D - 1) poly(A).
    w = c["prewarp_rad_s"]
    T = c["period_s"] if w is None else 2 * np.tan(w * c["period_s"] / 2) / w
    A, B, C, D, _ = cont2discrete(tf2ss(c["num"], c["den"]), T, "bilinear" if c["method"] == "tustin" else "zoh")
    scale_b = max(np.max(np.abs(np.poly(A - B @ C))), abs(D[0, 0] - 1) * np.max(np.abs(np.poly(A))),
                  np.max(np.abs(num)))
    eb, ea = np.max(np.abs(b - num)) / scale_b, np.max(np.abs(a - den)) / scale_a
    worst[c["name"]] = (eb, ea)
    assert eb <= 1e-12 and ea <= 1e-12, (c["name"], list(b), list(num), list(a), list(den), eb, ea)
for k, (eb, ea) in worst.items():
    print(f"{k}: numerator {eb:.2e}, denominator {ea:.2e}")
"#;

#[test]
fn transfer_function_discretisation_is_python_controls_sample_system() {
    use std::f64::consts::TAU;
    let t = 1.0 / 20_000.0;
    let mul = |a: &[f64], b: &[f64]| {
        let mut out = vec![0.0; a.len() + b.len() - 1];
        for (i, x) in a.iter().enumerate() {
            for (j, y) in b.iter().enumerate() {
                out[i + j] += x * y;
            }
        }
        out
    };
    // A lead-lag (zero at 150 Hz, pole at 1.5 kHz), the same behind a notch at 900 Hz, a PID with
    // a filtered derivative (a pole at 0), an unstable first order, and 1/s².
    let (wz, wp, wn) = (TAU * 150.0, TAU * 1500.0, TAU * 900.0);
    let lead = (vec![-1.2 / wz, -1.2], vec![1.0 / wp, 1.0]);
    let notch = (mul(&lead.0, &[1.0, 2.0 * 0.01 * wn, wn * wn]), mul(&lead.1, &[1.0, 2.0 * 0.2 * wn, wn * wn]));
    let pid = (vec![-2e-4, -0.9, -40.0], vec![1.0 / (TAU * 3000.0), 1.0, 0.0]);
    let unstable = (vec![0.5], vec![1.0, -100.0]);
    let double = (vec![1.0], vec![1.0, 0.0, 0.0]);
    let mut cases = Vec::new();
    for (name, (num, den)) in
        [("lead-lag", lead), ("lead-lag-notch", notch), ("pid", pid), ("unstable", unstable), ("1/s2", double)]
    {
        for (method, m) in [
            ("tustin", Method::Tustin { prewarp_rad_s: None }),
            ("tustin", Method::Tustin { prewarp_rad_s: Some(wn) }),
            ("zoh", Method::Zoh),
        ] {
            let d = discretise(&num, &den, t, m);
            let prewarp = match m {
                Method::Tustin { prewarp_rad_s } => prewarp_rad_s,
                Method::Zoh => None,
            };
            let label = format!("{name} {method}{}", if prewarp.is_some() { " prewarped" } else { "" });
            cases.push(serde_json::json!({
                "name": label, "num": num, "den": den, "period_s": t, "method": method,
                "prewarp_rad_s": prewarp, "b": d.b, "a": d.a,
            }));
        }
    }
    let dir = TempDir::new("tf-python");
    let (file, script) = (dir.join("cases.json"), dir.join("check.py"));
    std::fs::write(&file, serde_json::to_string(&cases).unwrap()).unwrap();
    std::fs::write(&script, TF_CHECK).unwrap();
    let o = output_within(Command::new(venv().join("bin/python")).arg(&script).arg(&file), Duration::from_secs(300));
    eprintln!("{}", String::from_utf8_lossy(&o.stdout));
    assert_exit(&o, 0);
}

/// The scene's PD written as a transfer in z by hand, from the scene file's constants
/// (MODEL.md §3: `k_p = (k_e + k_s)/(k_i A_a A_s)`, `k_d = 2 ξ √(k_e m)/(k_i A_a A_s)`, the rate
/// the backward difference: `C(z) = −A_a ((k_p + k_d/T) − (k_d/T) z⁻¹)`), as `--set` overrides.
fn pd_as_transfer(file: &Path, damping: f64) -> Vec<String> {
    let t: toml::Table = std::fs::read_to_string(file).unwrap().parse().unwrap();
    let f = |table: &str, key: &str| t[table][key].as_float().unwrap_or_else(|| panic!("{table}.{key}"));
    let loop_gain = f("amb", "ki_n_per_a") * f("amb", "amp_gain_a_per_v") * f("amb", "sensor_gain_v_per_m");
    let ke = f("controller", "stiffness_n_per_m");
    let kp = (ke + f("amb", "ks_n_per_m")) / loop_gain;
    let kd = 2.0 * damping * (ke * f("rotor", "mass_kg")).sqrt() / loop_gain;
    let (a, period) = (f("amb", "amp_gain_a_per_v"), 1.0 / f("controller", "rate_hz"));
    vec![
        "controller.law=transfer_function".into(),
        format!("controller.params.num=[{:e}, {:e}]", -a * (kp + kd / period), a * kd / period),
        "controller.params.den=[1.0, 0.0]".into(),
        "controller.params.domain=\"z\"".into(),
        format!("controller.params.dt_s={period:e}"),
    ]
}

/// A small shock (0.5 G, no contact) on the paper scene from rest, sampled, ξ = 0.2 (the naive PD's
/// sampled loop at ξ = 0.01 grows, MODEL.md): the scene's PD written as a transfer in z gives
/// `pd`'s trace within round-off (the law sums `b₀ u_k + b₁ u_{k−1}` where `pd` sums
/// `k_p u_k + k_d (u_k − u_{k−1})/T`: each column within 1e-12 of its largest value); and the
/// transfer run in lockstep by the `controller` process writes the sampled run's trace byte for
/// byte (the same code in both processes).
#[test]
fn transfer_function_of_the_pd_runs_as_pd_sampled_and_lockstep() {
    common::controller_bin();
    let file = scene("paper-10g.toml");
    let dir = TempDir::new("tf-pd");
    let base = [
        "scene.duration_s=0.05",
        "shock[0].start_s=0.005",
        "shock[0].peak_g=0.5",
        "output.plots=false",
        "controller.damping_ratio=0.2",
        "controller.mode=sampled",
        // From rest at the centre: the first sample reads 0 V, where `pd`'s first rate (zero) and
        // the transfer's (from rest, u₋₁ = 0) agree.
        "initial.unbalance_orbit=false",
    ];
    let run = |name: &str, extra: &[String]| {
        let out = dir.join(name);
        let sets: Vec<String> = base.iter().map(|s| s.to_string()).chain(extra.iter().cloned()).collect();
        let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
        let o = output_within(&mut common::plant_run(&file, &out, &sets), Duration::from_secs(300));
        assert_exit(&o, 0);
        out
    };
    let tf = pd_as_transfer(&file, 0.2);
    let pd = common::Csv::read(&run("pd", &[]).join("trace.csv"));
    let sampled = run("tf", &tf);
    let ours = common::Csv::read(&sampled.join("trace.csv"));
    assert_eq!(pd.header, ours.header);
    let s = common::read_json(&sampled.join("summary.json"));
    assert_eq!(common::num(&s, "max_contact_force_n"), 0.0, "the small shock touches: {s:#}");
    let mut largest = 0.0f64;
    for name in &pd.header {
        let (a, b) = (pd.column(name), ours.column(name));
        let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let worst = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        assert!(worst <= 1e-12 * scale, "{name}: {worst:e} against a largest value of {scale:e}");
        largest = largest.max(worst / scale.max(f64::MIN_POSITIVE));
    }
    eprintln!("transfer_function against pd: largest difference {largest:.1e} of a column's largest value");
    let mut lockstep = tf.clone();
    lockstep.push("controller.mode=lockstep".into());
    let lockstep = run("tf-lockstep", &lockstep);
    assert!(
        std::fs::read(sampled.join("trace.csv")).unwrap() == std::fs::read(lockstep.join("trace.csv")).unwrap(),
        "the transfer in lockstep wrote another trace than in the plant's process"
    );
}

/// Bad input to the law, through `plant run`: exit 2, the key, the value and what was expected
/// named, nothing written.
#[test]
fn transfer_function_bad_input_is_refused_by_name_and_nothing_is_written() {
    let file = scene("paper-10g.toml");
    let law = ["controller.mode=sampled", "controller.law=transfer_function"];
    let cases: [(&[&str], &[&str]); 7] = [
        (&["controller.params.num=[1.0, 2.0]", "controller.params.den=[1.0]"], &["controller.params.num", "improper"]),
        (
            &["controller.params.num=[1.0]", "controller.params.den=[0.0, 1.0]"],
            &["controller.params.den = [0.0, 1.0]", "leading"],
        ),
        (
            &["controller.params.num=[nan]", "controller.params.den=[1.0, 1.0]"],
            &["controller.params.num", "element 1 = NaN", "finite"],
        ),
        (
            &[
                "controller.params.num=[1.0]",
                "controller.params.den=[1.0, 0.5]",
                "controller.params.domain=\"z\"",
                "controller.params.dt_s=1e-4",
            ],
            &["controller.params.dt_s = 0.0001 s", "the scene's controller period, 0.00005 s"],
        ),
        (
            &["controller.params.num=[1.0]", "controller.params.den=[1e-3, 1.0]", "controller.params.prewarp_hz=12000"],
            &["controller.params.prewarp_hz = 12000 Hz", "below the Nyquist frequency", "10000 Hz"],
        ),
        (
            &[
                "controller.params.num=[1.0]",
                "controller.params.den=[1.0, 1.0]",
                "controller.params.discretisation=\"foh\"",
            ],
            &["controller.params.discretisation = \"foh\"", "\"tustin\" or \"zoh\""],
        ),
        (&["controller.params.num=[1.0]"], &["controller.params.den", "must be too"]),
    ];
    for (i, (extra, needles)) in cases.iter().enumerate() {
        let sets: Vec<&str> = SHORT_TF.iter().chain(&law).chain(extra.iter()).copied().collect();
        common::refused(&format!("tf-bad-{i}"), &file, &sets, needles);
    }
}

const SHORT_TF: [&str; 2] = ["scene.duration_s=0.01", "output.plots=false"];

/// python-control's `sample_system` on state-space systems (python-control keeps the
/// realisation: `(A_d, B_d, C_d, D_d)` from scipy's `cont2discrete`), against the law's, matrix
/// by matrix, relative 1e-12 of each matrix's largest entry.
const SS_CHECK: &str = r#"
import json, sys
import numpy as np
import control as ct
for c in json.load(open(sys.argv[1])):
    kw = {} if c["prewarp_rad_s"] is None else {"prewarp_frequency": c["prewarp_rad_s"]}
    d = ct.sample_system(ct.ss(c["A"], c["B"], c["C"], c["D"]), c["period_s"], c["method"], **kw)
    worst = 0.0
    for ours, theirs in zip([c["a"], c["b"], c["c"], c["d"]], [d.A, d.B, d.C, d.D]):
        ours = np.array(ours)
        e = np.max(np.abs(ours - theirs)) / np.max(np.abs(theirs))
        worst = max(worst, e)
        assert e <= 1e-12, (c["name"], ours, theirs, e)
    print(f"{c['name']}: {worst:.2e}")
"#;

#[test]
fn state_space_discretisation_is_python_controls_sample_system() {
    use controller::state_space::{discretise, DMatrix, Method};
    use std::f64::consts::TAU;
    let t = 1.0 / 20_000.0;
    // Six states on four axes, coupled, with fast (3 kHz) and slow (30 Hz) modes, one unstable.
    let a = DMatrix::from_row_slice(
        6,
        6,
        &[
            -2e4, 3e3, 0.0, 0.0, 10.0, 0.0, //
            -3e3, -2e4, 0.0, 0.0, 0.0, 0.0, //
            1.0, 0.0, -200.0, 50.0, 0.0, 0.0, //
            0.0, 0.0, -50.0, -200.0, 0.0, 0.0, //
            0.0, 0.0, 0.0, 0.0, 30.0, 0.0, //
            0.0, 5.0, 0.0, 0.0, 0.0, -1e3,
        ],
    );
    let b = DMatrix::from_fn(6, 4, |i, j| ((i + 2 * j) % 5) as f64 - 2.0);
    let c = DMatrix::from_fn(4, 6, |i, j| -0.3 * ((3 * i + j) % 4) as f64 + 0.1);
    let d = DMatrix::from_fn(4, 4, |i, j| if i == j { -0.8 } else { 0.05 });
    let json = |m: &DMatrix<f64>| (0..m.nrows()).map(|i| m.row(i).iter().copied().collect()).collect::<Vec<Vec<f64>>>();
    let mut cases = Vec::new();
    for (name, method, m, prewarp) in [
        ("tustin", "tustin", Method::Tustin { prewarp_rad_s: None }, None),
        (
            "tustin prewarped at 2 kHz",
            "tustin",
            Method::Tustin { prewarp_rad_s: Some(TAU * 2000.0) },
            Some(TAU * 2000.0),
        ),
        ("zoh", "zoh", Method::Zoh, None),
    ] {
        let s = discretise(&a, &b, &c, &d, t, m).unwrap();
        cases.push(serde_json::json!({
            "name": name, "method": method, "prewarp_rad_s": prewarp, "period_s": t,
            "A": json(&a), "B": json(&b), "C": json(&c), "D": json(&d),
            "a": json(&s.a), "b": json(&s.b), "c": json(&s.c), "d": json(&s.d),
        }));
    }
    let dir = TempDir::new("ss-python");
    let (file, script) = (dir.join("cases.json"), dir.join("check.py"));
    std::fs::write(&file, serde_json::to_string(&cases).unwrap()).unwrap();
    std::fs::write(&script, SS_CHECK).unwrap();
    let o = output_within(Command::new(venv().join("bin/python")).arg(&script).arg(&file), Duration::from_secs(300));
    eprintln!("{}", String::from_utf8_lossy(&o.stdout));
    assert_exit(&o, 0);
}

/// `state_space` without matrices is the design's PD on every axis: on the two-plane rotor
/// (planes of different designs), sampled, from rest, a small shock, its trace is
/// decentralised `pd`'s within round-off (1e-12 of each column's largest value), and in lockstep
/// the sampled run's byte for byte. Matrices sized for the planar model are refused on it,
/// naming the key and the 4 axes, exit 2, nothing written.
#[test]
fn state_space_runs_as_pd_on_the_two_plane_rotor_and_refuses_sizes_of_another() {
    common::controller_bin();
    let file = scene("two-plane-asymmetric-10g.toml");
    let dir = TempDir::new("ss-pd");
    let base = [
        "scene.duration_s=0.03",
        "shock[0].start_s=0.005",
        "shock[0].peak_g=0.5",
        "output.plots=false",
        "controller.damping_ratio=0.2",
        "controller.mode=sampled",
        "initial.unbalance_orbit=false",
    ];
    let run = |name: &str, extra: &[&str]| {
        let out = dir.join(name);
        let sets: Vec<&str> = base.iter().chain(extra).copied().collect();
        let o = output_within(&mut common::plant_run(&file, &out, &sets), Duration::from_secs(300));
        assert_exit(&o, 0);
        out
    };
    let pd = common::Csv::read(&run("pd", &["controller.law=pd"]).join("trace.csv"));
    let sampled = run("ss", &["controller.law=state_space"]);
    let ours = common::Csv::read(&sampled.join("trace.csv"));
    assert_eq!(pd.header, ours.header);
    let mut largest = 0.0f64;
    for name in &pd.header {
        let (a, b) = (pd.column(name), ours.column(name));
        let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let worst = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        assert!(worst <= 1e-12 * scale, "{name}: {worst:e} against a largest value of {scale:e}");
        largest = largest.max(worst / scale.max(f64::MIN_POSITIVE));
    }
    eprintln!("state_space against pd: largest difference {largest:.1e} of a column's largest value");
    let lockstep = run("ss-lockstep", &["controller.law=state_space", "controller.mode=lockstep"]);
    assert!(
        std::fs::read(sampled.join("trace.csv")).unwrap() == std::fs::read(lockstep.join("trace.csv")).unwrap(),
        "state_space in lockstep wrote another trace than in the plant's process"
    );
    common::refused(
        "ss-bad-axes",
        &file,
        &[
            "scene.duration_s=0.01",
            "output.plots=false",
            "controller.law=state_space",
            "controller.params.a=[[-1.0]]",
            "controller.params.b=[[1.0, 0.0]]",
            "controller.params.c=[[1.0], [0.0]]",
        ],
        &["law state_space", "controller.params.b", "is 1 × 2: expected 1 × 4", "4 axes"],
    );
}

/// python-control writes a law as JSON, as docs/guide/controllers.md shows (`json.dump` of the
/// `TransferFunction`'s and the `StateSpace`'s fields); `plant run` with `file = …` writes the
/// trace byte for byte that the same law written into `[controller.params]` writes, and so does
/// numpy's `.npz` of the same arrays (`savez`, and `savez_compressed` with A in Fortran order),
/// and scipy's `savemat` of them (MATLAB's level 5; the state-space law compressed, as MATLAB
/// writes it). A FIFO, a file of another format, a `.mat` of another level, cut short, short
/// of a variable or with one of another type or shape: refused naming the file and the
/// variable, exit 2, nothing written.
const WRITE_LAWS: &str = r#"
import json, sys
import numpy as np
import scipy.io
import control as ct
out = sys.argv[1]
wz, wp = 2 * np.pi * 150, 2 * np.pi * 1500
C = ct.tf([-1.2 / wz, -1.2], [1 / wp, 1])
json.dump({"num": C.num[0][0].tolist(), "den": C.den[0][0].tolist(), "dt": C.dt}, open(f"{out}/tf.json", "w"))
K = ct.ss(C)
K = ct.ss(np.kron(np.eye(2), K.A), np.kron(np.eye(2), K.B), np.kron(np.eye(2), K.C), np.kron(np.eye(2), K.D))
Kd = ct.sample_system(K, 5e-5, "zoh")
json.dump({"A": Kd.A.tolist(), "B": Kd.B.tolist(), "C": Kd.C.tolist(), "D": Kd.D.tolist(), "dt": Kd.dt},
          open(f"{out}/ss.json", "w"))
np.savez(f"{out}/tf.npz", num=C.num[0][0], den=C.den[0][0], dt=float(C.dt))
np.savez_compressed(f"{out}/ss.npz", A=np.asfortranarray(Kd.A), B=Kd.B, C=Kd.C, D=Kd.D, dt=Kd.dt)
# MATLAB's level 5 as scipy writes it: the tf uncompressed (dt the int 0 python-control holds),
# the ss compressed (as MATLAB's `save` writes by default).
scipy.io.savemat(f"{out}/tf.mat", {"num": C.num[0][0], "den": C.den[0][0], "dt": C.dt})
scipy.io.savemat(f"{out}/ss.mat", {"A": Kd.A, "B": Kd.B, "C": Kd.C, "D": Kd.D, "dt": Kd.dt}, do_compression=True)
# Refused: a missing variable, a variable of the wrong type, shape or number of dimensions.
scipy.io.savemat(f"{out}/no-den.mat", {"num": C.num[0][0], "dt": 0.0})
scipy.io.savemat(f"{out}/text-num.mat", {"num": "1, 2", "den": C.den[0][0]})
scipy.io.savemat(f"{out}/b-shape.mat", {"A": Kd.A, "B": Kd.B[:, :1], "C": Kd.C, "D": Kd.D, "dt": Kd.dt})
scipy.io.savemat(f"{out}/a-cube.mat", {"A": np.zeros((2, 2, 2)), "B": Kd.B, "C": Kd.C, "D": Kd.D, "dt": Kd.dt})
whole = open(f"{out}/ss.mat", "rb").read()
open(f"{out}/cut.mat", "wb").write(whole[:-10])
print(f"num = {C.num[0][0].tolist()}\nden = {C.den[0][0].tolist()}")
for k, m in zip("abcd", (Kd.A, Kd.B, Kd.C, Kd.D)):
    print(f"{k} = {m.tolist()}")
"#;

#[test]
fn a_law_python_control_wrote_runs_as_the_same_law_in_the_scene() {
    let dir = TempDir::new("law-files");
    std::fs::create_dir_all(dir.join("laws")).unwrap();
    let script = dir.join("write.py");
    std::fs::write(&script, WRITE_LAWS).unwrap();
    let o = output_within(
        Command::new(venv().join("bin/python")).arg(&script).arg(dir.join("laws")),
        Duration::from_secs(120),
    );
    assert_exit(&o, 0);
    let printed = String::from_utf8_lossy(&o.stdout).to_string();
    let line = |key: &str| {
        let l = printed.lines().find(|l| l.starts_with(&format!("{key} = "))).unwrap();
        format!("controller.params.{l}").replacen(" = ", "=", 1)
    };
    let file = scene("paper-10g.toml");
    let base = ["scene.duration_s=0.02", "output.plots=false", "controller.mode=sampled"];
    let run = |name: &str, extra: &[String]| {
        let out = dir.join(name);
        let sets: Vec<String> = base.iter().map(|s| s.to_string()).chain(extra.iter().cloned()).collect();
        let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
        let o = output_within(&mut common::plant_run(&file, &out, &sets), Duration::from_secs(300));
        assert_exit(&o, 0);
        std::fs::read(out.join("trace.csv")).unwrap()
    };
    let law = |name: &str| format!("controller.law={name}");
    let path = |name: &str| format!("controller.params.file=\"{}\"", dir.join("laws").join(name).display());
    let tf_file = run("tf-file", &[law("transfer_function"), path("tf.json")]);
    let tf_inline = run("tf-inline", &[law("transfer_function"), line("num"), line("den")]);
    assert!(tf_file == tf_inline, "transfer_function from python-control's JSON differs from the same in the scene");
    let tf_npz = run("tf-npz", &[law("transfer_function"), path("tf.npz")]);
    assert!(tf_npz == tf_inline, "transfer_function from numpy's .npz differs from the same in the scene");
    let ss_file = run("ss-file", &[law("state_space"), path("ss.json")]);
    let ss_inline = run(
        "ss-inline",
        &[
            law("state_space"),
            line("a"),
            line("b"),
            line("c"),
            line("d"),
            "controller.params.domain=\"z\"".into(),
            "controller.params.dt_s=5e-5".into(),
        ],
    );
    assert!(ss_file == ss_inline, "state_space from python-control's JSON differs from the same in the scene");
    let ss_npz = run("ss-npz", &[law("state_space"), path("ss.npz")]);
    assert!(ss_npz == ss_inline, "state_space from numpy's compressed .npz (A in Fortran order) differs");
    let tf_mat = run("tf-mat", &[law("transfer_function"), path("tf.mat")]);
    assert!(tf_mat == tf_inline, "transfer_function from scipy's savemat differs from the same in the scene");
    let ss_mat = run("ss-mat", &[law("state_space"), path("ss.mat")]);
    assert!(ss_mat == ss_inline, "state_space from scipy's compressed savemat differs from the same in the scene");
    // Refused: a FIFO (never waited on), a file of another format, a .mat of another level
    // (v7.3 is HDF5: its header as MATLAB writes it, the HDF5 signature at 512), cut short, short
    // of a variable, a variable of another type, shape or number of dimensions.
    for fifo in ["fifo.json", "fifo.mat"] {
        assert!(Command::new("mkfifo").arg(dir.join("laws").join(fifo)).status().unwrap().success());
    }
    std::fs::write(dir.join("laws").join("law.mat"), b"MATLAB 5.0 MAT-file, Platform: GLNXA64\x00\xff").unwrap();
    let mut v73 =
        b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Sun May 19 14:40:48 2024 HDF5 schema 1.00 .".to_vec();
    v73.resize(512, b' ');
    v73.extend_from_slice(b"\x89HDF\r\n\x1a\n\0\0\0\0");
    std::fs::write(dir.join("laws").join("v73.mat"), v73).unwrap();
    let tf = "controller.law=transfer_function";
    let ss = "controller.law=state_space";
    for (name, law, needles) in [
        ("fifo.json", tf, &["controller.params.file", "not a regular file"][..]),
        ("fifo.mat", ss, &["controller.params.file", "fifo.mat", "not a regular file"]),
        ("law.mat", tf, &["controller.params.file", "law.mat", "shorter than a .mat file's 128-byte header"]),
        ("v73.mat", tf, &["controller.params.file", "v73.mat", "v7.3 (HDF5)", "expected level 5", "-v7"]),
        ("cut.mat", ss, &["controller.params.file", "cut.mat", "element 5", "truncated"]),
        ("no-den.mat", tf, &["controller.params.file", "no-den.mat", "`den` is missing", "expected {\"num\""]),
        ("text-num.mat", tf, &["text-num.mat", "variable `num` is text", "expected a real matrix"]),
        ("b-shape.mat", ss, &["b-shape.mat", "`B` is 2 × 1: expected 2 × 2", "2 axes"]),
        ("a-cube.mat", ss, &["a-cube.mat", "variable `A` is 2 × 2 × 2", "expected a matrix"]),
    ] {
        let sets = ["scene.duration_s=0.01", "output.plots=false", "controller.mode=sampled", law, &path(name)];
        common::refused(&format!("law-file-{name}"), &file, &sets, needles);
    }
}

/// The closed loop in the linear regime against python-control: the paper scene, sampled, from
/// rest at (1, 0.5) µm (no unbalance, no shock, no contact, the linear force law, integrator
/// tolerance 1e-12), under a `transfer_function` PD with a derivative filter at 2 kHz (in `s`,
/// Tustin). python-control closes the exported discrete plant (`plant linear`, its hold and
/// delay states in) with its own `sample_system` of the same transfer
/// (`feedback(P, K, sign=+1)`, `forced_response` from the same start); the run's rotor state
/// (position and velocity, every sample) is its to 1e-9 of the largest value (measured 2.8e-14).
const KICK: &str = r#"
import sys, numpy as np, control as ct
num, den = [float(v) for v in sys.argv[3].split(",")], [float(v) for v in sys.argv[4].split(",")]
z = np.load(sys.argv[1] + "/linear.npz")
dt = float(z["dt"])
P = ct.ss(z["Ad"], z["Bd"], z["Cd"], z["Dd"], dt)
assert list(z["states_d"][:4]) == ["x", "y", "vx", "vy"], z["states_d"]
K = ct.ss(ct.sample_system(ct.tf(num, den), dt, "tustin"))
cl = ct.feedback(P, ct.append(K, K), sign=1)
tr = np.genfromtxt(sys.argv[2] + "/trace.csv", delimiter=",", names=True)
n = len(tr["t_s"])
x0 = np.zeros(cl.nstates); x0[0], x0[1] = 1e-6, 5e-7
r = ct.forced_response(cl, np.arange(n) * dt, np.zeros((2, n)), X0=x0, return_x=True)
for k, col in enumerate(["dx_m", "dy_m", "vx_m_s", "vy_m_s"]):
    e = np.max(np.abs(tr[col] - r.states[k])) / np.max(np.abs(r.states[k]))
    print(f"{col}: {e:.1e} of its largest value")
    assert e <= 1e-9, (col, e)
"#;

#[test]
fn a_transfer_function_loop_is_python_controls_forced_response_on_the_exported_plant() {
    let dir = TempDir::new("tf-kick");
    let file = scene("paper-10g.toml");
    let sets = ["controller.mode=sampled"];
    let lin = dir.join("lin");
    let mut cmd = plant_linear(&file, &lin, &[]);
    for s in sets {
        cmd.args(["--set", s]);
    }
    assert_exit(&output_within(&mut cmd, Duration::from_secs(60)), 0);
    // The PD of the scene (k_e = 1e6 N/m, here ξ = 0.2) with its derivative filtered at 2 kHz:
    // C(s) = −(k_p + k_d s/(τ s + 1)), k_p = (k_e + k_s)/(k_i A_s), k_d = 2 ξ √(k_e m)/(k_i A_s).
    let (kp, kd, tau) =
        ((1e6 + 4.32e5) / 5.4e6, 2.0 * 0.2 * (1e6f64 * 11.5).sqrt() / 5.4e6, 1.0 / (std::f64::consts::TAU * 2000.0));
    let (num, den) = ([-(kp * tau + kd), -kp], [tau, 1.0]);
    let list = |v: &[f64]| v.iter().map(|x| format!("{x:e}")).collect::<Vec<_>>().join(",");
    let run = dir.join("run");
    let all = [
        "scene.duration_s=0.02".to_string(),
        "output.plots=false".into(),
        "controller.law=transfer_function".into(),
        format!("controller.params.num=[{}]", list(&num)),
        format!("controller.params.den=[{}]", list(&den)),
        "rotor.eccentricity_um=0".into(),
        "initial.unbalance_orbit=false".into(),
        "initial.rotor_x_um=1.0".into(),
        "initial.rotor_y_um=0.5".into(),
        "shock[0].start_s=10".into(),
        "integrator.rtol=1e-12".into(),
        "integrator.atol=1e-18".into(),
        sets[0].into(),
    ];
    let all: Vec<&str> = all.iter().map(String::as_str).collect();
    let o = output_within(&mut common::plant_run(&file, &run, &all), Duration::from_secs(300));
    assert_exit(&o, 0);
    let script = dir.join("kick.py");
    std::fs::write(&script, KICK).unwrap();
    let o = output_within(
        Command::new(venv().join("bin/python")).arg(&script).arg(&lin).arg(&run).arg(list(&num)).arg(list(&den)),
        Duration::from_secs(120),
    );
    eprintln!("{}", String::from_utf8_lossy(&o.stdout));
    assert_exit(&o, 0);
}

/// Issue 39 item 4, the whole loop worked (scripts/design-loop/design_loop.py,
/// docs/guide/design-loop.md): the linear plant of two-plane-asymmetric-10g at 500 Hz out,
/// a decentralised lead-lag with a notch designed in python-control from `linear.npz` alone,
/// written as a `state_space` law file, graded by `plant assess` and run through the 10 G
/// shock (cut to 0.1 s). python-control's figures on the exported model (`stability_margins`
/// of each axis' loop with the others closed, the peak of `|S|` on 20 000 frequencies) against
/// the report card's: the phase margin within 1° of the computed (the law's linear form) and
/// of the measured one, the gain margin within 0.1 dB of the computed one (the measured one is
/// read between 24 points: 0.3 dB coarser), the measured `|S|` peak within 0.1 dB.
#[test]
fn the_worked_loop_designs_in_python_control_and_the_report_card_agrees() {
    let dir = TempDir::new("design-loop");
    let out = dir.join("loop");
    let o = output_within(
        Command::new(venv().join("bin/python"))
            .arg(workspace_root().join("scripts/design-loop/design_loop.py"))
            .arg(plant_bin())
            .arg(scene("two-plane-asymmetric-10g.toml"))
            .arg(&out)
            .arg("--quick"),
        Duration::from_secs(900),
    );
    eprintln!("{}", String::from_utf8_lossy(&o.stdout));
    assert_exit(&o, 0);
    let rows = common::read_json(&out.join("figures.json"));
    let rows = rows.as_array().expect("figures.json: a list");
    assert_eq!(rows.len(), 4, "one row per axis");
    let num = |v: &serde_json::Value, key: &str| v[key].as_f64().unwrap_or_else(|| panic!("{key} in {v}"));
    for r in rows {
        let (pc, computed, measured, peak) = (&r["python_control"], &r["computed"], &r["measured"], &r["peak"]);
        let axis = pc["axis"].as_str().unwrap_or_default().to_string();
        let pm = num(pc, "phase_margin_deg");
        assert!((pm - num(computed, "phase_margin_deg")).abs() < 1.0, "{axis}: PM {pm} against {computed}");
        assert!((pm - num(measured, "phase_margin_deg")).abs() < 1.0, "{axis}: PM {pm} against {measured}");
        let gm = num(pc, "gain_margin_db");
        assert!((gm - num(computed, "gain_margin_db")).abs() < 0.1, "{axis}: GM {gm} against {computed}");
        assert!((num(pc, "gain_margin_hz") / num(computed, "gain_margin_hz") - 1.0).abs() < 0.01, "{axis}: {r}");
        let s = num(pc, "s_peak_db");
        assert!((s - num(peak, "s_db")).abs() < 0.1, "{axis}: |S| peak {s} dB against {peak}");
        // The card's closed form of the state_space law (its discrete system on the exported
        // plant, every axis closed): python-control's peak on the same model, and its closed
        // loop's poles.
        let form = &r["closed_form"];
        assert_eq!(form["stable"], true, "{axis}: {r}");
        assert!((s - num(form, "s_db")).abs() < 0.01, "{axis}: |S| peak {s} dB against the closed form {form}");
        assert!((num(pc, "s_peak_hz") / num(form, "f_hz") - 1.0).abs() < 0.005, "{axis}: {r}");
        let pole = num(pc, "largest_pole");
        assert!((pole / num(form, "largest_pole") - 1.0).abs() < 1e-9, "{axis}: largest pole {pole} against {form}");
        // A design, not a stub: stable, zone A (|S| below 9.5 dB), a phase margin above 30°.
        assert!(s < 9.5 && pm > 30.0, "{axis}: {r}");
    }
    // The report card's open-loop Bode and Nyquist charts (item 3): the section and the chart,
    // the last axis' colour (y_B, the palette's fourth, 0xd6 0x27 0x28) drawn on it.
    let html = common::read_text(&out.join("assess/report.html"));
    assert!(html.contains("Open loop: Bode and Nyquist") && html.contains("open_loop_1.png"), "no open-loop section");
    let chart = common::Png::read(&out.join("assess/open_loop_1.png"));
    assert_eq!((chart.width, chart.height), (1800, 800));
    assert!(chart.count_in_plot([0xd6, 0x27, 0x28]) > 2000, "y_B's curve is not on the open-loop chart");
    let summary = common::read_json(&out.join("shock/summary.json"));
    assert_eq!(summary["status"], "completed", "{summary}");
    assert_eq!(summary["model"]["law"], "state_space", "{summary}");
}
