//! The driver shared by the embedded Runge–Kutta pairs (Dp5, Dop853): error norm, Hairer's
//! initial-step heuristic, PI step-size control, last-step landing on `t1`, dense-output
//! hand-off and the failure checks. The formulas are in the parent module's documentation.

use super::{all_finite, ErrorNorm, IntegrationError, Integrator, Rhs, Samples, Settings, System, Workspace, STAGES};

/// Step-size controller constants: `h₊ = h / clamp(err^α·err_old^(−β)/safety, 1/fac_max,
/// 1/fac_min)`.
pub(crate) struct Control {
    pub(crate) alpha: f64,
    pub(crate) beta: f64,
    pub(crate) safety: f64,
    pub(crate) fac_min: f64,
    pub(crate) fac_max: f64,
}

/// What the continuous extension of one accepted step reads.
pub(crate) struct StepView<'a, const N: usize> {
    /// Step size.
    pub(crate) h: f64,
    /// State at the start of the step.
    pub(crate) y: &'a [f64; N],
    /// State at the end of the step.
    pub(crate) y_new: &'a [f64; N],
    /// Stages (slot 0: `f` at the start; the method's FSAL slot: `f` at the end).
    pub(crate) k: &'a [[f64; N]; STAGES],
    /// Coefficients from [`EmbeddedPair::prepare_dense`].
    pub(crate) dense: &'a [[f64; N]; 4],
}

/// An explicit embedded Runge–Kutta pair with a continuous extension.
pub(crate) trait EmbeddedPair {
    /// Order used by the initial-step heuristic.
    const ORDER: i32;
    /// Step-size control constants.
    const CONTROL: Control;
    /// Stage slot that holds `f(t + h, y₊)` after [`EmbeddedPair::finish`].
    const FSAL: usize;

    /// Tries a step of size `h` from `(t, y)` with `ws.k[0] = f(t, y)`; writes the candidate to
    /// `ws.y_new` and returns the scaled error norm (≤ 1 to accept; may be NaN or ∞).
    fn attempt<const N: usize, S: System<N>>(
        rhs: &mut Rhs<'_, S>,
        settings: &Settings<N>,
        t: f64,
        h: f64,
        y: &[f64; N],
        ws: &mut Workspace<N>,
    ) -> f64;

    /// After acceptance: makes `ws.k[FSAL] = f(t + h, y₊)`.
    fn finish<const N: usize, S: System<N>>(rhs: &mut Rhs<'_, S>, t: f64, h: f64, ws: &mut Workspace<N>);

    /// After `finish`, for a step that holds sample times: fills `ws.dense` (and any extra
    /// stages the extension needs).
    fn prepare_dense<const N: usize, S: System<N>>(
        rhs: &mut Rhs<'_, S>,
        t: f64,
        h: f64,
        y: &[f64; N],
        ws: &mut Workspace<N>,
    );

    /// The continuous extension at `θ = (t* − t)/h`, written to `out`.
    fn interpolate<const N: usize>(theta: f64, step: &StepView<'_, N>, out: &mut [f64; N]);
}

/// Scaled norms of several error vectors `h·eₘ` sharing the scale
/// `sᵢ = atolᵢ + rtol·max(|yᵢ|, |y₊ᵢ|)`. Non-finite input gives a non-finite norm.
#[inline]
pub(crate) fn scaled_norms<const N: usize, const M: usize>(
    settings: &Settings<N>,
    h: f64,
    y: &[f64; N],
    y_new: &[f64; N],
    errs: [&[f64; N]; M],
) -> [f64; M] {
    let habs = h.abs();
    let mut acc = [0.0; M];
    match settings.norm {
        ErrorNorm::Rms => {
            for i in 0..N {
                let r = habs / (settings.atol[i] + settings.rtol * y[i].abs().max(y_new[i].abs()));
                for m in 0..M {
                    let q = errs[m][i] * r;
                    acc[m] += q * q;
                }
            }
            let n = settings.rms_count.clamp(1, N.max(1)) as f64;
            acc.map(|a| (a / n).sqrt())
        }
        ErrorNorm::Max => {
            // f64::max drops NaN, so a sum rides along to catch non-finite terms.
            let mut guard = 0.0;
            for i in 0..N {
                let r = habs / (settings.atol[i] + settings.rtol * y[i].abs().max(y_new[i].abs()));
                for m in 0..M {
                    let q = (errs[m][i] * r).abs();
                    acc[m] = acc[m].max(q);
                    guard += q;
                }
            }
            if guard.is_finite() {
                acc
            } else {
                [f64::NAN; M]
            }
        }
    }
}

/// Hairer's initial step (HINIT in DOPRI5/DOP853): an explicit Euler probe gives estimates of
/// `‖y‖/‖f‖` and of the second derivative, `h ≈ (0.01/max(‖f′‖, ‖f‖))^(1/order)`, bounded by
/// `100·h₀` and `h_max`. Uses `ws.k[0] = f(t, y)` and one evaluation into `ws.k[1]`.
fn initial_step<const N: usize, S: System<N>>(
    rhs: &mut Rhs<'_, S>,
    settings: &Settings<N>,
    order: i32,
    (t, h_max): (f64, f64),
    y: &[f64; N],
    ws: &mut Workspace<N>,
) -> f64 {
    let scale = |i: usize| settings.atol[i] + settings.rtol * y[i].abs();
    let f0 = &ws.k[0];
    let (mut dnf, mut dny) = (0.0, 0.0);
    for (i, (f, yi)) in f0.iter().zip(y).enumerate() {
        let s = scale(i);
        dnf += (f / s).powi(2);
        dny += (yi / s).powi(2);
    }
    let h0 = if dnf <= 1e-10 || dny <= 1e-10 { 1e-6 } else { 0.01 * (dny / dnf).sqrt() }.min(h_max);
    for ((probe, yi), f) in ws.y_stage.iter_mut().zip(y).zip(f0) {
        *probe = yi + h0 * f;
    }
    rhs.eval(t + h0, &ws.y_stage, &mut ws.k[1]);
    let der2: f64 = (0..N).map(|i| ((ws.k[1][i] - ws.k[0][i]) / scale(i)).powi(2)).sum();
    let der2 = der2.sqrt() / h0;
    // NaN from a bad probe falls back on ‖f‖ (f64::max drops NaN).
    let der12 = der2.max(dnf.sqrt());
    let h1 = if der12 <= 1e-15 { (h0 * 1e-3).max(1e-6) } else { (0.01 / der12).powf(1.0 / f64::from(order)) };
    (100.0 * h0).min(h1).min(h_max)
}

/// One macro step of an embedded pair; see [`Integrator::advance_dense`].
pub(crate) fn run<M: EmbeddedPair, const N: usize, S: System<N>, F: FnMut(f64, &[f64; N])>(
    rhs: &mut Rhs<'_, S>,
    integrator: &mut Integrator<N>,
    (t0, t1): (f64, f64),
    y: &mut [f64; N],
    samples: &mut Samples<'_, F>,
) -> Result<(), IntegrationError> {
    let Integrator { settings, ws, adaptive: carried, stats } = integrator;
    let c = M::CONTROL;
    let h_max = settings.h_max.min(t1 - t0);

    rhs.eval(t0, y, &mut ws.k[0]);
    if !all_finite(&ws.k[0]) {
        return Err(IntegrationError::NonFinite { t: t0, state: y.to_vec() });
    }
    let mut h = if carried.h > 0.0 {
        carried.h
    } else if settings.h_init > 0.0 {
        settings.h_init
    } else {
        initial_step(rhs, settings, M::ORDER, (t0, h_max), y, ws)
    }
    .min(h_max);

    let mut t = t0;
    let mut attempts = 0_u64;
    let mut rejected_last = false;
    let mut non_finite_last = false;
    while t < t1 {
        // Land on t1 exactly; stretch by up to 1 % rather than leave a sliver.
        let last = t + 1.01 * h >= t1;
        let h_floor = settings.h_min.max(10.0 * f64::EPSILON * t.abs());
        if h < h_floor && !last {
            return Err(if non_finite_last {
                IntegrationError::NonFinite { t, state: y.to_vec() }
            } else {
                IntegrationError::StepSizeUnderflow { t, h, state: y.to_vec() }
            });
        }
        if attempts >= settings.max_steps {
            return Err(IntegrationError::TooManySteps { t, max_steps: settings.max_steps, state: y.to_vec() });
        }
        attempts += 1;

        let h_step = if last { t1 - t } else { h };
        let err = M::attempt(rhs, settings, t, h_step, y, ws);

        if !err.is_finite() {
            stats.rejected += 1;
            h = 0.5 * h_step;
            rejected_last = true;
            non_finite_last = true;
            continue;
        }
        non_finite_last = false;
        let err_pow = err.powf(c.alpha);
        if err > 1.0 {
            stats.rejected += 1;
            h = h_step / (1.0 / c.fac_min).min(err_pow / c.safety);
            rejected_last = true;
            continue;
        }

        // Accepted.
        let t_new = if last { t1 } else { t + h_step };
        if !all_finite(&ws.y_new) {
            return Err(IntegrationError::NonFinite { t: t_new, state: ws.y_new.to_vec() });
        }
        M::finish(rhs, t, h_step, ws);
        stats.steps += 1;
        if samples.due(t_new) {
            M::prepare_dense(rhs, t, h_step, y, ws);
            let Workspace { k, y_new, dense, y_out, .. } = ws;
            let step = StepView { h: h_step, y, y_new, k, dense };
            samples.emit(t_new, y_new, y_out, |ts, out| M::interpolate((ts - t) / h_step, &step, out));
        }
        *y = ws.y_new;
        ws.k[0] = ws.k[M::FSAL];
        t = t_new;
        if !all_finite(&ws.k[0]) {
            return Err(IntegrationError::NonFinite { t, state: y.to_vec() });
        }

        let fac = (err_pow / carried.err_old.powf(c.beta) / c.safety).clamp(1.0 / c.fac_max, 1.0 / c.fac_min);
        carried.err_old = err.max(1e-4);
        let mut h_new = h_step / fac;
        if rejected_last {
            h_new = h_new.min(h_step);
        }
        rejected_last = false;
        // A step shortened to land on t1 says nothing against the step it replaced.
        h = if last { h_new.max(h) } else { h_new }.min(h_max);
    }
    carried.h = h;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::Method;

    /// Slots a model leaves at zero add nothing to the RMS norm's sum; with `rms_count` the
    /// components it uses, the padded state's norm is the unpadded state's, bit for bit, and
    /// without it the padding dilutes the norm by `sqrt(used / N)`.
    #[test]
    fn the_rms_norm_counts_the_components_the_model_uses() {
        let y = [1e-4, -2e-5, 3.0];
        let y_new = [1.1e-4, -2.2e-5, 3.1];
        let err = [3e-9, 1e-10, 2e-7];
        let compact = Settings::<3>::new(Method::Dp5);
        let [want] = scaled_norms(&compact, 1e-5, &y, &y_new, [&err]);
        let pad = |v: [f64; 3]| {
            let mut p = [0.0; 8];
            p[..3].copy_from_slice(&v);
            p
        };
        let padded = Settings::<8> { rms_count: 3, ..Settings::new(Method::Dp5) };
        let [got] = scaled_norms(&padded, 1e-5, &pad(y), &pad(y_new), [&pad(err)]);
        assert_eq!(got, want);
        let diluted = Settings::<8>::new(Method::Dp5);
        let [loose] = scaled_norms(&diluted, 1e-5, &pad(y), &pad(y_new), [&pad(err)]);
        assert!((loose / want - (3.0f64 / 8.0).sqrt()).abs() < 1e-12, "{loose} against {want}");
        assert!(Settings::<8> { rms_count: 0, ..Settings::new(Method::Dp5) }.validate().is_err());
        assert!(Settings::<8> { rms_count: 9, ..Settings::new(Method::Dp5) }.validate().is_err());
    }
}
