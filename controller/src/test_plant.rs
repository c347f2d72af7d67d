//! Test-only plant: the linearised bearing axis `m ẍ = k_i i + k_s x + f_ext`
//! discretised exactly over one controller period (zero-order hold), with the
//! command applied `d` samples late, as `plant`'s `sampled` mode does it.
//!
//! The transition matrix `Φ = e^{AT}` and input vector `Γ = ∫₀ᵀ e^{As} ds B`
//! are computed by a fine RK4 over one period (independently of the series
//! [`crate::discrete_pd`] designs with), so the tests check the design
//! against a separate discretisation.

use crate::law::{saturate, ControlLaw, LoopConstants, Sample};
use std::collections::VecDeque;

/// Exact ZOH discretisation of one axis: `[x, v]_{k+1} = Φ [x, v]_k + Γ F_k`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct AxisZoh {
    pub phi: [[f64; 2]; 2],
    pub gamma: [f64; 2],
}

impl AxisZoh {
    /// `m ẍ = F + k_s x` over period `t`, by RK4 with `steps` sub-steps.
    pub fn new(mass: f64, ks: f64, t: f64, steps: usize) -> Self {
        let a = [[0.0, 1.0], [ks / mass, 0.0]];
        let f =
            |y: [f64; 2], input: f64| [a[0][0] * y[0] + a[0][1] * y[1], a[1][0] * y[0] + a[1][1] * y[1] + input / mass];
        let run = |y0: [f64; 2], input: f64| {
            let h = t / steps as f64;
            let mut y = y0;
            for _ in 0..steps {
                let k1 = f(y, input);
                let k2 = f([y[0] + 0.5 * h * k1[0], y[1] + 0.5 * h * k1[1]], input);
                let k3 = f([y[0] + 0.5 * h * k2[0], y[1] + 0.5 * h * k2[1]], input);
                let k4 = f([y[0] + h * k3[0], y[1] + h * k3[1]], input);
                for i in 0..2 {
                    y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
                }
            }
            y
        };
        let c0 = run([1.0, 0.0], 0.0);
        let c1 = run([0.0, 1.0], 0.0);
        let gamma = run([0.0, 0.0], 1.0);
        Self { phi: [[c0[0], c1[0]], [c0[1], c1[1]]], gamma }
    }

    /// One period with force `force` held.
    pub fn step(&self, y: [f64; 2], force: f64) -> [f64; 2] {
        [
            self.phi[0][0] * y[0] + self.phi[0][1] * y[1] + self.gamma[0] * force,
            self.phi[1][0] * y[0] + self.phi[1][1] * y[1] + self.gamma[1] * force,
        ]
    }
}

/// The sampled loop around the plant.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rig {
    /// Controller period T (s).
    pub period: f64,
    /// Command delay d (samples).
    pub delay: usize,
    /// Amplifier current limit (A).
    pub limit: f64,
}

/// Runs `law` against both axes for `ticks` periods from `[x, v]` per axis;
/// `f_ext` is a constant external force per axis (N, e.g. `−m g` on y).
/// The coil holds the first command for the first `delay` ticks.
/// Returns the displacement per tick and the saturated command per tick.
pub(crate) fn simulate(
    law: &mut dyn ControlLaw,
    c: &LoopConstants,
    rig: Rig,
    init: [[f64; 2]; 2],
    f_ext: [f64; 2],
    ticks: usize,
) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
    let Rig { period, delay, limit } = rig;
    let zoh = AxisZoh::new(c.rotor_mass_kg, c.ks_n_per_m, period, 200);
    let mut y = init;
    let mut queue: VecDeque<[f64; 2]> = VecDeque::with_capacity(delay + 1);
    let mut xs = Vec::with_capacity(ticks);
    let mut cmds = Vec::with_capacity(ticks);
    for k in 0..ticks {
        let sensor_v = [c.sensor_gain_v_per_m * y[0][0], c.sensor_gain_v_per_m * y[1][0]];
        xs.push([y[0][0], y[1][0]]);
        let cmd = saturate(
            law.update(&Sample { seq: k as u64, t_s: k as f64 * period, sensor_v, ..Default::default() }),
            limit,
        );
        cmds.push(cmd);
        if k == 0 {
            // Before the first command arrives the coil holds it (the plant holds the bias).
            queue.extend(std::iter::repeat_n(cmd, delay));
        }
        queue.push_back(cmd);
        let applied = queue.pop_front().expect("queue holds at least the new command");
        for ax in 0..2 {
            y[ax] = zoh.step(y[ax], c.ki_n_per_a * applied[ax] + f_ext[ax]);
        }
    }
    (xs, cmds)
}

/// Damping ratio and damped frequency (rad/s) of a free decay, from the
/// positive peaks (log decrement over the peaks after `skip_s`) and the
/// interpolated upward zero crossings.
pub(crate) fn decay_measure(x: &[f64], period: f64, skip_s: f64) -> (f64, f64) {
    let start = (skip_s / period) as usize;
    let mut crossings = Vec::new();
    for k in start.max(1)..x.len() {
        if x[k - 1] < 0.0 && x[k] >= 0.0 {
            let frac = -x[k - 1] / (x[k] - x[k - 1]);
            crossings.push((k as f64 - 1.0 + frac) * period);
        }
    }
    assert!(crossings.len() >= 3, "too few cycles to measure: {}", crossings.len());
    let mut peaks = Vec::new();
    for w in crossings.windows(2) {
        let (a, b) = ((w[0] / period) as usize, (w[1] / period) as usize);
        peaks.push(x[a..=b].iter().cloned().fold(f64::MIN, f64::max));
    }
    let cycles = (peaks.len() - 1) as f64;
    let delta = (peaks[0] / peaks[peaks.len() - 1]).ln() / cycles;
    let zeta = delta / (4.0 * std::f64::consts::PI.powi(2) + delta * delta).sqrt();
    let t_cycle = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
    (zeta, 2.0 * std::f64::consts::PI / t_cycle)
}
