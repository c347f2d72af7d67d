//! How a law given as a linear system (`transfer_function`, `state_space`) is made discrete:
//! the keys `domain`, `discretisation`, `prewarp_hz` and `dt_s` of `[controller.params]`, read
//! and checked together, once for both laws.

use crate::error::LawError;
use crate::params::{Check, ParamReader};

/// How a continuous system becomes discrete.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// Bilinear, with an optional prewarp frequency (rad/s).
    Tustin {
        /// ω_w (rad/s), if any.
        prewarp_rad_s: Option<f64>,
    },
    /// Zero-order hold.
    Zoh,
}

/// The domain a law is given in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Domain {
    /// In `s`, to be discretised at the controller's period by this method.
    Continuous(Method),
    /// In `z`, at the controller's period already.
    Discrete,
}

/// Reads the discretisation keys of a law whose controller runs at `period_s` (s). `from_file`:
/// the file the system came from and its `dt` (none: continuous), which then sets the domain
/// (`domain` and `dt_s` refused beside it). `continuous` and `discrete` name the law's forms in
/// the messages ("a transfer in s", "a law in z").
pub fn read(
    p: &mut ParamReader<'_>,
    from_file: Option<&(String, Option<f64>)>,
    period_s: f64,
    continuous: &str,
    discrete: &str,
) -> Result<Domain, LawError> {
    let domain = p.optional_text("domain")?;
    let method = p.optional_text("discretisation")?;
    let prewarp_hz = p.optional_number("prewarp_hz", "Hz", Check::Positive)?;
    let dt_s = p.optional_number("dt_s", "s", Check::Positive)?;
    let (domain, dt_s) = match from_file {
        None => (domain.unwrap_or_else(|| "s".into()), dt_s),
        Some((path, dt)) => {
            let why = format!("the file {path:?} gives it (its `dt`)");
            if let Some(v) = domain {
                return Err(p.error("domain", format!("{v:?}"), "", why));
            }
            if let Some(v) = dt_s {
                return Err(p.error("dt_s", v, "s", why));
            }
            (if dt.is_some() { "z" } else { "s" }.to_string(), *dt)
        }
    };
    let nyquist = 0.5 / period_s;
    match domain.as_str() {
        "s" => {
            if let Some(dt) = dt_s {
                return Err(p.error("dt_s", dt, "s", format!("only for domain = \"z\" ({continuous} has no period)")));
            }
            match method.as_deref().unwrap_or("tustin") {
                "tustin" => {
                    if let Some(f) = prewarp_hz.filter(|f| *f >= nyquist) {
                        return Err(p.error(
                            "prewarp_hz",
                            f,
                            "Hz",
                            format!("must be below the Nyquist frequency of the controller's rate, {nyquist} Hz"),
                        ));
                    }
                    let prewarp_rad_s = prewarp_hz.map(|f| std::f64::consts::TAU * f);
                    Ok(Domain::Continuous(Method::Tustin { prewarp_rad_s }))
                }
                "zoh" => {
                    if let Some(f) = prewarp_hz {
                        return Err(p.error("prewarp_hz", f, "Hz", "only with discretisation = \"tustin\""));
                    }
                    Ok(Domain::Continuous(Method::Zoh))
                }
                other => Err(p.error("discretisation", format!("{other:?}"), "", "expected \"tustin\" or \"zoh\"")),
            }
        }
        "z" => {
            if let Some(m) = method {
                return Err(p.error("discretisation", format!("{m:?}"), "", "only for domain = \"s\""));
            }
            if let Some(f) = prewarp_hz {
                return Err(p.error("prewarp_hz", f, "Hz", "only for domain = \"s\" with discretisation = \"tustin\""));
            }
            let Some(dt) = dt_s else {
                return Err(p.error(
                    "dt_s",
                    "(not set)",
                    "s",
                    format!("{discrete} needs its sampling period: the controller's, {period_s} s"),
                ));
            };
            if (dt - period_s).abs() > 1e-9 * period_s {
                return Err(p.error(
                    "dt_s",
                    dt,
                    "s",
                    format!("must be the scene's controller period, {period_s} s (1 / controller.rate_hz)"),
                ));
            }
            Ok(Domain::Discrete)
        }
        other => Err(p.error("domain", format!("{other:?}"), "", "expected \"s\" or \"z\"")),
    }
}
