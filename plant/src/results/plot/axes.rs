//! Axis ranges (padding, log decades, equal scales) and tick labels.

use super::MAX_TICKS;
use plotters::coord::combinators::{BindKeyPoints, IntoLogRange, LogCoord, WithKeyPoints};

/// Smallest and largest finite value, if any.
pub(crate) fn finite_bounds(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values.filter(|v| v.is_finite()).fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

/// Largest magnitude of a linear axis bound: keeps `hi - lo` finite, which
/// plotters' tick search needs (it loops forever on an infinite span).
pub(crate) const AXIS_LIMIT: f64 = f64::MAX / 4.0;

/// Widens `[lo, hi]` by 5 % on each side; a (nearly) constant range gets
/// ±10 % of its value, or ±1 about zero. Bounds are clamped to
/// ±[`AXIS_LIMIT`].
pub(crate) fn padded(lo: f64, hi: f64) -> (f64, f64) {
    let (lo, hi) = (lo.clamp(-AXIS_LIMIT, AXIS_LIMIT), hi.clamp(-AXIS_LIMIT, AXIS_LIMIT));
    let span = hi - lo;
    let scale = lo.abs().max(hi.abs());
    let (a, b) = if span <= scale * 1e-12 || span <= f64::MIN_POSITIVE {
        let mid = lo + 0.5 * span;
        let half = if mid != 0.0 { 0.1 * mid.abs() } else { 1.0 };
        (mid - half, mid + half)
    } else {
        (lo - 0.05 * span, hi + 0.05 * span)
    };
    (a.max(-AXIS_LIMIT), b.min(AXIS_LIMIT))
}

/// `[lo, hi]` as it is (heat map axes and colour range), clamped to
/// ±[`AXIS_LIMIT`]; padded as by [`padded`] if that leaves it empty.
pub(crate) fn unpadded(lo: f64, hi: f64) -> (f64, f64) {
    let (lo, hi) = (lo.clamp(-AXIS_LIMIT, AXIS_LIMIT), hi.clamp(-AXIS_LIMIT, AXIS_LIMIT));
    if hi > lo {
        (lo, hi)
    } else {
        padded(lo, hi)
    }
}

/// Most decades a log axis shows; smaller values are not drawn.
pub(crate) const MAX_DECADES: f64 = 30.0;

/// Log axis bounds for positive `[lo, hi]`: 5 % of the span in decades on
/// each side; if that holds fewer than two powers of ten (too few to
/// label), rounded outwards to whole decades. Kept within 1e-300..1e300
/// and to at most [`MAX_DECADES`] below the top.
pub(crate) fn log_padded(lo: f64, hi: f64) -> (f64, f64) {
    let (a, b) = (lo.log10().clamp(-299.0, 299.0), hi.log10().clamp(-299.0, 299.0));
    let m = 0.05 * (b - a);
    let (a, b) = (a - m, b + m);
    let (mut a, mut b) = if b.floor() - a.ceil() >= 1.0 {
        (a, b)
    } else {
        let (mut a, mut b) = (a.floor(), b.ceil());
        if b - a < 1.0 {
            a -= 1.0;
            b += 1.0;
        }
        (a, b)
    };
    b = b.min(300.0);
    a = a.max(-300.0).max(b - MAX_DECADES);
    (10f64.powf(a), 10f64.powf(b))
}

/// Scales `(lo, hi)` about its centre to `span`.
pub(crate) fn centred(lo: f64, hi: f64, span: f64) -> (f64, f64) {
    let mid = lo + 0.5 * (hi - lo);
    (mid - 0.5 * span, mid + 0.5 * span)
}

/// Widens the two ranges so that one data unit is the same number of pixels
/// on both axes of a `w`×`h` plotting area.
pub(crate) fn equalise(x: (f64, f64), y: (f64, f64), w: usize, h: usize) -> ((f64, f64), (f64, f64)) {
    let per_px = ((x.1 - x.0) / w as f64).max((y.1 - y.0) / h as f64);
    (centred(x.0, x.1, per_px * w as f64), centred(y.0, y.1, per_px * h as f64))
}

/// The tick step plotters picks on a linear axis: the smallest 1, 2 or 5
/// × 10^k that gives no more than `max_ticks` ticks.
pub(crate) fn tick_step(lo: f64, hi: f64, max_ticks: usize) -> f64 {
    let span = (hi - lo).abs();
    if !(span.is_finite() && span > 0.0) {
        return 1.0;
    }
    let mut decade = 10f64.powf(span.log10().floor() - 1.0);
    loop {
        for m in [1.0, 2.0, 5.0] {
            let step = m * decade;
            if ((span / step).floor() as usize) < max_ticks {
                return step;
            }
        }
        decade *= 10.0;
    }
}

/// Tick label formatter for a linear axis over `[lo, hi]`: fixed-point with
/// just enough decimals for the tick step, or scientific notation for very
/// large or very small magnitudes.
pub(crate) fn linear_ticks(lo: f64, hi: f64) -> impl Fn(&f64) -> String {
    let step = tick_step(lo, hi, MAX_TICKS);
    let step_exp = step.log10().floor() as i32;
    let magnitude = lo.abs().max(hi.abs());
    let scientific = !(1e-3..1e5).contains(&magnitude);
    move |v: &f64| {
        // Snap values within rounding noise of zero to zero.
        if v.abs() < step * 1e-6 {
            return if scientific { "0".to_string() } else { format!("{:.*}", (-step_exp).max(0) as usize, 0.0) };
        }
        if scientific {
            let exp = v.abs().log10().floor() as i32;
            let digits = (exp - step_exp).max(0) as usize;
            format!("{:.*e}", digits, v)
        } else {
            let digits = (-step_exp).max(0) as usize;
            format!("{:.*}", digits, v)
        }
    }
}

/// A log axis over `[lo, hi]` with its own key points ([`log_key_points`]).
pub(crate) fn log_axis(lo: f64, hi: f64) -> WithKeyPoints<LogCoord<f64>> {
    let (bold, light) = log_key_points(lo, hi);
    LogCoord::from((lo..hi).log_scale()).with_key_points(bold).with_light_points(light)
}

/// The labelled and the grid values of a log axis over `[lo, hi]`. Written here rather than
/// taken from plotters, whose log key points start at the lowest power of ten in the range
/// (data below it sit beside an unlabelled stretch) and label no value between powers once the
/// range spans more than a decade: up to 1.2 decades every 1…9 × 10ᵏ is labelled, up to 3
/// decades 1, 2, 5 × 10ᵏ, up to 12 the powers of ten, beyond that every n-th power (at most 12
/// labels); the grid has every 1…9 × 10ᵏ up to 12 decades, the labelled values beyond.
pub(crate) fn log_key_points(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    let decades = (hi / lo).log10();
    let (k0, k1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let inside = |v: f64| v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9);
    let all: [f64; 9] = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0];
    let values = |mantissas: &[f64], every: i32| -> Vec<f64> {
        (k0..=k1)
            .filter(|k| k.rem_euclid(every) == 0)
            .flat_map(|k| mantissas.iter().map(move |m| m * 10f64.powi(k)))
            .filter(|v| inside(*v))
            .collect()
    };
    let bold = if decades <= 1.2 {
        values(&all, 1)
    } else if decades <= 3.0 {
        values(&[1.0, 2.0, 5.0], 1)
    } else if decades <= 12.0 {
        values(&[1.0], 1)
    } else {
        values(&[1.0], (decades / 12.0).ceil() as i32)
    };
    let light = if decades <= 12.0 { values(&all, 1) } else { bold.clone() };
    (bold, light)
}

/// Tick label formatter for a log axis: plain numbers between 10⁻³ and
/// 10⁵, scientific notation otherwise.
pub(crate) fn log_ticks(v: &f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".to_string()
    } else if (1e-3..1e5).contains(&a) {
        let digits = (-(a.log10().floor() as i32)).max(0) as usize;
        format!("{:.*}", digits, v)
    } else {
        format!("{:.0e}", v)
    }
}

/// Fraction `[0, 1]` of the axis at which a value lies.
#[derive(Clone, Copy)]
pub(crate) struct AxisMap {
    pub(crate) lo: f64,
    pub(crate) hi: f64,
    pub(crate) log: bool,
}

impl AxisMap {
    pub(crate) fn frac(&self, v: f64) -> f64 {
        if self.log {
            (v.log10() - self.lo.log10()) / (self.hi.log10() - self.lo.log10())
        } else {
            (v - self.lo) / (self.hi - self.lo)
        }
    }
}

/// A number with at most four significant digits and no trailing zeros.
pub(crate) fn short_number(v: f64) -> String {
    let s = format!("{:.4}", v);
    let digits = if v.abs() >= 1.0 { (3 - v.abs().log10().floor() as i32).max(0) as usize } else { 4 };
    let s = if digits < 4 { format!("{:.*}", digits, v) } else { s };
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}
