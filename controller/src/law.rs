//! The contract of a control law.
//!
//! * A **per-plane law** ([`ControlLaw`]) reads one bearing plane's x and y ([`Sample`]) and
//!   returns that plane's two currents. It is built from the plane's [`Design`] and its own
//!   [`Params`] by the constructor in its [`LawEntry`]. On the planar model it is the whole
//!   controller; on a two-plane rotor it runs decentralised, one instance per plane, each
//!   built from its own plane's design ([`Decentralised`]).
//! * A **law of the whole rotor** ([`RotorLaw`]) reads every axis at once ([`RotorSample`])
//!   and returns every current: a centralised law such as `modal`, built from the
//!   [`RotorDesign`] by the constructor in its [`RotorLawEntry`].
//!
//! [`AnyLaw`] is either entry: what a controller process offers ([`build_among`] builds the
//! one a hello names, as a [`RotorLaw`] in both cases). Both kinds get the keyphasor (the
//! rotor's speed and angle) in every sample. [`LawError`] (why a law could not be built) lives
//! in [`crate::error`], the designs in [`crate::design`]; both are re-exported here.

pub use crate::design::{Design, Geometry, LoopConstants, PdDesign, RotorDesign, ROTOR_AXES};
pub use crate::error::LawError;
use crate::params::Params;

/// One controller input of a per-plane law: what the digital controller reads at a tick for
/// one bearing plane, with the rotor's keyphasor.
///
/// ```
/// use controller::Sample;
/// // A sample built by hand (tests, replays): name what you set, default the rest.
/// let s = Sample { seq: 3, t_s: 1.5e-4, sensor_v: [0.25, -0.1], ..Default::default() };
/// assert_eq!((s.speed_rad_s, s.angle_rad), (0.0, 0.0));
/// // The keyphasor: the rotor at 500 Hz, a quarter turn past the unbalance's reference.
/// let s = Sample { speed_rad_s: std::f64::consts::TAU * 500.0, angle_rad: std::f64::consts::FRAC_PI_2, ..s };
/// assert!(s.angle_rad >= 0.0 && s.angle_rad < std::f64::consts::TAU);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Sample {
    /// Sample index k (the tick it was taken at).
    pub seq: u64,
    /// Simulated time of the sample (s).
    pub t_s: f64,
    /// Sensor voltages `A_s·Δ` of this law's bearing plane (V), x then y (Δ the rotor's
    /// displacement from the housing centre at the sensor plane).
    pub sensor_v: [f64; 2],
    /// The rotor's spin speed Ω (rad/s), positive about +z: the keyphasor's speed.
    pub speed_rad_s: f64,
    /// The rotor's angle (rad) in [0, 2π), in the sensor frame (the housing's x, y): the
    /// keyphasor. At angle 0 the (static) unbalance points along +x; it turns with the spin,
    /// so the synchronous unbalance force points along (cos angle, sin angle).
    pub angle_rad: f64,
}

/// One controller input of a law of the whole rotor: every axis at once.
///
/// ```
/// use controller::RotorSample;
/// let s = RotorSample { axes: 4, sensor_v: [0.1, 0.2, 0.3, 0.4], speed_rad_s: 100.0, ..Default::default() };
/// let b = s.plane(1); // plane B's pair, with the keyphasor
/// assert_eq!((b.sensor_v, b.speed_rad_s), ([0.3, 0.4], 100.0));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct RotorSample {
    /// Sample index k (the tick it was taken at).
    pub seq: u64,
    /// Simulated time of the sample (s).
    pub t_s: f64,
    /// Axes in use: 2 (planar: x, y) or 4 (x_A, y_A, x_B, y_B).
    pub axes: u32,
    /// Sensor voltages (V) per axis in axis order; entries past `axes` are 0.
    pub sensor_v: [f64; ROTOR_AXES],
    /// The rotor's spin speed Ω (rad/s): the keyphasor's speed.
    pub speed_rad_s: f64,
    /// The rotor's angle (rad) in [0, 2π): the keyphasor ([`Sample::angle_rad`]).
    pub angle_rad: f64,
}

impl RotorSample {
    /// Bearing plane `p`'s sample (0 = A, 1 = B), with the keyphasor.
    #[inline]
    pub fn plane(&self, p: usize) -> Sample {
        Sample {
            seq: self.seq,
            t_s: self.t_s,
            sensor_v: [self.sensor_v[2 * p], self.sensor_v[2 * p + 1]],
            speed_rad_s: self.speed_rad_s,
            angle_rad: self.angle_rad,
        }
    }
}

/// A sampled control law of one bearing plane: one call per controller tick.
///
/// State lives in `self`, so a law is deterministic given its sample sequence;
/// the caller owns time (it is in the sample), never the law.
pub trait ControlLaw: Send {
    /// The law's registry name (`controller.law`).
    fn name(&self) -> &'static str;
    /// One tick: coil currents per axis (A), x then y, before the amplifier limit.
    fn update(&mut self, sample: &Sample) -> [f64; 2];
    /// Forget all memory (back to the state before the first sample).
    fn reset(&mut self);
    /// The PD this law is while the rotor levitates (read at each sample, the rate as the
    /// backward difference, as `pd` does): what `plant assess` takes the sampled loop's closed
    /// form of. `None` (the default) for a law that is no such PD; `plant assess` then grades
    /// the law by measurement alone.
    fn linear_pd(&self) -> Option<LinearPd> {
        None
    }
    /// The law around levitation as a linear filter of each axis: its PD ([`LinearPd`], read at
    /// each sample, the rate as the backward difference) behind an optional second-order filter
    /// of the sensor voltage (a notch). What `plant assess` takes a flexible rotor's closed form
    /// of. The default: [`ControlLaw::linear_pd`] with no filter.
    fn linear(&self) -> Option<LinearLaw> {
        self.linear_pd().map(|pd| LinearLaw { pd, filter: None })
    }
    /// Whether the law starts holding its plane's weight itself, without the gravity bias: an
    /// integrator preloaded with the weight's current on its y axis (`ross_pid` with
    /// `controller.gravity_bias = false`: ROSS's way, the integral carries the weight), so that
    /// at the plant's rest, where the sensors read zero, its first command is the static one
    /// (docs/MODEL.md §13.6). The default: `false`.
    fn holds_weight_at_rest(&self) -> bool {
        false
    }
}

/// A law around levitation as a linear filter ([`ControlLaw::linear`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearLaw {
    /// The PD on the filtered voltage.
    pub pd: LinearPd,
    /// The filter ahead of it, `y_k = b₀ u_k + b₁ u_{k−1} + b₂ u_{k−2} − a₁ y_{k−1} − a₂ y_{k−2}`:
    /// `([b₀, b₁, b₂], [a₁, a₂])`.
    pub filter: Option<([f64; 3], [f64; 2])>,
}

/// The gains of a PD around levitation ([`ControlLaw::linear_pd`]): `i = bias − A_a (k_p u + k_d u̇)`
/// on the sensor voltage `u`, as `controller::PdGains` writes them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearPd {
    /// Proportional gain `k_p` (as `PdGains::kp`).
    pub kp: f64,
    /// Derivative gain `k_d` (s, as `PdGains::kd`).
    pub kd: f64,
}

/// A sampled control law of the whole rotor: every axis in, every current out, one call per
/// controller tick. Implement it for a law that couples the planes (centralised, modal); a
/// per-plane [`ControlLaw`] becomes one through [`Decentralised`].
pub trait RotorLaw: Send {
    /// The law's registry name (`controller.law`).
    fn name(&self) -> &'static str;
    /// One tick: coil currents (A) per axis in axis order, before the amplifier limits;
    /// entries past `sample.axes` are ignored.
    fn update(&mut self, sample: &RotorSample) -> [f64; ROTOR_AXES];
    /// Forget all memory (back to the state before the first sample).
    fn reset(&mut self);
}

/// A per-plane law's constructor: from the plane's design and the law's own parameters.
pub type BuildLaw = fn(&Design, &Params) -> Result<Box<dyn ControlLaw>, LawError>;

/// A rotor law's constructor: from the whole rotor's design and the law's own parameters.
pub type BuildRotorLaw = fn(&RotorDesign, &Params) -> Result<Box<dyn RotorLaw>, LawError>;

/// A per-plane law as it is offered: its name, a one-line summary and its constructor. Each
/// law's file defines one (`controller::pd::LAW`, …); the registry lists the built-in ones,
/// and a crate of your own defines its own and hands it to `controller::serve`.
#[derive(Clone, Copy)]
pub struct LawEntry {
    /// The name `controller.law` selects it by (what [`ControlLaw::name`] reports).
    pub name: &'static str,
    /// One line for help texts and the guide (docs/guide/controllers.md).
    pub summary: &'static str,
    /// Builds the law from a plane's design and its own parameters; refuses parameters it
    /// does not know or that are out of range.
    pub build: BuildLaw,
}

impl std::fmt::Debug for LawEntry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LawEntry").field("name", &self.name).field("summary", &self.summary).finish()
    }
}

/// A law of the whole rotor as it is offered ([`LawEntry`]'s counterpart for [`RotorLaw`]).
#[derive(Clone, Copy)]
pub struct RotorLawEntry {
    /// The name `controller.law` selects it by (what [`RotorLaw::name`] reports).
    pub name: &'static str,
    /// One line for help texts and the guide (docs/guide/controllers.md).
    pub summary: &'static str,
    /// Builds the law from the rotor's design and its own parameters; refuses a rotor it
    /// cannot drive ([`LawError::Axes`]) and parameters it does not know or that are out of
    /// range.
    pub build: BuildRotorLaw,
}

impl std::fmt::Debug for RotorLawEntry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RotorLawEntry").field("name", &self.name).field("summary", &self.summary).finish()
    }
}

/// A law a controller offers: per plane or of the whole rotor.
///
/// ```
/// use controller::{build_among, AnyLaw, Params, RotorDesign, RotorSample};
/// let offered = [AnyLaw::from(controller::pd::LAW), AnyLaw::from(controller::modal::LAW)];
/// // A per-plane law on a two-plane rotor: one pd per plane, each from its plane's design.
/// let mut law = build_among(&offered, "pd", &RotorDesign::symmetric_study(), &Params::default()).unwrap();
/// let i = law.update(&RotorSample { axes: 4, ..Default::default() });
/// assert_eq!(i[0], 0.0); // centred: no x current, the gravity bias on y at both planes
/// assert!(i[1] > 0.5 && i[3] == i[1]);
/// let e = build_among(&offered, "pid", &RotorDesign::symmetric_study(), &Params::default()).err().unwrap();
/// assert_eq!(e.to_string(), "unknown controller law `pid` (known laws: pd, modal)");
/// ```
#[derive(Clone, Copy, Debug)]
pub enum AnyLaw {
    /// A per-plane law (decentralised on a two-plane rotor).
    Plane(LawEntry),
    /// A law of the whole rotor.
    Rotor(RotorLawEntry),
}

impl AnyLaw {
    /// The law's name.
    pub fn name(&self) -> &'static str {
        match self {
            AnyLaw::Plane(e) => e.name,
            AnyLaw::Rotor(e) => e.name,
        }
    }

    /// Its one-line summary.
    pub fn summary(&self) -> &'static str {
        match self {
            AnyLaw::Plane(e) => e.summary,
            AnyLaw::Rotor(e) => e.summary,
        }
    }

    /// Builds the law for a rotor: a rotor law from the whole design; a per-plane law once
    /// per plane, each from its plane's design, run side by side ([`Decentralised`]).
    pub fn build(&self, design: &RotorDesign, params: &Params) -> Result<Box<dyn RotorLaw>, LawError> {
        design.check()?;
        match self {
            AnyLaw::Rotor(e) => (e.build)(design, params),
            AnyLaw::Plane(e) => {
                let planes = design.planes().iter().map(|d| (e.build)(d, params)).collect::<Result<Vec<_>, _>>()?;
                Ok(Box::new(Decentralised::new(planes)))
            }
        }
    }
}

impl From<LawEntry> for AnyLaw {
    fn from(e: LawEntry) -> Self {
        AnyLaw::Plane(e)
    }
}

impl From<RotorLawEntry> for AnyLaw {
    fn from(e: RotorLawEntry) -> Self {
        AnyLaw::Rotor(e)
    }
}

/// Builds law `name` among `laws` (any kind) for a rotor; an unknown name is refused naming
/// the laws on offer.
pub fn build_among(
    laws: &[AnyLaw],
    name: &str,
    design: &RotorDesign,
    params: &Params,
) -> Result<Box<dyn RotorLaw>, LawError> {
    let Some(law) = laws.iter().find(|l| l.name() == name) else {
        return Err(LawError::Unknown { name: name.to_string(), known: laws.iter().map(AnyLaw::name).collect() });
    };
    law.build(design, params)
}

/// Per-plane laws run side by side: plane p's law reads axes 2p, 2p + 1 and drives them.
/// One plane on the planar model; the arithmetic is then exactly the per-plane law's.
pub struct Decentralised {
    planes: Vec<Box<dyn ControlLaw>>,
}

impl Decentralised {
    /// One law per plane, A first (one or two).
    pub fn new(planes: Vec<Box<dyn ControlLaw>>) -> Self {
        assert!(matches!(planes.len(), 1 | 2), "one law per bearing plane: 1 or 2, not {}", planes.len());
        Self { planes }
    }

    /// Plane `p`'s law.
    pub fn plane(&self, p: usize) -> &dyn ControlLaw {
        self.planes[p].as_ref()
    }
}

impl RotorLaw for Decentralised {
    fn name(&self) -> &'static str {
        self.planes[0].name()
    }

    #[inline]
    fn update(&mut self, sample: &RotorSample) -> [f64; ROTOR_AXES] {
        let mut out = [0.0; ROTOR_AXES];
        for (p, law) in self.planes.iter_mut().enumerate() {
            let i = law.update(&sample.plane(p));
            out[2 * p] = i[0];
            out[2 * p + 1] = i[1];
        }
        out
    }

    fn reset(&mut self) {
        for law in &mut self.planes {
            law.reset();
        }
    }
}

/// One axis current saturated at `|i| ≤ limit` (A); a non-finite current (NaN, ±∞) is no
/// current at all and becomes NaN, never the limit: the plant counts it as an invalid command,
/// whichever side (the plant, or a controller process) saturates it.
#[inline]
fn saturate_one(i: f64, limit: f64) -> f64 {
    if i.is_finite() {
        i.clamp(-limit, limit)
    } else {
        f64::NAN
    }
}

/// Clamps each axis current to `|i| ≤ limit` (A); a non-finite one (NaN, ±∞) becomes NaN, which
/// the plant holds, counts and judges as an invalid command (`controller.max_invalid_burst`),
/// where a clamp would have made +∞ a valid full-scale current.
///
/// ```
/// assert_eq!(controller::saturate([3.0, -0.5], 2.0), [2.0, -0.5]);
/// let [x, y] = controller::saturate([f64::INFINITY, f64::NEG_INFINITY], 2.0);
/// assert!(x.is_nan() && y.is_nan());
/// ```
#[inline]
pub fn saturate(i: [f64; 2], limit: f64) -> [f64; 2] {
    [saturate_one(i[0], limit), saturate_one(i[1], limit)]
}

/// Clamps each axis current to its own limit (A) ([`RotorDesign::current_limits`]); a
/// non-finite one becomes NaN, as in [`saturate`].
///
/// ```
/// assert_eq!(controller::saturate_axes([3.0, -0.5, -4.0, 1.0], [2.0, 2.0, 1.5, 1.5]), [2.0, -0.5, -1.5, 1.0]);
/// assert!(controller::saturate_axes([0.0, 0.0, f64::INFINITY, 0.0], [2.0; 4])[2].is_nan());
/// ```
#[inline]
pub fn saturate_axes(i: [f64; ROTOR_AXES], limits: [f64; ROTOR_AXES]) -> [f64; ROTOR_AXES] {
    std::array::from_fn(|k| saturate_one(i[k], limits[k]))
}

/// A rotor angle wrapped into [0, 2π) (rad), as the keyphasor reports it; a non-finite
/// angle stays non-finite.
///
/// ```
/// use std::f64::consts::TAU;
/// assert!((controller::wrap_angle(TAU + 1.0) - 1.0).abs() < 1e-15);
/// assert_eq!(controller::wrap_angle(-1e-300), 0.0); // would round up to 2π
/// assert!(controller::wrap_angle(-1.0) > 5.28);
/// ```
#[inline]
pub fn wrap_angle(theta: f64) -> f64 {
    let r = theta.rem_euclid(std::f64::consts::TAU);
    // rem_euclid rounds a tiny negative angle up to 2π exactly: that is angle 0.
    if r >= std::f64::consts::TAU {
        0.0
    } else {
        r
    }
}
