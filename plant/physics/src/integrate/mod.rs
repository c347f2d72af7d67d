//! Hand-written ODE integrators on fixed-size state `[f64; N]`, with no allocation per step.
//!
//! # Problem and state layout
//!
//! A [`System`] is a first-order ODE `y' = f(t, y)` with `y ∈ ℝᴺ`. Its state is laid out as
//! `[positions; velocities]`: `N` is even and `y[N/2 + i]` is the time derivative of `y[i]`.
//! Only [`Method::SymplecticEuler`] relies on this layout; the other methods take any `N`.
//! Units are those of the system (SI in this project), time in seconds.
//!
//! # Macro steps
//!
//! [`Integrator::advance`] takes `y` from `t0` to `t1`: one *macro step*, over which the system
//! holds its inputs (controller currents, base motion samples) constant. Fixed-step methods take
//! [`Settings::substeps`] equal steps `h = (t1 − t0)/substeps`. Adaptive methods take as many
//! steps as their error control needs, shortening the last so that it lands on `t1` exactly.
//! Every macro step restarts cleanly: `f(t0, y0)` is evaluated afresh (no first-same-as-last stage
//! is carried across calls, since the inputs may have changed), but the step-size estimate and the
//! PI controller memory ([`AdaptiveState`]) are kept.
//!
//! # Methods (h is the step, kᵢ the stages)
//!
//! * [`Method::ExplicitEuler`]: `y₊ = y + h·f(t, y)`. Order 1, one evaluation per step.
//! * [`Method::SymplecticEuler`] (semi-implicit Euler): with `y = [q; v]` and `a` the second half of
//!   `f`, `v₊ = v + h·a(t, q, v)`, then `q₊ = q + h·v₊`. Order 1, one evaluation per step; the first
//!   half of `f` is ignored. Symplectic for separable Hamiltonian systems: the energy of an
//!   undamped oscillator oscillates within `O(h)` instead of drifting.
//! * [`Method::Rk4`]: the classic four-stage Runge–Kutta method. Order 4.
//! * [`Method::Dp5`]: Dormand–Prince 5(4) (Hairer's DOPRI5): six stages plus one first-same-as-last
//!   stage, advancing with the fifth-order solution, embedded fourth-order error estimate,
//!   PI step control, continuous extension of order 4.
//! * [`Method::Dop853`]: Hairer's DOP853: a 12-stage eighth-order method whose error estimate
//!   combines embedded fifth- and third-order estimates, `err = e₅² / √(e₅² + 0.01·e₃²)`, with
//!   I step control and a seventh-order continuous extension (three extra stages, evaluated only
//!   for steps that hold a sample time).
//!
//! # Error norm and step control (adaptive methods)
//!
//! Per component the error is scaled by `sᵢ = atolᵢ + rtol·max(|yᵢ|, |y₊ᵢ|)` and combined by
//! [`ErrorNorm::Rms`] (default, Hairer's: `√(Σ (errᵢ/sᵢ)² / N)`) or [`ErrorNorm::Max`]
//! (`maxᵢ |errᵢ/sᵢ|`, the flavour of MATLAB's ode45). A step is accepted when `err ≤ 1`. The
//! next step is `h₊ = h / clamp(err^α · err_old^(−β) / safety, 1/fac_max, 1/fac_min)` with
//! `err_old` the error of the previous accepted step (floored at 1e-4):
//!
//! | method | α | β | safety | fac_min | fac_max |
//! |--------|---|---|--------|---------|---------|
//! | Dp5    | 0.2 − 0.75·β = 0.17 | 0.04 | 0.9 | 0.2 | 10 |
//! | Dop853 | 1/8 | 0 | 0.9 | 0.333 | 6 |
//!
//! After a rejection, `h₊ = h / min(1/fac_min, err^α/safety)`, and the next accepted step may not
//! grow. A non-finite error estimate counts as a rejection and halves the step. The first step
//! of the first macro step is [`Settings::h_init`], or Hairer's heuristic when that is 0.
//!
//! # Dense output
//!
//! [`Integrator::advance_dense`] calls a sink at given times inside the macro step: Dp5 and Dop853
//! use their own continuous extensions (orders 4 and 7); the fixed-step methods use the cubic
//! Hermite interpolant between substeps built from `y` and `f` at both ends (order 3, which is
//! the method's own order or better for Euler; for Rk4 the interpolant error `O(h⁴)` matches the
//! global error). The extensions' errors are not controlled: on a smooth test problem Dp5's
//! samples stay within about 2× the tolerance, Dop853's (one order below its method) reach
//! 10–50× at long steps. Where samples must be as good as step ends, cap `h_max` or end a
//! macro step at the sample time.
//!
//! # Numerical failure
//!
//! Never a panic: a non-finite state or derivative, a step-size underflow or too many steps in one
//! macro step come back as an [`IntegrationError`] with the time and state. On error, `y` is left
//! at the last accepted (finite) state. When an adaptive step collapses below the floor because
//! every attempt met a non-finite stage (a right-hand side that returns NaN past some point),
//! the error is [`IntegrationError::NonFinite`] at the last good time, not `StepSizeUnderflow`.
//!
//! ```
//! use plant_physics::integrate::{FnSystem, Integrator, Method, Settings};
//!
//! // Harmonic oscillator q'' = −q, state [q, v].
//! let sys = FnSystem(|_t: f64, y: &[f64; 2], dy: &mut [f64; 2]| {
//!     dy[0] = y[1];
//!     dy[1] = -y[0];
//! });
//! let mut integrator = Integrator::new(Settings::adaptive(Method::Dp5, 1e-10, 1e-12));
//! let mut y = [1.0, 0.0];
//! integrator.advance(&sys, 0.0, 1.0, &mut y).unwrap();
//! assert!((y[0] - 1.0_f64.cos()).abs() < 1e-9);
//! ```

mod adaptive;
mod dop853;
mod dp5;
mod explicit_euler;
mod rk4;
mod symplectic_euler;

use serde::{Deserialize, Serialize};

/// A first-order system `y' = f(t, y)`.
///
/// The state layout is `[positions; velocities]` (`N` even, the second half are the time
/// derivatives of the first half), which [`Method::SymplecticEuler`] relies on.
pub trait System<const N: usize> {
    /// Writes `f(t, y)` into `dy`. Must be a pure function of `(t, y)` over one macro step: no
    /// I/O, no allocation. Every element of `dy` must be written.
    fn rhs(&self, t: f64, y: &[f64; N], dy: &mut [f64; N]);
}

/// Adapts a closure `|t, y, dy| …` into a [`System`].
///
/// ```
/// use plant_physics::integrate::{FnSystem, System};
///
/// let decay = FnSystem(|_t: f64, y: &[f64; 1], dy: &mut [f64; 1]| dy[0] = -y[0]);
/// let mut dy = [0.0];
/// decay.rhs(0.0, &[2.0], &mut dy);
/// assert_eq!(dy, [-2.0]);
/// ```
#[derive(Clone, Copy, Debug)]
pub struct FnSystem<F>(pub F);

impl<const N: usize, F: Fn(f64, &[f64; N], &mut [f64; N])> System<N> for FnSystem<F> {
    fn rhs(&self, t: f64, y: &[f64; N], dy: &mut [f64; N]) {
        (self.0)(t, y, dy)
    }
}

/// The integration method.
///
/// ```
/// use plant_physics::integrate::Method;
///
/// let m: Method = serde_json::from_str("\"dop853\"").unwrap();
/// assert_eq!(m, Method::Dop853);
/// assert!(m.is_adaptive());
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Explicit (forward) Euler, order 1, fixed step.
    ExplicitEuler,
    /// Symplectic (semi-implicit) Euler, order 1, fixed step; needs the `[q; v]` layout.
    SymplecticEuler,
    /// Classic Runge–Kutta, order 4, fixed step.
    Rk4,
    /// Dormand–Prince 5(4), adaptive, dense output of order 4.
    Dp5,
    /// Hairer's DOP853, order 8, adaptive, dense output of order 7.
    Dop853,
}

impl Method {
    /// Whether the method controls its step size (Dp5, Dop853) rather than taking
    /// [`Settings::substeps`] equal steps.
    pub fn is_adaptive(self) -> bool {
        matches!(self, Method::Dp5 | Method::Dop853)
    }

    /// The classical order of the method (the order of the solution it advances with).
    pub fn order(self) -> u32 {
        match self {
            Method::ExplicitEuler | Method::SymplecticEuler => 1,
            Method::Rk4 => 4,
            Method::Dp5 => 5,
            Method::Dop853 => 8,
        }
    }
}

/// How the adaptive methods combine the scaled per-component errors into one number.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ErrorNorm {
    /// Root mean square, `√(Σ (errᵢ/sᵢ)² / N)`: Hairer's DOPRI5 and DOP853 (default).
    #[default]
    Rms,
    /// Maximum, `maxᵢ |errᵢ/sᵢ|`: MATLAB's ode45 flavour; stricter for large `N`.
    Max,
}

/// Numerical settings of an [`Integrator`]. Each field's doc gives its unit and the default of
/// [`Settings::new`].
///
/// To force an adaptive method onto a fixed step `h` (for convergence studies), set
/// `h_init = h_max = h` and `rtol` and `atol` huge (e.g. 1e30): every step is then accepted.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings<const N: usize> {
    /// The method. Default [`Method::Dp5`].
    pub method: Method,
    /// Fixed-step methods: equal substeps per macro step, ≥ 1. Default 1.
    pub substeps: u32,
    /// Adaptive methods: relative tolerance (dimensionless), ≥ 0. Default 1e-6.
    pub rtol: f64,
    /// Adaptive methods: absolute tolerance per component, in that component's unit, ≥ 0, and
    /// `atolᵢ + rtol > 0`. Default 1e-9 for every component.
    pub atol: [f64; N],
    /// Adaptive methods: how the scaled errors are combined. Default [`ErrorNorm::Rms`].
    pub norm: ErrorNorm,
    /// Adaptive methods, [`ErrorNorm::Rms`]: the number of components the mean is taken over,
    /// 1 to N. Default N. A state with slots its model does not use (they stay zero and add
    /// nothing to the sum: the flexible rotor's reduced coordinates past its basis) counts only
    /// the components it uses, so that its tolerance does not depend on the padding.
    pub rms_count: usize,
    /// Adaptive methods: smallest step, s, below which the controller gives up with
    /// [`IntegrationError::StepSizeUnderflow`]. The floor actually used is
    /// `max(h_min, 10·ε·|t|)` (ε the machine epsilon), so that `t + h ≠ t`. The last step of a
    /// macro step, shortened to land on `t1`, is exempt. Default 1e-14 s.
    pub h_min: f64,
    /// Adaptive methods: largest step, s, > 0; the macro step `t1 − t0` bounds it too.
    /// Default `f64::INFINITY` (the macro step).
    pub h_max: f64,
    /// Adaptive methods: first step, s, of the first macro step; later macro steps start with
    /// the carried estimate. 0 selects Hairer's initial-step heuristic (two evaluations).
    /// Default 0.
    pub h_init: f64,
    /// Adaptive methods: most step attempts (accepted or rejected) in one macro step before
    /// [`IntegrationError::TooManySteps`]; guards against stalls. Default 100 000.
    pub max_steps: u64,
}

impl<const N: usize> Settings<N> {
    /// The defaults documented on each field, for `method`.
    pub fn new(method: Method) -> Self {
        Self {
            method,
            substeps: 1,
            rtol: 1e-6,
            atol: [1e-9; N],
            norm: ErrorNorm::Rms,
            rms_count: N,
            h_min: 1e-14,
            h_max: f64::INFINITY,
            h_init: 0.0,
            max_steps: 100_000,
        }
    }

    /// A fixed-step method taking `substeps` equal steps per macro step.
    ///
    /// ```
    /// use plant_physics::integrate::{Method, Settings};
    ///
    /// let s = Settings::<4>::fixed(Method::Rk4, 10);
    /// assert_eq!(s.substeps, 10);
    /// assert!(s.validate().is_ok());
    /// ```
    pub fn fixed(method: Method, substeps: u32) -> Self {
        Self { substeps, ..Self::new(method) }
    }

    /// An adaptive method with relative tolerance `rtol` and the same absolute tolerance `atol`
    /// for every component.
    pub fn adaptive(method: Method, rtol: f64, atol: f64) -> Self {
        Self { rtol, atol: [atol; N], ..Self::new(method) }
    }

    /// Checks the ranges documented on each field.
    ///
    /// ```
    /// use plant_physics::integrate::{Method, Settings};
    ///
    /// assert!(Settings::<3>::new(Method::SymplecticEuler).validate().is_err()); // odd N
    /// assert!(Settings::<2>::fixed(Method::Rk4, 0).validate().is_err());
    /// ```
    pub fn validate(&self) -> Result<(), InvalidSettings> {
        let bad = |why| Err(InvalidSettings(why));
        if self.method == Method::SymplecticEuler && !N.is_multiple_of(2) {
            return bad("symplectic Euler needs an even state length [positions; velocities]");
        }
        if self.substeps == 0 {
            return bad("substeps must be at least 1");
        }
        if !(self.rtol >= 0.0 && self.rtol.is_finite()) {
            return bad("rtol must be finite and non-negative");
        }
        if !self.atol.iter().all(|&a| a >= 0.0 && a.is_finite() && a + self.rtol > 0.0) {
            return bad("each atol must be finite, non-negative, and atol + rtol > 0");
        }
        if self.rms_count == 0 || self.rms_count > N {
            return bad("rms_count must be 1 to N, the components the RMS norm is taken over");
        }
        if !(self.h_min >= 0.0 && self.h_min.is_finite()) {
            return bad("h_min must be finite and non-negative");
        }
        if self.h_max.is_nan() || self.h_max <= 0.0 {
            return bad("h_max must be positive");
        }
        if !(self.h_init >= 0.0 && self.h_init.is_finite()) {
            return bad("h_init must be finite and non-negative (0 = automatic)");
        }
        if self.max_steps == 0 {
            return bad("max_steps must be at least 1");
        }
        Ok(())
    }
}

impl<const N: usize> Default for Settings<N> {
    /// [`Settings::new`] with [`Method::Dp5`].
    fn default() -> Self {
        Self::new(Method::Dp5)
    }
}

/// Settings outside their documented ranges; the text says which.
#[derive(Debug, thiserror::Error, Clone, Copy, PartialEq, Eq)]
#[error("invalid integrator settings: {0}")]
pub struct InvalidSettings(pub &'static str);

/// Work counters, cumulative since the integrator was made (or [`Integrator::reset_stats`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Accepted steps (for fixed-step methods: substeps taken).
    pub steps: u64,
    /// Rejected step attempts (adaptive methods only).
    pub rejected: u64,
    /// Evaluations of [`System::rhs`].
    pub rhs_evals: u64,
}

/// Numerical failure of a macro step. State values are SI; `state` is a copy of the state at `t`
/// (allocated only on this error path).
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum IntegrationError {
    /// The state, or the derivative `f(t, state)`, holds a NaN or an infinity. If the state is
    /// finite the derivative is the culprit: either directly, or because every step tried from
    /// `t` down to the smallest step met a non-finite stage.
    #[error("non-finite state at t = {t} s: {state:?}")]
    NonFinite {
        /// Time, s.
        t: f64,
        /// State at `t`.
        state: Vec<f64>,
    },
    /// The error controller asked for a step below the floor of [`Settings::h_min`].
    #[error("step size underflow at t = {t} s (h = {} s): {state:?}", crate::number::shown(*h))]
    StepSizeUnderflow {
        /// Time, s.
        t: f64,
        /// The step the controller asked for, s.
        h: f64,
        /// State at `t`.
        state: Vec<f64>,
    },
    /// More than [`Settings::max_steps`] step attempts in one macro step.
    #[error("more than {max_steps} steps in one macro step at t = {t} s: {state:?}")]
    TooManySteps {
        /// Time reached, s.
        t: f64,
        /// The limit, [`Settings::max_steps`].
        max_steps: u64,
        /// State at `t`.
        state: Vec<f64>,
    },
}

/// What an adaptive method carries from one macro step to the next. Part of the simulation
/// state for bit-for-bit snapshot and resume (see [`Integrator::adaptive_state`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct AdaptiveState {
    /// Step-size estimate for the next step, s; 0 = none yet ([`Settings::h_init`] or the
    /// heuristic applies).
    pub h: f64,
    /// Error norm of the last accepted step (PI controller memory), floored at 1e-4.
    pub err_old: f64,
}

impl Default for AdaptiveState {
    /// No estimate, `err_old = 1e-4` (Hairer's start).
    fn default() -> Self {
        Self { h: 0.0, err_old: 1e-4 }
    }
}

/// Number of stage buffers: DOP853 with its dense-output stages needs 16.
const STAGES: usize = 16;

/// Stage slot where the fixed-step methods put `f(t₊, y₊)` (Rk4 uses slots 0–3).
const FIXED_END: usize = 4;

/// Scratch memory of an integrator; no meaning between macro steps.
#[derive(Clone, Debug)]
pub(crate) struct Workspace<const N: usize> {
    /// Stages; slot 0 always holds `f(t, y)` at the start of a step.
    pub(crate) k: [[f64; N]; STAGES],
    /// Argument of the stage being evaluated.
    pub(crate) y_stage: [f64; N],
    /// Candidate solution at the end of the step.
    pub(crate) y_new: [f64; N],
    /// Error estimate (divided by h) of the step; DOP853's fifth-order one.
    pub(crate) err: [f64; N],
    /// DOP853's third-order error estimate (divided by h).
    pub(crate) err3: [f64; N],
    /// Continuous-extension coefficients (divided by h).
    pub(crate) dense: [[f64; N]; 4],
    /// An interpolated state handed to the sample sink.
    pub(crate) y_out: [f64; N],
}

impl<const N: usize> Workspace<N> {
    fn new() -> Self {
        Self {
            k: [[0.0; N]; STAGES],
            y_stage: [0.0; N],
            y_new: [0.0; N],
            err: [0.0; N],
            err3: [0.0; N],
            dense: [[0.0; N]; 4],
            y_out: [0.0; N],
        }
    }
}

/// A system whose evaluations are counted.
pub(crate) struct Rhs<'a, S> {
    sys: &'a S,
    evals: u64,
}

impl<'a, S> Rhs<'a, S> {
    #[inline(always)]
    pub(crate) fn eval<const N: usize>(&mut self, t: f64, y: &[f64; N], dy: &mut [f64; N])
    where
        S: System<N>,
    {
        self.evals += 1;
        self.sys.rhs(t, y, dy);
    }
}

/// The sample times of one macro step and the sink they go to.
pub(crate) struct Samples<'a, F> {
    times: &'a [f64],
    next: usize,
    sink: F,
}

impl<F> Samples<'_, F> {
    /// Whether a sample time is due at or before `t_end`.
    #[inline]
    pub(crate) fn due(&self, t_end: f64) -> bool {
        self.next < self.times.len() && self.times[self.next] <= t_end
    }

    /// Hands every sample time up to `t_end` to the sink: `y_end` exactly at `t_end`, otherwise
    /// what `interpolate(t, out)` writes into `out`.
    #[inline]
    pub(crate) fn emit<const N: usize>(
        &mut self,
        t_end: f64,
        y_end: &[f64; N],
        out: &mut [f64; N],
        mut interpolate: impl FnMut(f64, &mut [f64; N]),
    ) where
        F: FnMut(f64, &[f64; N]),
    {
        while self.due(t_end) {
            let t = self.times[self.next];
            if t == t_end {
                (self.sink)(t, y_end);
            } else {
                interpolate(t, out);
                (self.sink)(t, out);
            }
            self.next += 1;
        }
    }
}

/// Whether every component is finite.
#[inline]
pub(crate) fn all_finite<const N: usize>(y: &[f64; N]) -> bool {
    // A sum is non-finite iff a term is (or it overflows, which is trouble too).
    y.iter().map(|v| v * 0.0).sum::<f64>() == 0.0
}

/// `out = y + h·Σⱼ aⱼ·kⱼ` over the non-zero entries `(j, aⱼ)` of one tableau row (the sum is
/// formed first, then added to `y`, as in Hairer's codes).
#[inline(always)]
pub(crate) fn stage_arg<const N: usize>(
    y: &[f64; N],
    h: f64,
    row: &[(usize, f64)],
    k: &[[f64; N]; STAGES],
    out: &mut [f64; N],
) {
    weighted_sum(row, k, out);
    for i in 0..N {
        out[i] = y[i] + h * out[i];
    }
}

/// `out = Σⱼ aⱼ·kⱼ` over the entries `(j, aⱼ)` of `row`.
#[inline(always)]
pub(crate) fn weighted_sum<const N: usize>(row: &[(usize, f64)], k: &[[f64; N]; STAGES], out: &mut [f64; N]) {
    *out = [0.0; N];
    for &(j, a) in row {
        let kj = &k[j];
        for i in 0..N {
            out[i] += a * kj[i];
        }
    }
}

/// A fixed-step one-step method.
pub(crate) trait FixedStep {
    /// One step of size `h` from `(t, y)`, with `ws.k[0] = f(t, y)` on entry, writing the
    /// result to `ws.y_new`. May use stage slots `1..FIXED_END`.
    fn step<const N: usize, S: System<N>>(rhs: &mut Rhs<'_, S>, t: f64, h: f64, y: &[f64; N], ws: &mut Workspace<N>);
}

/// Steps and interpolation for the fixed-step methods.
fn run_fixed<M: FixedStep, const N: usize, S: System<N>, F: FnMut(f64, &[f64; N])>(
    rhs: &mut Rhs<'_, S>,
    integrator: &mut Integrator<N>,
    (t0, t1): (f64, f64),
    y: &mut [f64; N],
    samples: &mut Samples<'_, F>,
) -> Result<(), IntegrationError> {
    let Integrator { settings, ws, stats, .. } = integrator;
    let n = settings.substeps.max(1);
    let h = (t1 - t0) / f64::from(n);
    rhs.eval(t0, y, &mut ws.k[0]);
    for i in 0..n {
        let t = t0 + f64::from(i) * h;
        let last = i + 1 == n;
        let t_new = if last { t1 } else { t0 + f64::from(i + 1) * h };
        M::step(rhs, t, h, y, ws);
        if !all_finite(&ws.y_new) {
            return Err(IntegrationError::NonFinite { t: t_new, state: ws.y_new.to_vec() });
        }
        stats.steps += 1;
        // f(t₊, y₊) is the next step's first stage; on the last substep only the interpolant
        // needs it.
        if !last || samples.due(t_new) {
            rhs.eval(t_new, &ws.y_new, &mut ws.k[FIXED_END]);
            let Workspace { k, y_new, y_out, .. } = ws;
            let (f0, f1) = (&k[0], &k[FIXED_END]);
            samples.emit(t_new, y_new, y_out, |ts, out| hermite(((ts - t) / h, h), (y, f0), (y_new, f1), out));
            ws.k[0] = ws.k[FIXED_END];
        }
        *y = ws.y_new;
    }
    Ok(())
}

/// Cubic Hermite interpolant at `θ ∈ [0, 1]` of a step of size `h` from `(y0, f0)` to `(y1, f1)`:
/// `y0 + θ·Δ + θ(θ−1)·((1−2θ)·Δ + (θ−1)·h·f0 + θ·h·f1)`, `Δ = y1 − y0`.
#[inline]
fn hermite<const N: usize>(
    (theta, h): (f64, f64),
    (y0, f0): (&[f64; N], &[f64; N]),
    (y1, f1): (&[f64; N], &[f64; N]),
    out: &mut [f64; N],
) {
    let a = theta * (theta - 1.0);
    let (c_d, c0, c1) = (1.0 - 2.0 * theta, (theta - 1.0) * h, theta * h);
    for i in 0..N {
        let d = y1[i] - y0[i];
        out[i] = y0[i] + theta * d + a * (c_d * d + c0 * f0[i] + c1 * f1[i]);
    }
}

/// Integrates a [`System`] over macro steps. Owns only scratch memory, the settings, the carried
/// [`AdaptiveState`] and the [`Stats`]; the simulation state `(t, y)` belongs to the caller.
///
/// ```
/// use plant_physics::integrate::{FnSystem, Integrator, Method, Settings};
///
/// let sys = FnSystem(|_t: f64, y: &[f64; 1], dy: &mut [f64; 1]| dy[0] = -y[0]);
/// let mut rk4 = Integrator::new(Settings::fixed(Method::Rk4, 100));
/// let mut y = [1.0];
/// let mut samples = Vec::new();
/// rk4.advance_dense(&sys, 0.0, 1.0, &mut y, &[0.25, 0.5], |t, y| samples.push((t, y[0])))
///     .unwrap();
/// assert!((y[0] - (-1.0_f64).exp()).abs() < 1e-9);
/// assert!((samples[1].1 - (-0.5_f64).exp()).abs() < 1e-9);
/// assert_eq!(rk4.stats().steps, 100);
/// ```
#[derive(Clone, Debug)]
pub struct Integrator<const N: usize> {
    settings: Settings<N>,
    ws: Workspace<N>,
    adaptive: AdaptiveState,
    stats: Stats,
}

impl<const N: usize> Integrator<N> {
    /// An integrator with `settings`.
    ///
    /// # Panics
    ///
    /// If `settings` fail [`Settings::validate`] (a programmer error: validate settings that come
    /// from configuration first, or use [`Integrator::try_new`]).
    pub fn new(settings: Settings<N>) -> Self {
        match Self::try_new(settings) {
            Ok(integrator) => integrator,
            Err(e) => panic!("{e}"),
        }
    }

    /// An integrator with `settings`, or why they are invalid.
    pub fn try_new(settings: Settings<N>) -> Result<Self, InvalidSettings> {
        settings.validate()?;
        Ok(Self { settings, ws: Workspace::new(), adaptive: AdaptiveState::default(), stats: Stats::default() })
    }

    /// The settings.
    pub fn settings(&self) -> &Settings<N> {
        &self.settings
    }

    /// Changes the substeps of a fixed-step method for the next macro steps (ignored by the
    /// adaptive methods); `substeps` is at least 1.
    pub fn set_substeps(&mut self, substeps: u32) {
        self.settings.substeps = substeps.max(1);
    }

    /// Work counters since creation or the last [`Integrator::reset_stats`].
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// Sets the work counters (resume from a snapshot: the counters go on from its).
    pub fn set_stats(&mut self, stats: Stats) {
        self.stats = stats;
    }

    /// Zeroes the work counters.
    pub fn reset_stats(&mut self) {
        self.stats = Stats::default();
    }

    /// The step-size estimate and controller memory carried to the next macro step (unused by
    /// the fixed-step methods).
    pub fn adaptive_state(&self) -> AdaptiveState {
        self.adaptive
    }

    /// Restores a carried state saved by [`Integrator::adaptive_state`] (resume from a snapshot),
    /// or forgets it with `AdaptiveState::default()`.
    pub fn set_adaptive_state(&mut self, state: AdaptiveState) {
        self.adaptive = state;
    }

    /// Advances `y` from `t0` to `t1`: one macro step, over which the system holds its inputs
    /// constant. Fixed-step methods take [`Settings::substeps`] equal steps. Adaptive methods
    /// restart cleanly at `t0` (the first stage is re-evaluated: no first-same-as-last stage is
    /// carried across calls since inputs may have changed) but keep their step-size estimate;
    /// the last step is shortened to land on `t1` exactly. `t1 == t0` does nothing.
    ///
    /// On error `y` holds the last accepted state, which may be short of `t1`.
    ///
    /// # Panics
    ///
    /// If `t1 < t0` or either is not finite (a programmer error).
    pub fn advance<S: System<N>>(
        &mut self,
        sys: &S,
        t0: f64,
        t1: f64,
        y: &mut [f64; N],
    ) -> Result<(), IntegrationError> {
        self.advance_dense(sys, t0, t1, y, &[], |_, _| {})
    }

    /// As [`Integrator::advance`], and calls `sample(t, &y_t)` for every time in `times`
    /// (sorted ascending, inside `(t0, t1]`), in order, as the steps pass them. Dp5 and Dop853
    /// use their continuous extensions (orders 4 and 7; Dop853's costs three extra evaluations
    /// for each step that holds a sample); the fixed-step methods use the cubic Hermite
    /// interpolant between substeps (one extra evaluation when a sample falls in the last
    /// substep). A sample at the end of a step gets that step's state exactly.
    ///
    /// Times outside `(t0, t1]` are a programmer error, caught by a debug assertion; in release
    /// builds times ≤ `t0` are extrapolated from the first step and times > `t1` are skipped.
    /// If an error occurs, only the samples before the failing step have been delivered.
    ///
    /// # Panics
    ///
    /// If `t1 < t0` or either is not finite (a programmer error).
    pub fn advance_dense<S: System<N>, F: FnMut(f64, &[f64; N])>(
        &mut self,
        sys: &S,
        t0: f64,
        t1: f64,
        y: &mut [f64; N],
        times: &[f64],
        sample: F,
    ) -> Result<(), IntegrationError> {
        assert!(t0.is_finite() && t1.is_finite() && t1 >= t0, "advance needs finite t0 ≤ t1, got t0 = {t0}, t1 = {t1}");
        debug_assert!(
            times.windows(2).all(|w| w[0] <= w[1])
                && times.first().is_none_or(|&t| t > t0)
                && times.last().is_none_or(|&t| t <= t1),
            "sample times must be sorted and inside (t0, t1]"
        );
        if t1 == t0 {
            return Ok(());
        }
        let mut rhs = Rhs { sys, evals: 0 };
        let mut samples = Samples { times, next: 0, sink: sample };
        let span = (t0, t1);
        let result = match self.settings.method {
            Method::ExplicitEuler => {
                run_fixed::<explicit_euler::ExplicitEuler, N, S, F>(&mut rhs, self, span, y, &mut samples)
            }
            Method::SymplecticEuler => {
                run_fixed::<symplectic_euler::SymplecticEuler, N, S, F>(&mut rhs, self, span, y, &mut samples)
            }
            Method::Rk4 => run_fixed::<rk4::Rk4, N, S, F>(&mut rhs, self, span, y, &mut samples),
            Method::Dp5 => adaptive::run::<dp5::Dp5, N, S, F>(&mut rhs, self, span, y, &mut samples),
            Method::Dop853 => adaptive::run::<dop853::Dop853, N, S, F>(&mut rhs, self, span, y, &mut samples),
        };
        self.stats.rhs_evals += rhs.evals;
        result
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_finite_spots_nan_and_infinities() {
        assert!(all_finite(&[0.0, -1.0, 1e300]));
        assert!(!all_finite(&[0.0, f64::NAN]));
        assert!(!all_finite(&[f64::INFINITY, 0.0]));
        assert!(!all_finite(&[f64::NEG_INFINITY]));
        assert!(all_finite::<0>(&[]));
    }

    #[test]
    fn hermite_reproduces_a_cubic() {
        // p(t) = 1 + 2t − t² + 0.5t³ on [0.5, 0.5 + h].
        let p = |t: f64| 1.0 + 2.0 * t - t * t + 0.5 * t * t * t;
        let dp = |t: f64| 2.0 - 2.0 * t + 1.5 * t * t;
        let (ta, h) = (0.5, 0.7);
        let tb = ta + h;
        for theta in [0.0, 0.1, 0.5, 0.77, 1.0] {
            let mut out = [0.0];
            hermite((theta, h), (&[p(ta)], &[dp(ta)]), (&[p(tb)], &[dp(tb)]), &mut out);
            assert!((out[0] - p(ta + theta * h)).abs() < 1e-14, "θ = {theta}");
        }
    }

    #[test]
    fn invalid_settings_are_refused() {
        let mut s = Settings::<2>::adaptive(Method::Dp5, 0.0, 0.0);
        assert!(Integrator::try_new(s.clone()).is_err());
        s.atol = [1e-9, 0.0];
        assert!(s.validate().is_err());
        s.rtol = 1e-6;
        assert!(s.validate().is_ok());
        s.h_max = 0.0;
        assert!(s.validate().is_err());
        s.h_max = f64::NAN;
        assert!(s.validate().is_err());
    }

    #[test]
    fn zero_length_macro_step_does_nothing() {
        let sys = FnSystem(|_t: f64, _y: &[f64; 2], dy: &mut [f64; 2]| *dy = [1.0, 1.0]);
        let mut y = [1.0, 2.0];
        let mut integrator = Integrator::new(Settings::default());
        integrator.advance(&sys, 1.0, 1.0, &mut y).unwrap();
        assert_eq!(y, [1.0, 2.0]);
        assert_eq!(integrator.stats(), Stats::default());
    }
}
