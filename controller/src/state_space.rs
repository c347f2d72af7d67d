//! `state_space`: a controller of every axis at once given as a state-space system `(A, B, C, D)`
//! (python-control's `ss`, MATLAB's `ss`, an LQG or H∞ design): the sensor voltages of every
//! axis in (V, axis order x_A, y_A[, x_B, y_B]), the current commands out (A), added to the
//! design's bias currents (the gravity bias on y, as `pd`'s, per plane); the amplifier limits
//! apply as for any law. It drives the planar model (2 axes) and the two-plane rotor (4).
//!
//! # Parameters (`[controller.params]`)
//!
//! | key | unit | default | meaning |
//! |---|---|---|---|
//! | `a` | – | – | A, n × n (rows of numbers), n ≤ [`MAX_STATES`] |
//! | `b` | – | – | B, n × axes |
//! | `c` | A/V | – | C, axes × n |
//! | `d` | A/V | zeros | D, axes × axes |
//! | `domain` | – | `"s"` | `"s"`: continuous, discretised here; `"z"`: given discrete |
//! | `discretisation` | – | `"tustin"` | `"tustin"` or `"zoh"`; `domain = "s"` only |
//! | `prewarp_hz` | Hz | none | Tustin's prewarp frequency (> 0, below Nyquist) |
//! | `dt_s` | s | – | the discrete system's period; required with `domain = "z"`, must be the scene's controller period |
//!
//! | `file` | – | none | a JSON file `{"A": …, "B": …, "C": …, "D": …, "dt": 0}` or numpy's `.npz` of the same (python-control's `StateSpace` fields; `dt` 0 or absent: continuous, else the controller's period) instead of `a` … `d`, `domain`, `dt_s` |
//!
//! `a`, `b`, `c` are given together or not at all; none of them: the design's PD per axis as
//! `pd` samples it (one state per axis, the previous voltage), the sign convention written out.
//! An unstable controller is allowed.
//!
//! # Discretisation (at the controller's period `T`), as python-control's `sample_system`
//!
//! * **Zero-order hold**: `A_d = e^{AT}`, `B_d = ∫₀ᵀ e^{As} ds B` from one matrix exponential of
//!   `[[A, B], [0, 0]] T` (Van Loan), `C_d = C`, `D_d = D` (scipy's `cont2discrete`).
//! * **Tustin** (scipy's generalised bilinear transform, α = ½), with `T_w = T`, or
//!   `2 tan(ω_w T/2)/ω_w` prewarped at `ω_w`: `M = I − A T_w/2`, `A_d = M⁻¹ (I + A T_w/2)`,
//!   `B_d = M⁻¹ B T_w`, `C_d = C M⁻¹`, `D_d = D + C B_d / 2`.
//!
//! # Running
//!
//! From rest (`x₀ = 0`): `y_k = C_d x_k + D_d u_k`, `x_{k+1} = A_d x_k + B_d u_k`, `i_k = bias + y_k`,
//! in buffers allocated once when the law is built.

use crate::design::{RotorDesign, ROTOR_AXES};
use crate::discretisation::{self, Domain};
use crate::error::LawError;
use crate::law::{RotorLaw, RotorLawEntry, RotorSample};
use crate::law_file::LawFile;
use crate::params::{Check, ParamReader, Params};
use crate::pd::PdGains;
pub use nalgebra::DMatrix;

/// The most states the law takes.
pub const MAX_STATES: usize = 64;

/// `state_space` and its parameters (the module doc's table).
pub const LAW: RotorLawEntry = RotorLawEntry {
    name: "state_space",
    summary: "a state-space system (A, B, C, D) of every axis at once, sensor V to current A, continuous \
              (Tustin with optional prewarp, or zero-order hold, at the controller rate) or discrete \
              (params a, b, c, d, domain, discretisation, prewarp_hz, dt_s, file)",
    build,
};

fn build(design: &RotorDesign, params: &Params) -> Result<Box<dyn RotorLaw>, LawError> {
    let system = discrete(design, params)?;
    let mut bias = [0.0; ROTOR_AXES];
    for (k, plane) in design.planes().iter().enumerate() {
        let b = PdGains::from_design(&plane.pd(), &plane.constants)?.bias_a;
        bias[2 * k..2 * k + 2].copy_from_slice(&b);
    }
    Ok(Box::new(StateSpace::new(system, bias)))
}

/// The discrete system the law runs on `design` with `params` (read, checked and discretised as
/// [`LAW`] builds it): the law's linear form, which the plant's margins are computed from.
pub fn discrete(design: &RotorDesign, params: &Params) -> Result<DiscreteSs, LawError> {
    design.check()?;
    let mut p = params.reader(LAW.name);
    let system = read(&mut p, design)?;
    p.finish()?;
    Ok(system)
}

/// A discrete state-space system `(A_d, B_d, C_d, D_d)`.
#[derive(Clone, Debug, PartialEq)]
pub struct DiscreteSs {
    /// A_d (n × n).
    pub a: DMatrix<f64>,
    /// B_d (n × axes).
    pub b: DMatrix<f64>,
    /// C_d (axes × n).
    pub c: DMatrix<f64>,
    /// D_d (axes × axes).
    pub d: DMatrix<f64>,
}

pub use crate::discretisation::Method;

fn matrix(rows: &[Vec<f64>]) -> DMatrix<f64> {
    let (r, c) = (rows.len(), rows.first().map_or(0, Vec::len));
    DMatrix::from_fn(r, c, |i, j| rows[i][j])
}

fn read(p: &mut ParamReader<'_>, design: &RotorDesign) -> Result<DiscreteSs, LawError> {
    let period_s = design.plane_a().period_s;
    let axes = design.axes() as usize;
    let file = p.optional_text("file")?;
    let mut given = (p.optional_matrix("a", "")?, p.optional_matrix("b", "")?, p.optional_matrix("c", "A/V")?);
    let mut d = p.optional_matrix("d", "A/V")?;
    // From a file: A, B, C, D and the period (0 or absent: continuous), as python-control's
    // StateSpace holds them.
    let mut from_file: Option<(String, Option<f64>)> = None;
    if let Some(path) = file {
        if given.0.is_some() || given.1.is_some() || given.2.is_some() || d.is_some() {
            return Err(p.error(
                "file",
                format!("{path:?}"),
                "",
                "a, b, c, d come from the file: not also in [controller.params]",
            ));
        }
        let f = LawFile::read(p, &path, r#"{"A": [[...]], "B": [[...]], "C": [[...]], "D": [[...]], "dt": 0}"#)?;
        given = (Some(f.matrix(p, "A")?), Some(f.matrix(p, "B")?), Some(f.matrix(p, "C")?));
        d = if f.has("D") { Some(f.matrix(p, "D")?) } else { None };
        let dt = f.number(p, "dt")?.filter(|dt| *dt != 0.0);
        if let Some(dt) = dt {
            if !(dt > 0.0 && (dt - period_s).abs() <= 1e-9 * period_s) {
                return Err(p.error(
                    "file",
                    format!("{path:?}"),
                    "",
                    format!("its `dt` = {dt} s must be 0 (continuous) or the scene's controller period, {period_s} s"),
                ));
            }
        }
        from_file = Some((path, dt));
    }
    let (a, b, c) = match given {
        (Some(a), Some(b), Some(c)) => (a, b, c),
        (None, None, None) => {
            let why = "only with a, b and c (without them the law is the design's PD)";
            if let Some(v) = d {
                return Err(p.error("d", format!("{v:?}"), "A/V", why));
            }
            for key in ["domain", "discretisation"] {
                if let Some(v) = p.optional_text(key)? {
                    return Err(p.error(key, format!("{v:?}"), "", why));
                }
            }
            if let Some(v) = p.optional_number("prewarp_hz", "Hz", Check::Finite)? {
                return Err(p.error("prewarp_hz", v, "Hz", why));
            }
            if let Some(v) = p.optional_number("dt_s", "s", Check::Finite)? {
                return Err(p.error("dt_s", v, "s", why));
            }
            return pd_system(design);
        }
        (a, b, c) => {
            let missing = [("a", a.is_none()), ("b", b.is_none()), ("c", c.is_none())]
                .iter()
                .filter(|(_, m)| *m)
                .map(|(k, _)| *k)
                .collect::<Vec<_>>()
                .join(", ");
            let key = if missing.starts_with('a') {
                "a"
            } else if missing.starts_with('b') {
                "b"
            } else {
                "c"
            };
            return Err(p.error(key, "(not set)", "", format!("a, b and c go together: {missing} not set")));
        }
    };
    let n = a.len();
    let size = |p: &ParamReader<'_>, key: &'static str, m: &[Vec<f64>], rows: usize, cols: usize, what: &str| {
        let (r, c) = (m.len(), m.first().map_or(0, Vec::len));
        let why = format!("is {r} × {c}: expected {rows} × {cols} ({what})");
        match (&from_file, (r, c) == (rows, cols)) {
            (_, true) => Ok(()),
            // From a file: the file named, and the variable as it is called there.
            (Some((path, _)), false) => {
                Err(p.error("file", format!("{path:?}"), "", format!("its `{}` {why}", key.to_uppercase())))
            }
            (None, false) => Err(p.error(key, format!("{m:?}"), "", why)),
        }
    };
    if n == 0 || n > MAX_STATES {
        let why = format!("expected 1 to {MAX_STATES} states (rows)");
        return Err(match &from_file {
            Some((path, _)) => p.error("file", format!("{path:?}"), "", format!("its `A` has {n} rows: {why}")),
            None => p.error("a", format!("{a:?}"), "", why),
        });
    }
    size(p, "a", &a, n, n, "square: states × states")?;
    size(p, "b", &b, n, axes, &format!("states × axes, this rotor has {axes} axes"))?;
    size(p, "c", &c, axes, n, &format!("axes × states, this rotor has {axes} axes"))?;
    let d = match d {
        Some(d) => {
            size(p, "d", &d, axes, axes, &format!("axes × axes, this rotor has {axes} axes"))?;
            matrix(&d)
        }
        None => DMatrix::zeros(axes, axes),
    };
    let (a, b, c) = (matrix(&a), matrix(&b), matrix(&c));
    let system =
        match discretisation::read(p, from_file.as_ref(), period_s, "a continuous system", "a discrete system")? {
            Domain::Continuous(method) => match discretise(&a, &b, &c, &d, period_s, method) {
                Some(s) => s,
                None => {
                    return Err(p.error(
                        "a",
                        format!("{a}").replace('\n', " "),
                        "",
                        "I − A T/2 is singular: A has an eigenvalue at 2/T, where Tustin has no image",
                    ))
                }
            },
            Domain::Discrete => DiscreteSs { a, b, c, d },
        };
    let finite = |m: &DMatrix<f64>| m.iter().all(|v| v.is_finite());
    if !(finite(&system.a) && finite(&system.b) && finite(&system.c) && finite(&system.d)) {
        return Err(p.error("a", "(as given)", "", format!("discretised at {period_s} s, the matrices overflow")));
    }
    Ok(system)
}

/// The design's PD per axis as `pd` samples it: state = the previous voltage,
/// `y = −A_a ((k_p + k_d/T) u − (k_d/T) x)`.
fn pd_system(design: &RotorDesign) -> Result<DiscreteSs, LawError> {
    let axes = design.axes() as usize;
    let mut c = DMatrix::zeros(axes, axes);
    let mut d = DMatrix::zeros(axes, axes);
    for (k, plane) in design.planes().iter().enumerate() {
        let g = PdGains::from_design(&plane.pd(), &plane.constants)?;
        let t = plane.period_s;
        for axis in [2 * k, 2 * k + 1] {
            c[(axis, axis)] = g.amp_gain_a_per_v * g.kd / t;
            d[(axis, axis)] = -g.amp_gain_a_per_v * (g.kp + g.kd / t);
        }
    }
    Ok(DiscreteSs { a: DMatrix::zeros(axes, axes), b: DMatrix::identity(axes, axes), c, d })
}

/// `(A, B, C, D)` discretised at `period_s` (s); `None` if Tustin's `I − A T_w/2` is singular.
pub fn discretise(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    c: &DMatrix<f64>,
    d: &DMatrix<f64>,
    period_s: f64,
    method: Method,
) -> Option<DiscreteSs> {
    let n = a.nrows();
    let m = b.ncols();
    match method {
        Method::Zoh => {
            let mut aug = DMatrix::<f64>::zeros(n + m, n + m);
            aug.view_mut((0, 0), (n, n)).copy_from(&(a * period_s));
            aug.view_mut((0, n), (n, m)).copy_from(&(b * period_s));
            let e = aug.exp();
            Some(DiscreteSs {
                a: e.view((0, 0), (n, n)).into_owned(),
                b: e.view((0, n), (n, m)).into_owned(),
                c: c.clone(),
                d: d.clone(),
            })
        }
        Method::Tustin { prewarp_rad_s } => {
            let tw = match prewarp_rad_s {
                Some(w) => 2.0 * (w * period_s / 2.0).tan() / w,
                None => period_s,
            };
            let identity = DMatrix::<f64>::identity(n, n);
            let lu = (&identity - a * (tw / 2.0)).lu();
            let ad = lu.solve(&(&identity + a * (tw / 2.0)))?;
            let bd = lu.solve(&(b * tw))?;
            // C M⁻¹ = (M⁻ᵀ Cᵀ)ᵀ.
            let cd = (&identity - a * (tw / 2.0)).transpose().lu().solve(&c.transpose())?.transpose();
            let dd = d + c * &bd * 0.5;
            Some(DiscreteSs { a: ad, b: bd, c: cd, d: dd })
        }
    }
}

/// The law: the discrete system from rest, plus the bias.
#[derive(Clone, Debug)]
pub struct StateSpace {
    sys: DiscreteSs,
    x: Vec<f64>,
    next: Vec<f64>,
    bias: [f64; ROTOR_AXES],
}

impl StateSpace {
    /// The law of discrete system `sys` with bias currents `bias` (A, axis order), from rest.
    pub fn new(sys: DiscreteSs, bias: [f64; ROTOR_AXES]) -> Self {
        let n = sys.a.nrows();
        Self { sys, x: vec![0.0; n], next: vec![0.0; n], bias }
    }

    /// The discrete system it runs.
    pub fn system(&self) -> &DiscreteSs {
        &self.sys
    }
}

impl RotorLaw for StateSpace {
    fn name(&self) -> &'static str {
        LAW.name
    }

    fn update(&mut self, s: &RotorSample) -> [f64; ROTOR_AXES] {
        let (n, m) = (self.sys.a.nrows(), self.sys.b.ncols());
        let u = &s.sensor_v[..m];
        let mut out = self.bias;
        for (i, o) in out.iter_mut().enumerate().take(m) {
            let mut y = 0.0;
            for j in 0..n {
                y += self.sys.c[(i, j)] * self.x[j];
            }
            for (j, uj) in u.iter().enumerate() {
                y += self.sys.d[(i, j)] * uj;
            }
            *o += y;
        }
        for i in 0..n {
            let mut v = 0.0;
            for j in 0..n {
                v += self.sys.a[(i, j)] * self.x[j];
            }
            for (j, uj) in u.iter().enumerate() {
                v += self.sys.b[(i, j)] * uj;
            }
            self.next[i] = v;
        }
        std::mem::swap(&mut self.x, &mut self.next);
        out
    }

    fn reset(&mut self) {
        self.x.iter_mut().for_each(|v| *v = 0.0);
    }
}

#[cfg(test)]
mod tests;
