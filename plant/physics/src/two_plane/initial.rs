//! The levitated steady state a two-plane run starts from: the rotor on its linear unbalance
//! response (static and couple unbalance, [`super::linear`], with each plane's continuous PD of
//! the levitation design), each race at rest on its balls under gravity, the rotor at rated
//! speed.

use super::linear::{LinearRotor, PlaneLoop};
use super::{ix, Params, State, N};
use crate::initial::race_sag;
use nalgebra::Complex;

/// How a two-plane run starts, besides the physical parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InitialConditions {
    /// Start on the linear unbalance response of the levitation design (else centred).
    pub unbalance_orbit: bool,
    /// Angle of the static unbalance at t = 0 (rad): the rotor's spin angle θ(0).
    pub unbalance_phase: f64,
    /// Closed-loop stiffness k_e of each plane's levitation design (N/m), > 0.
    pub stiffness: f64,
    /// Closed-loop damping ratio ξ_e of each plane's design, on its load share.
    pub damping_ratio: f64,
    /// Whether each plane's bias current carries its share of the weight; if not, the rotor
    /// starts where the loops hold it under gravity.
    pub gravity_bias: bool,
    /// Offset added to the rotor axis at the centre of mass (m), x then y.
    pub rotor_offset: [f64; 2],
    /// Offset added to the slopes a, b (rad).
    pub slope_offset: [f64; 2],
}

/// The linear loops of the levitation design: `k_e` on each plane's sensor, `c = 2 ξ_e √(k_e m_i)`
/// with `m_i` the plane's load share, the bearing's own `k_s`.
pub fn design_loops(p: &Params, stiffness: f64, damping_ratio: f64) -> LinearRotor {
    let plane = |i: usize| {
        let pl = &p.planes[i];
        PlaneLoop {
            station: pl.station,
            sensor: pl.sensor,
            stiffness,
            damping: 2.0 * damping_ratio * (stiffness * p.load_share(i)).sqrt(),
            negative_stiffness: pl.params.loop_constants.ks_n_per_m,
        }
    };
    LinearRotor {
        mass: p.rotor.mass,
        transverse_inertia: p.rotor.transverse_inertia,
        polar_inertia: p.rotor.polar_inertia,
        planes: [plane(0), plane(1)],
    }
}

/// The initial state for parameters `p` and the conditions `ic`.
pub fn initial_state(p: &Params, ic: &InitialConditions) -> State {
    let mut y = [0.0; N];
    let loops = design_loops(p, ic.stiffness, ic.damping_ratio);
    let r = &p.rotor;
    let w = r.speed;
    let phase = ic.unbalance_phase;
    if ic.unbalance_orbit {
        // Static unbalance M e ω² at the centre of mass, couple κ ω² at φ_c, both turning with θ.
        let force = Complex::new(r.mass * r.eccentricity * w * w, 0.0);
        let moment = Complex::from_polar(r.couple_moment() * w * w, r.couple_phase);
        let [zeta, phi] = loops.forced_response(w, force, moment);
        let turn = Complex::from_polar(1.0, phase);
        let (zeta, phi) = (zeta * turn, phi * turn);
        y[ix::X] = zeta.re;
        y[ix::Y] = zeta.im;
        // The velocity is j ω times the position.
        y[ix::VX] = -zeta.im * w;
        y[ix::VY] = zeta.re * w;
        if phi != Complex::new(0.0, 0.0) {
            y[ix::SX] = phi.re;
            y[ix::SY] = phi.im;
            y[ix::VSX] = -phi.im * w;
            y[ix::VSY] = phi.re * w;
        }
    }
    if !ic.gravity_bias {
        let sag = loops.static_deflection(r.mass * p.gravity);
        y[ix::Y] -= sag.x;
        y[ix::SY] -= sag.y;
    }
    y[ix::X] += ic.rotor_offset[0];
    y[ix::Y] += ic.rotor_offset[1];
    y[ix::SX] += ic.slope_offset[0];
    y[ix::SY] += ic.slope_offset[1];
    y[ix::TR] = phase;
    y[ix::WR] = w;
    for (plane, x) in p.planes.iter().zip(ix::RACE) {
        y[x + 1] = race_sag(&plane.params);
    }
    y
}
