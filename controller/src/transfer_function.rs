//! `transfer_function`: a controller designed elsewhere (python-control, MATLAB, ROSS's
//! `controller_transfer_function`) given as a transfer function, the same on every axis: sensor
//! voltage in (V), coil current command out (A), added to the design's bias currents (the
//! gravity bias on y, as `pd`'s); the amplifier limit applies as for any law.
//!
//! # Parameters (`[controller.params]`)
//!
//! | key | unit | default | meaning |
//! |---|---|---|---|
//! | `num` | A/V | – (required) | numerator, descending powers of `s` (or of `z`), as `control.tf(num, den)` |
//! | `den` | – | – (required) | denominator, descending powers; its leading coefficient non-zero |
//! | `domain` | – | `"s"` | `"s"`: continuous, discretised here; `"z"`: given discrete |
//! | `discretisation` | – | `"tustin"` | `"tustin"` (bilinear) or `"zoh"` (zero-order hold); `domain = "s"` only |
//! | `prewarp_hz` | Hz | none | Tustin's prewarp frequency (> 0, below Nyquist); `"tustin"` only |
//! | `dt_s` | s | – | the discrete law's sampling period; required with `domain = "z"`, must be the scene's controller period |
//! | `file` | – | none | a JSON file holding `num`, `den`, `dt` instead |
//!
//! Neither `num` nor `den` given: the design's PD as `pd` samples it (`controller.stiffness_n_per_m`,
//! `damping_ratio`), `C(z) = −A_a ((k_p + k_d/T) − (k_d/T) z⁻¹)`: a law that levitates, and the
//! sign convention written out (a restoring law has a negative DC gain: `i = bias + C u`).
//! Unlike `pd`, whose first rate is zero, the transfer starts from rest (`u₋₁ = 0`).
//!
//! `file`: the path of a JSON object `{"num": [...], "den": [...], "dt": 0}` or numpy's `.npz` of
//! the same arrays (python-control's
//! `TransferFunction` fields; `dt` 0 or absent: in `s`, else in `z` and the controller's period)
//! instead of `num`, `den`, `domain` and `dt_s` ([`crate::law_file`]).
//!
//! The transfer must be proper (the numerator's degree at most the denominator's: a causal
//! law), of order at most [`MAX_ORDER`], every coefficient finite. An unstable controller is
//! allowed (some designs are).
//!
//! # Discretisation (at the controller's period `T`)
//!
//! * **Tustin**: `s = K (z − 1)/(z + 1)` with `K = 2/T`, or with a prewarp frequency `ω_w`,
//!   `K = ω_w / tan(ω_w T/2)` (the sampled law's response at `ω_w` is then exactly the continuous
//!   one's). Exactly python-control's `sample_system(sys, T, 'tustin', prewarp_frequency=ω_w)`
//!   (which shrinks the period to `2 tan(ω_w T/2)/ω_w` instead): polynomial arithmetic,
//!   `N(s) = Σ n_k s^k` becomes `Σ n_k K^k (z − 1)^k (z + 1)^(n−k)`, likewise `D`.
//! * **Zero-order hold**: the controllable canonical realisation `(A, B, C, D)` of the transfer
//!   (scipy's `tf2ss`), `Φ = e^{AT}`, `Γ = ∫₀ᵀ e^{As} ds B` from one matrix exponential of the
//!   augmented `[[A, B], [0, 0]] T` (Van Loan, nalgebra's Padé with scaling and squaring), and
//!   back to a transfer: `den = det(zI − Φ)`, `num = det(zI − Φ + Γ C) + (D − 1) den` (scipy's
//!   `ss2tf`). The characteristic polynomials by Faddeev–LeVerrier, written here because
//!   nalgebra has none (a few lines; exact enough for the orders a law has, see the tests).
//!
//! Both give `b(z)/a(z)` normalised to `a₀ = 1`, as python-control's result is.
//!
//! # Running
//!
//! Each axis runs the difference equation in transposed direct form II from rest (every state
//! zero before the first sample), its state allocated once when the law is built:
//!
//! ```text
//! y_k = b₀ u_k + s₁        s_j ← b_j u_k − a_j y_k + s_{j+1}  (s_{n+1} = 0)        i_k = bias + y_k
//! ```

use crate::discretisation::{self, Domain};
use crate::law::{ControlLaw, Design, LawEntry, LawError, Sample};
use crate::law_file::LawFile;
use crate::params::{Check, ParamReader, Params};
use crate::pd::PdGains;
use nalgebra::DMatrix;

/// The highest order a transfer may have (the denominator's degree).
pub const MAX_ORDER: usize = 20;

/// `transfer_function` and its parameters (the module doc's table).
pub const LAW: LawEntry = LawEntry {
    name: "transfer_function",
    summary: "a transfer function on every axis, sensor V to current A, in s (Tustin with optional prewarp, or \
              zero-order hold, at the controller rate) or in z (params num, den, domain, discretisation, \
              prewarp_hz, dt_s, file)",
    build,
};

fn build(design: &Design, params: &Params) -> Result<Box<dyn ControlLaw>, LawError> {
    let tf = discrete(design, params)?;
    let bias = PdGains::from_design(&design.pd(), &design.constants)?.bias_a;
    Ok(Box::new(TransferFunction::new(tf, bias)))
}

/// The discrete transfer the law runs on `design` with `params` (read, checked and discretised
/// as [`LAW`] builds it): the law's linear form, which the plant's margins are computed from.
pub fn discrete(design: &Design, params: &Params) -> Result<DiscreteTf, LawError> {
    let mut p = params.reader(LAW.name);
    let tf = read(&mut p, design)?;
    p.finish()?;
    Ok(tf)
}

pub use crate::discretisation::Method;

/// A discrete transfer `b(z)/a(z)`, descending powers of `z`, `a₀ = 1`, `b` as long as `a`.
#[derive(Clone, Debug, PartialEq)]
pub struct DiscreteTf {
    /// Numerator `b₀ … b_n`.
    pub b: Vec<f64>,
    /// Denominator `1, a₁ … a_n`.
    pub a: Vec<f64>,
}

fn coefficients(values: &[f64]) -> String {
    format!("{values:?}")
}

/// Reads and checks the law's parameters and discretises the transfer at `period_s`.
fn read(p: &mut ParamReader<'_>, design: &Design) -> Result<DiscreteTf, LawError> {
    let period_s = design.period_s;
    let file = p.optional_text("file")?;
    let (given_num, given_den) = (p.optional_numbers("num", "A/V")?, p.optional_numbers("den", "")?);
    // From a file: num, den and its period (0 or absent: continuous), as python-control's
    // TransferFunction holds them.
    let mut from_file: Option<(String, Option<f64>)> = None;
    let (num, den) = match (given_num, given_den) {
        (None, None) if file.is_some() => {
            let path = file.clone().unwrap_or_default();
            let f = LawFile::read(p, &path, r#"{"num": [...], "den": [...], "dt": 0}"#)?;
            let (num, den) = (f.numbers(p, "num")?, f.numbers(p, "den")?);
            let dt = f.number(p, "dt")?.filter(|dt| *dt != 0.0);
            if let Some(dt) = dt {
                if !(dt > 0.0 && (dt - period_s).abs() <= 1e-9 * period_s) {
                    return Err(p.error(
                        "file",
                        format!("{path:?}"),
                        "",
                        format!(
                            "its `dt` = {dt} s must be 0 (continuous) or the scene's controller period, {period_s} s"
                        ),
                    ));
                }
            }
            from_file = Some((path, dt));
            (num, den)
        }
        (Some(_), _) | (_, Some(_)) if file.is_some() => {
            return Err(p.error(
                "file",
                format!("{:?}", file.unwrap_or_default()),
                "",
                "num and den come from the file: not also in [controller.params]",
            ))
        }
        (Some(num), Some(den)) => (num, den),
        (None, None) => {
            // Neither given: the design's PD as `pd` samples it (module doc), a law that levitates.
            let g = PdGains::from_design(&design.pd(), &design.constants)?;
            let (a, t) = (g.amp_gain_a_per_v, design.period_s);
            let tf = normalise(&[-a * (g.kp + g.kd / t), a * g.kd / t], &[1.0, 0.0]);
            let why = "only with num and den (without them the law is the design's PD)";
            if let Some(v) = p.optional_text("domain")? {
                return Err(p.error("domain", format!("{v:?}"), "", why));
            }
            if let Some(v) = p.optional_text("discretisation")? {
                return Err(p.error("discretisation", format!("{v:?}"), "", why));
            }
            if let Some(v) = p.optional_number("prewarp_hz", "Hz", Check::Finite)? {
                return Err(p.error("prewarp_hz", v, "Hz", why));
            }
            if let Some(v) = p.optional_number("dt_s", "s", Check::Finite)? {
                return Err(p.error("dt_s", v, "s", why));
            }
            return Ok(tf);
        }
        (Some(_), None) => return Err(p.error("den", "(not set)", "", "num is given: den = [a0, a1, …] must be too")),
        (None, Some(_)) => {
            return Err(p.error("num", "(not set)", "A/V", "den is given: num = [b0, b1, …] must be too"))
        }
    };
    if den[0] == 0.0 {
        return Err(p.error("den", coefficients(&den), "", "the leading coefficient must not be zero"));
    }
    // Leading zeros of the numerator lower its degree: harmless.
    let first = num.iter().position(|&v| v != 0.0).unwrap_or(num.len() - 1);
    let num = num[first..].to_vec();
    if num.len() > den.len() {
        return Err(p.error(
            "num",
            coefficients(&num),
            "A/V",
            format!(
                "an improper transfer (numerator of degree {} over a denominator of degree {}): the degree of num \
                 must be at most den's",
                num.len() - 1,
                den.len() - 1
            ),
        ));
    }
    if den.len() - 1 > MAX_ORDER {
        return Err(p.error("den", coefficients(&den), "", format!("order {} above {MAX_ORDER}", den.len() - 1)));
    }
    let tf = match discretisation::read(p, from_file.as_ref(), period_s, "a transfer in s", "a law in z")? {
        Domain::Continuous(method) => discretise(&num, &den, period_s, method),
        Domain::Discrete => normalise(&num, &den),
    };
    if !tf.b.iter().chain(&tf.a).all(|v| v.is_finite()) {
        return Err(p.error(
            "den",
            coefficients(&den),
            "",
            format!("discretised at {period_s} s, the coefficients overflow: {:?} / {:?}", tf.b, tf.a),
        ));
    }
    Ok(tf)
}

/// `num/den` (descending powers, `den[0] ≠ 0`, `num` no longer than `den`) as [`DiscreteTf`]:
/// divided by `den[0]`, the numerator padded with leading zeros.
pub fn normalise(num: &[f64], den: &[f64]) -> DiscreteTf {
    let a0 = den[0];
    let mut b = vec![0.0; den.len() - num.len()];
    b.extend(num.iter().map(|v| v / a0));
    DiscreteTf { b, a: den.iter().map(|v| v / a0).collect() }
}

/// The transfer `num(s)/den(s)` (as [`normalise`] takes it) discretised at `period_s` (s).
pub fn discretise(num: &[f64], den: &[f64], period_s: f64, method: Method) -> DiscreteTf {
    match method {
        Method::Tustin { prewarp_rad_s } => {
            let k = match prewarp_rad_s {
                Some(w) => w / (w * period_s / 2.0).tan(),
                None => 2.0 / period_s,
            };
            tustin(num, den, k)
        }
        Method::Zoh => zoh(num, den, period_s),
    }
}

fn poly_mul(a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    out
}

/// `p(s)` of degree ≤ n under `s = K (z − 1)/(z + 1)`, times `(z + 1)^n`: descending in `z`.
fn bilinear(p: &[f64], n: usize, k: f64) -> Vec<f64> {
    let mut out = vec![0.0; n + 1];
    // p[i] is the coefficient of s^(len − 1 − i).
    for (i, c) in p.iter().enumerate() {
        let power = p.len() - 1 - i;
        let mut term = vec![c * k.powi(power as i32)];
        for _ in 0..power {
            term = poly_mul(&term, &[1.0, -1.0]);
        }
        for _ in power..n {
            term = poly_mul(&term, &[1.0, 1.0]);
        }
        for (o, t) in out.iter_mut().zip(&term) {
            *o += t;
        }
    }
    out
}

fn tustin(num: &[f64], den: &[f64], k: f64) -> DiscreteTf {
    let n = den.len() - 1;
    normalise(&bilinear(num, n, k), &bilinear(den, n, k))
}

/// Faddeev–LeVerrier: `det(zI − M) = Σ p_k z^(n−k)` (descending, `p₀ = 1`) and the matrices
/// `M_k` of `adj(zI − M) = Σ_{k=1..n} M_k z^(n−k)`.
fn faddeev_leverrier(m: &DMatrix<f64>) -> (Vec<f64>, Vec<DMatrix<f64>>) {
    let n = m.nrows();
    let identity = DMatrix::<f64>::identity(n, n);
    let mut p = vec![1.0];
    let mut adj = Vec::with_capacity(n);
    let mut mk = identity.clone();
    for k in 1..=n {
        let product = m * &mk;
        p.push(-product.trace() / k as f64);
        adj.push(mk);
        mk = product + &identity * p[k];
    }
    (p, adj)
}

fn zoh(num: &[f64], den: &[f64], period_s: f64) -> DiscreteTf {
    let monic = normalise(num, den);
    let n = den.len() - 1;
    if n == 0 {
        return monic;
    }
    let (b, a) = (&monic.b, &monic.a);
    let d = b[0];
    // Controllable canonical form (scipy's tf2ss): A's first row −a₁ … −a_n, ones below the
    // diagonal; B = e₁; C_j = b_j − b₀ a_j.
    let mut aug = DMatrix::<f64>::zeros(n + 1, n + 1);
    for j in 0..n {
        aug[(0, j)] = -a[j + 1] * period_s;
    }
    for i in 1..n {
        aug[(i, i - 1)] = period_s;
    }
    aug[(0, n)] = period_s;
    let e = aug.exp();
    let phi = e.view((0, 0), (n, n)).into_owned();
    let gamma = e.view((0, n), (n, 1)).into_owned();
    let c = DMatrix::from_fn(1, n, |_, j| b[j + 1] - d * a[j + 1]);
    // num = C adj(zI − Φ) Γ + D det(zI − Φ), term by term. (scipy's ss2tf takes the difference
    // det(zI − Φ + ΓC) − det(zI − Φ) instead, which cancels: on 1/s² at 20 kHz its numerator
    // is off by 8e-8 relative; see the tests.)
    let (den_d, adj) = faddeev_leverrier(&phi);
    let mut num_d = vec![d];
    for (k, m) in adj.iter().enumerate() {
        num_d.push((&c * m * &gamma)[(0, 0)] + d * den_d[k + 1]);
    }
    DiscreteTf { b: num_d, a: den_d }
}

/// The law: one transposed direct form II filter per axis, plus the bias.
#[derive(Clone, Debug)]
pub struct TransferFunction {
    tf: DiscreteTf,
    state: [Vec<f64>; 2],
    bias: [f64; 2],
}

impl TransferFunction {
    /// The law of discrete transfer `tf` with bias currents `bias` (A, x then y), from rest.
    pub fn new(tf: DiscreteTf, bias: [f64; 2]) -> Self {
        let n = tf.a.len() - 1;
        Self { tf, state: [vec![0.0; n], vec![0.0; n]], bias }
    }

    /// The discrete transfer it runs.
    pub fn transfer(&self) -> &DiscreteTf {
        &self.tf
    }
}

impl ControlLaw for TransferFunction {
    fn name(&self) -> &'static str {
        LAW.name
    }

    fn update(&mut self, s: &Sample) -> [f64; 2] {
        let (b, a) = (&self.tf.b, &self.tf.a);
        let n = a.len() - 1;
        let mut out = [0.0; 2];
        for (axis, state) in self.state.iter_mut().enumerate() {
            let u = s.sensor_v[axis];
            let y = b[0] * u + state.first().copied().unwrap_or(0.0);
            for j in 1..n {
                state[j - 1] = b[j] * u - a[j] * y + state[j];
            }
            if n > 0 {
                state[n - 1] = b[n] * u - a[n] * y;
            }
            out[axis] = self.bias[axis] + y;
        }
        out
    }

    fn reset(&mut self) {
        for s in &mut self.state {
            s.iter_mut().for_each(|v| *v = 0.0);
        }
    }
}

#[cfg(test)]
mod tests;
