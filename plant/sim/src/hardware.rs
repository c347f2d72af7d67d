//! The parts of the loop between the wire and the physics (docs/MODEL.md §12): each axis's
//! amplifier and coil ([`plant_physics::amplifier`]) and the sensor's front end (bandwidth,
//! runout, range: [`crate::sensor::FrontEnd`]). All off by default: a scene without them runs
//! the bare model, its arithmetic untouched.
//!
//! When one is on, [`Wired`] wraps the rotor model (planar or two-plane) and appends the
//! hardware's states to the model's, `EXTRA` numbers after the model's `N`:
//!
//! ```text
//! [ model (N) | coil currents i (4) | PI integrals q (4) | sensor filter z₀ (4) | ż₀ (4) | t_sat ]
//! ```
//!
//! one per axis in the order x_A, y_A, x_B, y_B (a planar model uses the first two), and the
//! time spent with any amplifier at its voltage limit. With unipolar amplifiers (MODEL.md §12.3)
//! each axis has two magnets, each with its own coil and amplifier: the coil states above are
//! then the + side's magnets', and the − side's follow, `EXTRA_UNIPOLAR` numbers in all:
//!
//! ```text
//! [ … as above (EXTRA) … | − side's currents i₋ (4) | − side's PI integrals q₋ (4) ]
//! ```
//!
//! (the bipolar layout is kept as it was, so that its runs step the very same state). The
//! controller's command (held over the macro step, or the continuous PD) is the current
//! reference; the model is evaluated with the coils' real currents. The sensor reads the
//! filter's output (with the runout in its input), or the displacement plus the runout when the
//! sensor is ideal, clipped to the range. The continuous PD reads that signal too, and
//! differentiates it as an analog controller does: the filter's output rate (or the
//! displacement's and the runout's), 0 while the range clips; the noise and the ADC are the
//! sampled controller's.

pub use crate::config::hardware::Hardware;
use crate::machine::{Machine, PlaneState};
use crate::model::{Control, Params, Release};
use crate::rows::{Record, RowHw, RowMagnets};
use crate::sensor::{runout, runout_rate};
use plant_physics::integrate::System;
use std::cell::RefCell;

/// Hardware states appended to the model's (bipolar amplifiers, or none).
pub const EXTRA: usize = 17;

/// Hardware states appended to the model's with unipolar amplifiers: the − side's magnets'
/// currents and integrals after [`EXTRA`].
pub const EXTRA_UNIPOLAR: usize = EXTRA + 8;

/// Offsets of the hardware states after the model's.
mod ex {
    /// Coil currents (A), 4 axes.
    pub const CURRENT: usize = 0;
    /// PI integrals (V), 4 axes.
    pub const INTEGRAL: usize = 4;
    /// Sensor filter outputs (m), 4 axes.
    pub const FILTER: usize = 8;
    /// Sensor filter output rates (m/s), 4 axes (second order).
    pub const FILTER_RATE: usize = 12;
    /// Time with any amplifier at its voltage limit (s).
    pub const SATURATED: usize = 16;
    /// Unipolar: the − side's magnets' coil currents (A), 4 axes (the + side's are `CURRENT`).
    pub const MINUS_CURRENT: usize = 17;
    /// Unipolar: the − side's magnets' PI integrals (V), 4 axes.
    pub const MINUS_INTEGRAL: usize = 21;
}

/// Absolute tolerances of the hardware states: currents `1e-6` A, integrals `1e-4` V, the
/// filter like the positions `p` (m) and velocities `v` (m/s), the saturation time 1 s (it
/// never limits the step); the unipolar layout's (the first [`EXTRA`] are the bipolar's).
pub fn atol(p: f64, v: f64) -> [f64; EXTRA_UNIPOLAR] {
    let mut a = [0.0; EXTRA_UNIPOLAR];
    a[ex::CURRENT..ex::CURRENT + 4].fill(1e-6);
    a[ex::INTEGRAL..ex::INTEGRAL + 4].fill(1e-4);
    a[ex::FILTER..ex::FILTER + 4].fill(p);
    a[ex::FILTER_RATE..ex::FILTER_RATE + 4].fill(v);
    a[ex::SATURATED] = 1.0;
    a[ex::MINUS_CURRENT..ex::MINUS_CURRENT + 4].fill(1e-6);
    a[ex::MINUS_INTEGRAL..ex::MINUS_INTEGRAL + 4].fill(1e-4);
    a
}

/// Each axis's coil voltages at one instant (V), x_A, y_A, x_B, y_B.
#[derive(Clone, Copy, Debug, Default)]
struct Volts {
    /// The bipolar coil's; unipolar: the differential `(v₊ − v₋)/2`.
    coil: [f64; 4],
    /// Unipolar: the + side's magnets'.
    plus: [f64; 4],
    /// Unipolar: the − side's magnets'.
    minus: [f64; 4],
}

/// A rotor model `M` on `N` states with the hardware's states appended: a model on `NA = N +
/// EXTRA` states, `N + EXTRA_UNIPOLAR` with unipolar amplifiers (module doc).
pub struct Wired<M, const N: usize, const NA: usize> {
    /// The model as the loop configures it (parameters, parked races).
    inner: M,
    /// A copy evaluated with the coils' currents (the evaluation sets its control).
    work: RefCell<M>,
    /// Each plane's command: the current reference.
    reference: [Control; 2],
    hw: Hardware,
}

/// The model's part and the hardware's part of an extended state (the hardware's in the
/// unipolar layout, zero past the state's end).
#[inline]
fn split<const N: usize, const NA: usize>(y: &[f64; NA]) -> ([f64; N], [f64; EXTRA_UNIPOLAR]) {
    let mut a = [0.0; N];
    let mut b = [0.0; EXTRA_UNIPOLAR];
    a.copy_from_slice(&y[..N]);
    b[..NA - N].copy_from_slice(&y[N..]);
    (a, b)
}

impl<M: Machine<N> + Clone, const N: usize, const NA: usize> Wired<M, N, NA> {
    /// Wraps `model` whose controls are `controls` (one per plane, as the loop set them).
    pub fn new(model: M, controls: [Control; 2], hw: Hardware) -> Self {
        let extra = if hw.is_unipolar() { EXTRA_UNIPOLAR } else { EXTRA };
        assert_eq!(NA, N + extra, "a wired model has the model's states and EXTRA (EXTRA_UNIPOLAR) more");
        Self { work: RefCell::new(model.clone()), inner: model, reference: controls, hw }
    }

    /// The extended initial state of the model's `y0`: the sensor filter at rest at its input,
    /// each coil at rest at its reference.
    pub fn initial(&self, y0: &[f64; N]) -> [f64; NA] {
        let mut y = [0.0; NA];
        y[..N].copy_from_slice(y0);
        for i in 0..M::PLANES {
            for (j, &measured) in self.raw_signal(y0, i).iter().enumerate() {
                y[N + ex::FILTER + 2 * i + j] = measured;
            }
        }
        for i in 0..M::PLANES {
            let reference = self.reference_current(&y, i);
            for (j, &current) in reference.iter().enumerate() {
                let ax = 2 * i + j;
                match (&self.hw.amplifiers[i], &self.hw.unipolar[i]) {
                    (Some(a), None) => {
                        y[N + ex::CURRENT + ax] = current;
                        y[N + ex::INTEGRAL + ax] = a.steady_integral(current);
                    }
                    (Some(a), Some(u)) => {
                        let (plus, minus) = ((u.bias + current).max(0.0), (u.bias - current).max(0.0));
                        y[N + ex::CURRENT + ax] = plus;
                        y[N + ex::INTEGRAL + ax] = a.steady_integral(plus);
                        y[N + ex::MINUS_CURRENT + ax] = minus;
                        y[N + ex::MINUS_INTEGRAL + ax] = a.steady_integral(minus);
                    }
                    (None, _) => {}
                }
            }
        }
        y
    }

    /// Plane `i`'s current reference in the extended state `y`: the held command, or the
    /// continuous PD on what the sensor's front end reads ([`Machine::pd_current`]).
    #[inline]
    fn reference_current(&self, y: &[f64; NA], i: usize) -> [f64; 2] {
        match self.reference[i] {
            Control::Held(c) => c,
            Control::Continuous(gains) => Machine::<NA>::pd_current(self, &gains, y, i),
            // The sensitivity measurement's excitation is not added behind an amplifier or a
            // sensor front end: `plant assess` refuses a scene with them (not assessed yet).
            Control::ContinuousExcited(gains, _) => Machine::<NA>::pd_current(self, &gains, y, i),
            // The run loop commands currents, never magnets; the differential current if it did.
            Control::Magnets { plus, minus } => [(plus[0] - minus[0]) * 0.5, (plus[1] - minus[1]) * 0.5],
        }
    }

    /// Plane `i`'s sensed displacement with the runout, before the filter and the range (m).
    #[inline]
    fn raw_signal(&self, y: &[f64; N], i: usize) -> [f64; 2] {
        let d = self.inner.sensed(y, i);
        if self.hw.front_end.runout.is_empty() {
            return d;
        }
        let theta = self.inner.spin(y).0;
        [
            d[0] + runout(&self.hw.front_end.runout, 2 * i, theta),
            d[1] + runout(&self.hw.front_end.runout, 2 * i + 1, theta),
        ]
    }

    /// Sets the working copy's controls to the coils' currents of the extended state `ye`, whose
    /// parts are `(y, x)` (the references where a plane has no amplifier; each magnet's current
    /// where it has unipolar ones), writing the hardware's rates into `dx` and each coil's
    /// voltage into `volts`.
    #[inline]
    fn apply(
        &self,
        m: &mut M,
        ye: &[f64; NA],
        (y, x): (&[f64; N], &[f64; EXTRA_UNIPOLAR]),
        dx: &mut [f64; EXTRA_UNIPOLAR],
        volts: &mut Volts,
    ) {
        let mut saturated = false;
        for i in 0..M::PLANES {
            let reference = self.reference_current(ye, i);
            let control = match (&self.hw.amplifiers[i], &self.hw.unipolar[i]) {
                (None, _) => Control::Held(reference),
                (Some(a), None) => {
                    let velocity = m.bearing_velocity(y, i);
                    for j in 0..2 {
                        let ax = 2 * i + j;
                        let r = a.rates(reference[j], x[ex::CURRENT + ax], x[ex::INTEGRAL + ax], velocity[j]);
                        dx[ex::CURRENT + ax] = r.current_rate;
                        dx[ex::INTEGRAL + ax] = r.integral_rate;
                        volts.coil[ax] = r.voltage;
                        saturated |= r.saturated;
                    }
                    Control::Held([x[ex::CURRENT + 2 * i], x[ex::CURRENT + 2 * i + 1]])
                }
                (Some(a), Some(u)) => {
                    // Each magnet's own loop: the + side's reference i_0 + i, its motional
                    // voltage (k_b/2) ẋ (the rotor closing its gap at ẋ); the − side's i_0 − i
                    // and −(k_b/2) ẋ (MODEL.md §12.3: the pair absorbs k_b i ẋ, as one coil).
                    let velocity = m.bearing_velocity(y, i);
                    let (mut plus, mut minus) = ([0.0; 2], [0.0; 2]);
                    for j in 0..2 {
                        let ax = 2 * i + j;
                        let (ip, qp) = (x[ex::CURRENT + ax], x[ex::INTEGRAL + ax]);
                        let (im, qm) = (x[ex::MINUS_CURRENT + ax], x[ex::MINUS_INTEGRAL + ax]);
                        let emf = 0.5 * a.back_emf * velocity[j];
                        let p = a.unipolar_rates(u.bridge, u.bias + reference[j], ip, qp, emf);
                        let n = a.unipolar_rates(u.bridge, u.bias - reference[j], im, qm, -emf);
                        dx[ex::CURRENT + ax] = p.current_rate;
                        dx[ex::INTEGRAL + ax] = p.integral_rate;
                        dx[ex::MINUS_CURRENT + ax] = n.current_rate;
                        dx[ex::MINUS_INTEGRAL + ax] = n.integral_rate;
                        volts.plus[ax] = p.voltage;
                        volts.minus[ax] = n.voltage;
                        volts.coil[ax] = (p.voltage - n.voltage) * 0.5;
                        saturated |= p.saturated || n.saturated;
                        // A current the integrator left a little below zero is none.
                        plus[j] = ip.max(0.0);
                        minus[j] = im.max(0.0);
                    }
                    Control::Magnets { plus, minus }
                }
            };
            m.set_control(i, control);
            if let Some(lp) = self.hw.front_end.low_pass {
                let u = self.raw_signal(y, i);
                for (j, &u) in u.iter().enumerate() {
                    let ax = 2 * i + j;
                    let r = lp.rates(u, [x[ex::FILTER + ax], x[ex::FILTER_RATE + ax]]);
                    dx[ex::FILTER + ax] = r[0];
                    dx[ex::FILTER_RATE + ax] = r[1];
                }
            }
        }
        dx[ex::SATURATED] = if saturated { 1.0 } else { 0.0 };
    }

    /// The working copy with its controls set for the extended state `y`.
    fn synced(&self, y: &[f64; NA]) -> (std::cell::RefMut<'_, M>, [f64; N], Volts) {
        let (iy, x) = split::<N, NA>(y);
        let mut m = self.work.borrow_mut();
        let (mut dx, mut volts) = ([0.0; EXTRA_UNIPOLAR], Volts::default());
        self.apply(&mut m, y, (&iy, &x), &mut dx, &mut volts);
        (m, iy, volts)
    }
}

impl<M: Machine<N> + Clone, const N: usize, const NA: usize> System<NA> for Wired<M, N, NA> {
    #[inline]
    fn rhs(&self, t: f64, y: &[f64; NA], dy: &mut [f64; NA]) {
        let (iy, x) = split::<N, NA>(y);
        let mut m = self.work.borrow_mut();
        let (mut dx, mut volts) = ([0.0; EXTRA_UNIPOLAR], Volts::default());
        self.apply(&mut m, y, (&iy, &x), &mut dx, &mut volts);
        let mut idy = [0.0; N];
        m.rhs(t, &iy, &mut idy);
        dy[..N].copy_from_slice(&idy);
        dy[N..].copy_from_slice(&dx[..NA - N]);
    }
}

impl<M: Machine<N> + Clone, const N: usize, const NA: usize> Machine<NA> for Wired<M, N, NA> {
    const PLANES: usize = M::PLANES;

    fn bearing(&self, i: usize) -> &Params {
        self.inner.bearing(i)
    }

    fn set_control(&mut self, i: usize, control: Control) {
        self.reference[i] = control;
    }

    fn sensed(&self, y: &[f64; NA], i: usize) -> [f64; 2] {
        let fe = &self.hw.front_end;
        let d = if fe.low_pass.is_some() {
            [y[N + ex::FILTER + 2 * i], y[N + ex::FILTER + 2 * i + 1]]
        } else {
            self.raw_signal(&split::<N, NA>(y).0, i)
        };
        [fe.clip(d[0]), fe.clip(d[1])]
    }

    fn sensed_rate(&self, y: &[f64; NA], i: usize) -> [f64; 2] {
        let (iy, x) = split::<N, NA>(y);
        let v = self.inner.sensed_rate(&iy, i);
        let fe = &self.hw.front_end;
        if !fe.is_on() {
            return v;
        }
        let u = self.raw_signal(&iy, i);
        let (theta, speed) = self.inner.spin(&iy);
        std::array::from_fn(|j| {
            let ax = 2 * i + j;
            let u_rate = if fe.runout.is_empty() { v[j] } else { v[j] + runout_rate(&fe.runout, ax, theta, speed) };
            fe.rate(u[j], u_rate, [x[ex::FILTER + ax], x[ex::FILTER_RATE + ax]])
        })
    }

    fn parked(&self, i: usize) -> bool {
        self.inner.parked(i)
    }

    fn set_parked(&mut self, i: usize, parked: bool) {
        self.inner.set_parked(i, parked);
        self.work.get_mut().set_parked(i, parked);
    }

    fn race_clear(&self, t0: f64, h: f64, y: &[f64; NA], i: usize) -> bool {
        let (m, iy, _) = self.synced(y);
        m.race_clear(t0, h, &iy, i)
    }

    fn park_race(&self, y: &mut [f64; NA], i: usize) {
        let (mut iy, _) = split::<N, NA>(y);
        self.inner.park_race(&mut iy, i);
        y[..N].copy_from_slice(&iy);
    }

    fn release_race(&self, t: f64, y: &mut [f64; NA], i: usize, release: Release) {
        let (mut iy, _) = split::<N, NA>(y);
        self.inner.release_race(t, &mut iy, i, release);
        y[..N].copy_from_slice(&iy);
    }

    fn radii(&self, y: &[f64; NA], i: usize) -> (f64, f64) {
        self.inner.radii(&split::<N, NA>(y).0, i)
    }

    fn spin(&self, y: &[f64; NA]) -> (f64, f64) {
        self.inner.spin(&split::<N, NA>(y).0)
    }

    fn touching(&self, y: &[f64; NA], i: usize) -> bool {
        self.inner.touching(&split::<N, NA>(y).0, i)
    }

    fn bearing_velocity(&self, y: &[f64; NA], i: usize) -> [f64; 2] {
        self.inner.bearing_velocity(&split::<N, NA>(y).0, i)
    }

    /// The model's contact state, the hardware at rest at it ([`Wired::initial`]).
    fn contact_state(&self, levitated: &[f64; NA]) -> [f64; NA] {
        self.initial(&self.inner.contact_state(&split::<N, NA>(levitated).0))
    }

    /// The model's record with the commanded currents in the current columns and, with an
    /// amplifier, the coils' currents and voltages: with unipolar ones, the differential
    /// current `(i₊ − i₋)/2` and voltage `(v₊ − v₋)/2` in the coil columns and each magnet's
    /// own in the magnets' columns.
    fn record(&self, t: f64, y: &[f64; NA]) -> Record {
        let (m, iy, volts) = self.synced(y);
        let mut r = m.record(t, &iy);
        drop(m);
        let a = self.reference_current(y, 0);
        r.a.loads.ix_a = a[0];
        r.a.loads.iy_a = a[1];
        if let (2, Some(b)) = (M::PLANES, r.b.as_mut()) {
            let c = self.reference_current(y, 1);
            b.loads.ix_a = c[0];
            b.loads.iy_a = c[1];
        }
        let x = split::<N, NA>(y).1;
        let magnet = |at: usize| x[at].max(0.0);
        if self.hw.amplified() {
            let mut hw = RowHw::NAN;
            for i in 0..M::PLANES {
                for j in 0..2 {
                    let ax = 2 * i + j;
                    let (current, voltage) = match (self.hw.amplifiers[i], self.hw.unipolar[i]) {
                        (Some(_), None) => (x[ex::CURRENT + ax], volts.coil[ax]),
                        (Some(_), Some(_)) => {
                            ((magnet(ex::CURRENT + ax) - magnet(ex::MINUS_CURRENT + ax)) * 0.5, volts.coil[ax])
                        }
                        (None, _) => (self.reference_current(y, i)[j], f64::NAN),
                    };
                    hw.planes[i].set_axis(j, current, voltage);
                }
            }
            r.hw = Some(hw);
        }
        if self.hw.is_unipolar() {
            let mut row = RowMagnets::NAN;
            for i in (0..M::PLANES).filter(|&i| self.hw.unipolar[i].is_some()) {
                for j in 0..2 {
                    let ax = 2 * i + j;
                    let currents = [magnet(ex::CURRENT + ax), magnet(ex::MINUS_CURRENT + ax)];
                    row.planes[i].set_axis(j, currents, [volts.plus[ax], volts.minus[ax]]);
                }
            }
            r.magnets = Some(row);
        }
        r
    }

    fn plane_states(&self, t: f64, y: &[f64; NA], visit: &mut dyn FnMut(usize, &PlaneState<'_>)) {
        let (m, iy, _) = self.synced(y);
        m.plane_states(t, &iy, visit);
    }

    /// The model's used components and all of the hardware's.
    fn used_components(&self) -> usize {
        self.inner.used_components() + (NA - N)
    }

    /// The model's tolerances with the hardware's after them ([`atol`]).
    fn atol(groups: [f64; 4]) -> [f64; NA] {
        let [p, v, ..] = groups;
        let mut a = [0.0; NA];
        a[..N].copy_from_slice(&M::atol(groups));
        a[N..].copy_from_slice(&atol(p, v)[..NA - N]);
        a
    }

    /// The model's failing state (the hardware's states are not in it).
    type Failure = M::Failure;

    fn failure(t: f64, y: &[f64; NA]) -> M::Failure {
        M::failure(t, &split::<N, NA>(y).0)
    }

    fn voltage_saturation(&self, y: &[f64; NA]) -> Option<f64> {
        self.hw.amplified().then(|| y[N + ex::SATURATED])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::load_scene;
    use crate::model::{ix, Model};
    use crate::sensor::Sensor;

    fn realistic(sets: &[&str]) -> crate::config::Scene {
        let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/realistic-10g.toml");
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        load_scene(&file, &sets).expect("the realistic scene")
    }

    fn wired(scene: &crate::config::Scene) -> Wired<Model, { crate::model::N }, { crate::model::N + EXTRA }> {
        let model = Model {
            params: scene.plane(0).clone(),
            base: scene.base.clone(),
            control: Control::Held([0.0; 2]),
            race_parked: false,
        };
        Wired::new(model, [Control::Held([0.0; 2]); 2], scene.hardware.clone())
    }

    /// With the rotor held still at the centre, what the sensor reads is the runout's harmonics
    /// exactly (the ideal low-pass: the sum itself; through the gain, the gain times it).
    #[test]
    fn runout_with_the_rotor_held_at_the_centre_is_the_harmonics() {
        let scene = realistic(&["sensor.bandwidth_hz=0"]);
        let w = wired(&scene);
        let harmonics = &scene.hardware.front_end.runout;
        assert_eq!(harmonics.len(), 4);
        let gain = scene.plane(0).loop_constants.sensor_gain_v_per_m;
        let mut sensor = Sensor::new(scene.sensor);
        for k in 0..100 {
            let theta = 0.37 * k as f64;
            let mut y = [0.0; crate::model::N + EXTRA];
            y[ix::TR] = theta;
            let sensed = Machine::sensed(&w, &y, 0);
            let expect: [f64; 2] = std::array::from_fn(|axis| {
                harmonics
                    .iter()
                    .filter(|h| h.axis == axis)
                    .map(|h| h.amplitude * (f64::from(h.order) * theta + h.phase).cos())
                    .sum::<f64>()
            });
            assert_eq!(sensed, expect, "θ = {theta}");
            // The scene's 1× and 2× harmonics, written out.
            let x = 1.5e-6 * theta.cos() + 0.75e-6 * (2.0 * theta + 30f64.to_radians()).cos();
            assert!((sensed[0] - x).abs() < 1e-18, "θ = {theta}: {} against {x}", sensed[0]);
            assert_eq!(sensor.read_with_gain(sensed, gain), [gain * expect[0], gain * expect[1]]);
        }
    }

    /// With each magnet at rest at its reference (`i_0 ± i`) the unipolar model's derivative is
    /// the bipolar model's: the nonlinear law's force from `i_0 + i`, `i_0 − i` is the one it
    /// gives the control current `i`. The magnets' motional voltages `±(k_b/2) ẋ` move their
    /// differential current at half the rate `k_b ẋ` moves the bipolar coil's, and their common
    /// current not at all.
    #[test]
    fn magnets_at_their_references_give_the_bipolar_derivative() {
        const N: usize = crate::model::N;
        let sets = ["amb.force_law=nonlinear", "sensor.runout=[]", "sensor.bandwidth_hz=0"];
        let bipolar = realistic(&sets);
        let unipolar = realistic(&[sets[0], sets[1], sets[2], "amb.amplifier_topology=unipolar"]);
        let model = |scene: &crate::config::Scene| Model {
            params: scene.plane(0).clone(),
            base: scene.base.clone(),
            control: Control::Held([0.0; 2]),
            race_parked: false,
        };
        let control = [Control::Held([0.3, -0.7]); 2];
        let wb = Wired::<Model, N, { N + EXTRA }>::new(model(&bipolar), control, bipolar.hardware.clone());
        let wu = Wired::<Model, N, { N + EXTRA_UNIPOLAR }>::new(model(&unipolar), control, unipolar.hardware.clone());
        let mut y0 = [0.0; N];
        y0[ix::XR] = 3e-5;
        y0[ix::YR] = -2e-5;
        y0[ix::VXR] = 0.01;
        y0[ix::VYR] = -0.02;
        let (yb, yu) = (wb.initial(&y0), wu.initial(&y0));
        let i0 = unipolar.hardware.unipolar[0].expect("unipolar").bias;
        assert_eq!(yu[N + ex::CURRENT], i0 + 0.3);
        assert_eq!(yu[N + ex::MINUS_CURRENT + 1], i0 + 0.7);
        let (mut db, mut du) = ([0.0; N + EXTRA], [0.0; N + EXTRA_UNIPOLAR]);
        wb.rhs(0.03, &yb, &mut db);
        wu.rhs(0.03, &yu, &mut du);
        for k in 0..N {
            assert!((db[k] - du[k]).abs() <= 1e-12 * db[k].abs().max(1e-9), "state {k}: {} against {}", db[k], du[k]);
        }
        // The rotor accelerates: the force is not zero.
        assert!(db[ix::VXR].abs() > 1.0);
        let kb = unipolar.hardware.amplifiers[0].expect("amplifier").back_emf;
        assert!(kb > 0.0);
        for j in 0..2 {
            let bipolar = db[N + ex::CURRENT + j];
            let differential = (du[N + ex::CURRENT + j] - du[N + ex::MINUS_CURRENT + j]) / 2.0;
            let expect = -kb * y0[ix::VXR + j] / unipolar.hardware.amplifiers[0].expect("amplifier").inductance;
            assert!((bipolar - expect).abs() <= 1e-9 * expect.abs(), "axis {j}: bipolar {bipolar} against {expect}");
            assert!(
                (2.0 * differential - bipolar).abs() <= 1e-9 * bipolar.abs(),
                "axis {j}: {bipolar}, {differential}"
            );
            assert!((du[N + ex::CURRENT + j] + du[N + ex::MINUS_CURRENT + j]).abs() <= 1e-9 * bipolar.abs());
        }
    }

    /// The continuous PD behind a front end reads what the sensor reads and differentiates it:
    /// the runout and its rate at the centre, the range's limit and no rate past it, the
    /// filter's output and its rate (`i = i_g − A_a (k_p A_s d + k_d A_s ḋ)`).
    #[test]
    fn the_continuous_pd_reads_the_sensors_front_end() {
        let pd = |scene: &crate::config::Scene, d: [f64; 2], rate: [f64; 2]| {
            let g =
                controller::PdGains::from_design(&scene.plane_design(0).pd(), &scene.plane(0).loop_constants).unwrap();
            let a_s = scene.plane(0).loop_constants.sensor_gain_v_per_m;
            let i = |k: usize| g.bias_a[k] - g.amp_gain_a_per_v * (g.kp * a_s * d[k] + g.kd * a_s * rate[k]);
            [i(0).clamp(-2.0, 2.0), i(1).clamp(-2.0, 2.0)]
        };
        let continuous = |scene: &crate::config::Scene| {
            let mut w = wired(scene);
            let g =
                controller::PdGains::from_design(&scene.plane_design(0).pd(), &scene.plane(0).loop_constants).unwrap();
            w.set_control(0, Control::Continuous(g));
            (w, g)
        };
        let close = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12;

        // Runout alone: the rotor held at the centre, spinning at 500 Hz.
        let scene = realistic(&["sensor.bandwidth_hz=0", "amb.amplifier=false"]);
        let (w, g) = continuous(&scene);
        let speed = std::f64::consts::TAU * 500.0;
        let phase = 30f64.to_radians();
        for k in 0..20 {
            let theta = 0.41 * k as f64;
            let mut y = [0.0; crate::model::N + EXTRA];
            y[ix::TR] = theta;
            y[ix::WR] = speed;
            let d = [
                1.5e-6 * theta.cos() + 0.75e-6 * (2.0 * theta + phase).cos(),
                1.5e-6 * (theta - std::f64::consts::FRAC_PI_2).cos()
                    + 0.75e-6 * (2.0 * theta - 60f64.to_radians()).cos(),
            ];
            let rate = [
                -1.5e-6 * speed * theta.sin() - 1.5e-6 * speed * (2.0 * theta + phase).sin(),
                -1.5e-6 * speed * (theta - std::f64::consts::FRAC_PI_2).sin()
                    - 1.5e-6 * speed * (2.0 * theta - 60f64.to_radians()).sin(),
            ];
            let got = Machine::pd_current(&w, &g, &y, 0);
            assert!(close(got, pd(&scene, d, rate)), "θ = {theta}: {got:?} against {:?}", pd(&scene, d, rate));
            // Not the exact state's PD (the rotor is at rest at the centre: the bias).
            assert!((got[0] - g.bias_a[0]).abs() > 1e-4, "θ = {theta}: the runout is not read");
        }

        // The range: past ±250 µm in x the PD reads the limit and no rate; y passes.
        let scene = realistic(&["sensor.bandwidth_hz=0", "sensor.runout=[]", "amb.amplifier=false"]);
        let (w, g) = continuous(&scene);
        let mut y = [0.0; crate::model::N + EXTRA];
        y[ix::XR] = 3e-4;
        y[ix::VXR] = 0.1;
        y[ix::YR] = -1e-5;
        y[ix::VYR] = 0.05;
        let got = Machine::pd_current(&w, &g, &y, 0);
        assert!(close(got, pd(&scene, [2.5e-4, -1e-5], [0.0, 0.05])), "{got:?}");
        y[ix::XR] = 2e-4;
        let got = Machine::pd_current(&w, &g, &y, 0);
        assert!(close(got, pd(&scene, [2e-4, -1e-5], [0.1, 0.05])), "{got:?}");

        // The 5 kHz Butterworth: its output and its output's rate, not the rotor's.
        let scene = realistic(&["sensor.runout=[]", "amb.amplifier=false"]);
        let (w, g) = continuous(&scene);
        let mut y = [0.0; crate::model::N + EXTRA];
        y[ix::XR] = 1e-4;
        y[ix::VXR] = 0.1;
        y[crate::model::N + ex::FILTER] = 4e-5;
        y[crate::model::N + ex::FILTER_RATE] = 0.02;
        let got = Machine::pd_current(&w, &g, &y, 0);
        assert!(close(got, pd(&scene, [4e-5, 0.0], [0.02, 0.0])), "{got:?}");
    }

    /// The range clips what the sensor reads; the filter's output is what is read when the
    /// sensor has a bandwidth.
    #[test]
    fn the_range_clips_and_the_filter_is_read() {
        let scene = realistic(&["sensor.runout=[]"]);
        let w = wired(&scene);
        let mut y = [0.0; crate::model::N + EXTRA];
        y[ix::XR] = 1e-4;
        y[crate::model::N + ex::FILTER] = 3e-4;
        y[crate::model::N + ex::FILTER + 1] = -1e-5;
        assert_eq!(Machine::sensed(&w, &y, 0), [2.5e-4, -1e-5]);
        let ideal = realistic(&["sensor.runout=[]", "sensor.bandwidth_hz=0"]);
        assert_eq!(Machine::sensed(&wired(&ideal), &y, 0), [1e-4, 0.0]);
    }
}
