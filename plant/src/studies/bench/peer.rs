//! The peer spec: everything an independent implementation of the plant's
//! derivative needs (SI parameters, continuous PD gains, the shock programme,
//! the initial state, the tick grid), plus seeded random states with the Rust
//! derivative at each, so that the peer can be checked to rounding. The Python
//! peer in `bench/peer/` reads it (format `amb-tdb-peer-spec/1`).
//!
//! Only scenes whose shocks are all double half-sines are accepted (the peer
//! implements that pulse only), with `controller.mode = "continuous"`.

use crate::config::{ControlMode, Rotor, Scene};
use crate::initial::initial_state;
use crate::model::{ix, Control, Model, State, N};
use crate::rng::SplitMix64;
use anyhow::bail;
use serde_json::{json, Value};
use shock_table::Pulse;

/// Names of the state components, in order.
pub const STATE_NAMES: [&str; N] =
    ["x_r", "y_r", "theta_r", "x_b", "y_b", "theta_b", "vx_r", "vy_r", "w_r", "vx_b", "vy_b", "w_b"];

/// The helpers this module draws states with, on the testbed's one generator.
trait Draw {
    /// Uniform in [lo, hi).
    fn range(&mut self, lo: f64, hi: f64) -> f64;
    /// Log-uniform in [lo, hi), lo > 0.
    fn log_range(&mut self, lo: f64, hi: f64) -> f64;
    /// Random sign.
    fn sign(&mut self) -> f64;
    fn below(&mut self, n: usize) -> usize;
}

impl Draw for SplitMix64 {
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        self.uniform([lo, hi])
    }
    fn log_range(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + (hi.ln() - lo.ln()) * self.unit()).exp()
    }
    fn sign(&mut self) -> f64 {
        if self.unit() < 0.5 {
            -1.0
        } else {
            1.0
        }
    }
    fn below(&mut self, n: usize) -> usize {
        ((self.unit() * n as f64) as usize).min(n - 1)
    }
}

/// Sample states: a mix of levitated, rotor on the race, race on several
/// balls, slip and race speed near zero, saturated current, and anything.
fn sample_states(scene: &Scene, y0: &State, n: usize, seed: u64) -> Vec<(String, f64, State)> {
    // The planar model's bearing (spec refuses any other).
    let p = scene.plane(0);
    let mut rng = SplitMix64::new(seed);
    let r0 = p.contact.gap;
    let rcl = p.balls.clearance;
    let (rr, rin) = (p.contact.rotor_radius, p.contact.bore_radius);
    let omega = p.speed;
    let vs = p.contact.friction.v_static;
    // Times: before, inside each half-sine of each shock, after, and on the segment boundaries.
    let mut marks = vec![0.0];
    for s in &scene.base.shocks {
        if let Pulse::DoubleHalfSine(d) = s.pulse {
            marks.extend([s.start, s.start + d.t1, s.start + d.t2]);
        }
    }
    marks.sort_by(f64::total_cmp);
    let t_end = scene.duration.max(1.5 * marks[marks.len() - 1]);
    let time = |rng: &mut SplitMix64| -> f64 {
        let u = rng.unit();
        if u < 0.1 {
            // Exactly on a segment boundary.
            marks[rng.below(marks.len())]
        } else if u < 0.7 && marks.len() > 1 {
            // Inside one of the intervals between boundaries (before the shock, inside a half-sine).
            let k = 1 + rng.below(marks.len() - 1);
            rng.range(marks[k - 1], marks[k])
        } else {
            rng.range(0.0, t_end)
        }
    };
    let kinds = ["levitated", "rotor_on_race", "race_on_balls", "low_slip", "saturated", "random"];
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        let kind = kinds[k % kinds.len()];
        let mut y = *y0;
        let t = time(&mut rng);
        y[ix::TR] = rng.range(-50.0, 5000.0);
        y[ix::WR] = omega * rng.range(0.7, 1.02);
        y[ix::TB] = rng.range(-1000.0, 1000.0);
        y[ix::WB] = rng.sign() * rng.log_range(1e-3, 3000.0);
        // Race position: on the balls by up to `depth`, or inside the clearance.
        let race = |rng: &mut SplitMix64, depth: f64| -> [f64; 2] {
            let a = rng.range(-std::f64::consts::PI, std::f64::consts::PI);
            let r = if rng.unit() < 0.2 { rng.range(0.0, rcl) } else { rcl + rng.log_range(1e-10, depth) };
            [r * a.cos(), r * a.sin()]
        };
        match kind {
            "levitated" => {
                let a = rng.range(-std::f64::consts::PI, std::f64::consts::PI);
                let r = rng.range(0.0, 0.6 * r0);
                y[ix::XR] = r * a.cos();
                y[ix::YR] = r * a.sin();
                y[ix::VXR] = rng.range(-0.05, 0.05);
                y[ix::VYR] = rng.range(-0.05, 0.05);
                y[ix::XB] = rng.range(-0.2e-6, 0.2e-6);
                y[ix::YB] = y0[ix::YB] + rng.range(-0.2e-6, 0.2e-6);
                y[ix::VXB] = rng.range(-1e-3, 1e-3);
                y[ix::VYB] = rng.range(-1e-3, 1e-3);
                if rng.unit() < 0.5 {
                    y[ix::WB] = rng.range(-2.0, 2.0);
                }
            }
            "rotor_on_race" | "low_slip" | "saturated" => {
                let eps = race(&mut rng, if kind == "saturated" { 3e-5 } else { 1e-5 });
                let a = rng.range(-std::f64::consts::PI, std::f64::consts::PI);
                let depth = if kind == "saturated" { rng.log_range(1e-7, 3e-5) } else { rng.log_range(1e-10, 3e-5) };
                let d = r0 + depth;
                let (n, tdir) = ([a.cos(), a.sin()], [-a.sin(), a.cos()]);
                y[ix::XB] = eps[0];
                y[ix::YB] = eps[1];
                y[ix::XR] = eps[0] + d * n[0];
                y[ix::YR] = eps[1] + d * n[1];
                let vmax = if kind == "saturated" { 8.0 } else { 0.5 };
                let (vn, vt) = (rng.range(-vmax, vmax), rng.range(-vmax, vmax));
                y[ix::VXB] = rng.range(-0.3, 0.3);
                y[ix::VYB] = rng.range(-0.3, 0.3);
                y[ix::VXR] = y[ix::VXB] + vn * n[0] + vt * tdir[0];
                y[ix::VYR] = y[ix::VYB] + vn * n[1] + vt * tdir[1];
                if kind == "low_slip" {
                    // Race speed such that the slip is inside (or near) the smoothed zone ±v_s.
                    let slip = rng.range(-2.0 * vs, 2.0 * vs);
                    y[ix::WB] = (vt + y[ix::WR] * rr - slip) / rin;
                } else if rng.unit() < 0.3 {
                    y[ix::WB] = rng.range(-1.5, 1.5);
                }
            }
            "race_on_balls" => {
                let eps = race(&mut rng, 2e-5);
                y[ix::XB] = eps[0];
                y[ix::YB] = eps[1];
                y[ix::VXB] = rng.range(-0.5, 0.5);
                y[ix::VYB] = rng.range(-0.5, 0.5);
                let a = rng.range(-std::f64::consts::PI, std::f64::consts::PI);
                let r = rng.range(0.0, 1.2 * r0);
                y[ix::XR] = eps[0] + r * a.cos();
                y[ix::YR] = eps[1] + r * a.sin();
                y[ix::VXR] = rng.range(-0.5, 0.5);
                y[ix::VYR] = rng.range(-0.5, 0.5);
            }
            _ => {
                for i in [ix::XR, ix::YR] {
                    y[i] = rng.range(-1.5 * (r0 + rcl), 1.5 * (r0 + rcl));
                }
                for i in [ix::XB, ix::YB] {
                    y[i] = rng.range(-1.5 * rcl, 1.5 * rcl);
                }
                for i in [ix::VXR, ix::VYR, ix::VXB, ix::VYB] {
                    y[i] = rng.range(-3.0, 3.0);
                }
            }
        }
        out.push((kind.to_string(), t, y));
    }
    out
}

/// The spec of a scene with `samples` random states (seeded) and, optionally, the
/// per-component scale of the absolute tolerances (`atol_i = rtol · atol_scale_i`).
pub fn spec(scene: &Scene, samples: usize, seed: u64, atol_scale: Option<[f64; N]>) -> anyhow::Result<Value> {
    if scene.controller.mode != ControlMode::Continuous {
        bail!("peer spec: controller.mode must be \"continuous\" (the peer evaluates the PD inside the derivative)");
    }
    let Rotor::Planar(params) = &scene.rotor else {
        bail!("peer spec: the peer implements the planar model (rotor.model = \"planar\")");
    };
    let gains = crate::run::plane_gains(scene)?[0];
    let mut shocks = Vec::new();
    for (i, s) in scene.base.shocks.iter().enumerate() {
        let Pulse::DoubleHalfSine(d) = s.pulse else {
            bail!(
                "peer spec: shock[{i}] is not a double half-sine ({:?}); the peer implements only that pulse",
                s.pulse
            )
        };
        shocks.push(json!({
            "kind": "double_half_sine",
            "start_s": s.start,
            "direction_rad": s.direction(),
            "unit": s.unit(),
            "a1": d.a1,
            "a2": d.a2,
            "t1": d.t1,
            "t2": d.t2,
        }));
    }
    let y0 = initial_state(scene, params);
    let model = Model {
        params: params.clone(),
        base: scene.base.clone(),
        control: Control::Continuous(gains),
        race_parked: false,
    };
    let samples_json: Vec<Value> = sample_states(scene, &y0, samples, seed)
        .into_iter()
        .chain(std::iter::once(("initial".to_string(), 0.0, y0)))
        .map(|(kind, t, y)| {
            let e = model.evaluate(t, &y);
            json!({
                "kind": kind,
                "t": t,
                "y": y,
                "dy": e.dy,
                "current_a": e.current,
                "contact_normal_n": e.contact.normal,
                "balls_loaded": e.balls.loaded,
            })
        })
        .collect();
    let mut spec = json!({
        "format": "amb-tdb-peer-spec/1",
        "scene": scene.name,
        "state_names": STATE_NAMES,
        "duration_s": scene.duration,
        "controller_period_s": scene.controller.period,
        "params": serde_json::to_value(params)?,
        "ball_count": params.balls.count(),
        "gains": {
            "kp": gains.kp,
            "kd": gains.kd,
            "amp_gain_a_per_v": gains.amp_gain_a_per_v,
            "bias_a": gains.bias_a,
        },
        "current_limit_a": params.current_limit,
        "shocks": shocks,
        "y0": y0,
        "samples_seed": seed,
        "samples": samples_json,
    });
    if let Some(scale) = atol_scale {
        spec["atol_scale"] = json!(scale);
    }
    Ok(spec)
}
