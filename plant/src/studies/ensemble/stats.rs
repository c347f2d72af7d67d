//! Statistics of an ensemble: the recovery probability with its Wilson score interval, order
//! statistics of the recovery times, and the thresholds of a sweep (where the probability of
//! recovery crosses 0.5).
//!
//! Wilson's 95 % interval for `k` successes in `n` trials, with `z = 1.959964`:
//!
//! ```text
//! centre = (p + z²/2n) / (1 + z²/n),   half = z √(p(1−p)/n + z²/4n²) / (1 + z²/n),   p = k/n
//! ```
//!
//! It stays inside [0, 1] and is not degenerate at k = 0 or k = n (16 members that all
//! recover give [0.806, 1]).

use serde::Serialize;

/// The normal quantile of a two-sided 95 % interval.
pub const Z95: f64 = 1.959_963_984_540_054;

/// Wilson score interval `[lo, hi]` for `k` of `n` (`[0, 1]` for `n = 0`).
///
/// ```
/// let [lo, hi] = plant::ensemble::stats::wilson(16, 16);
/// assert!((lo - 0.8063).abs() < 1e-4 && hi == 1.0);
/// ```
pub fn wilson(k: usize, n: usize) -> [f64; 2] {
    if n == 0 {
        return [0.0, 1.0];
    }
    let (nf, p) = (n as f64, k as f64 / n as f64);
    let z2 = Z95 * Z95;
    let denom = 1.0 + z2 / nf;
    let centre = (p + z2 / (2.0 * nf)) / denom;
    let half = Z95 * (p * (1.0 - p) / nf + z2 / (4.0 * nf * nf)).sqrt() / denom;
    // Exactly 0 and 1 at the ends (the formula gives them up to rounding).
    let lo = if k == 0 { 0.0 } else { (centre - half).max(0.0) };
    let hi = if k == n { 1.0 } else { (centre + half).min(1.0) };
    [lo, hi]
}

/// The `q` quantile (0 … 1) of `values` by linear interpolation between order statistics
/// (Hyndman & Fan type 7, as numpy's default); `None` for no values.
pub fn quantile(values: &[f64], q: f64) -> Option<f64> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let h = q.clamp(0.0, 1.0) * (v.len() - 1) as f64;
    let (i, f) = (h.floor() as usize, h - h.floor());
    Some(if i + 1 < v.len() { v[i] + f * (v[i + 1] - v[i]) } else { v[i] })
}

/// A value where the probability of recovery crosses 0.5.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Threshold {
    /// Where the estimate p̂ crosses 0.5 (linear between neighbouring points).
    pub value: f64,
    /// The interval that holds it: from the nearest point below whose 95 % band lies wholly on
    /// one side of 0.5 to the nearest such point above.
    pub interval: [f64; 2],
    /// `falling` (recovery less likely beyond it) or `rising`.
    pub direction: &'static str,
    /// True when the band still contains 0.5 at an end of the swept range: the interval is
    /// cut there and the threshold may lie outside.
    pub open: bool,
}

/// The crossings of 0.5 by `p` over `x` (ascending), each with the interval between the nearest
/// points on either side whose band `[lo, hi]` excludes 0.5. Interpolation is linear in `x` (pass `log10` values for a log
/// axis and convert back).
pub fn thresholds(x: &[f64], p: &[f64], lo: &[f64], hi: &[f64]) -> Vec<Threshold> {
    let n = x.len().min(p.len()).min(lo.len()).min(hi.len());
    let mut out = Vec::new();
    let cross = |a: f64, b: f64, xa: f64, xb: f64| xa + (0.5 - a) / (b - a) * (xb - xa);
    for i in 0..n.saturating_sub(1) {
        let (a, b) = (p[i] - 0.5, p[i + 1] - 0.5);
        // A crossing in [x_i, x_{i+1}): the sign changes, or p̂ sits at 0.5 at x_i after the other side.
        let here = if a == 0.0 { i > 0 && (p[i - 1] - 0.5) * b < 0.0 } else { a * b < 0.0 };
        if !here {
            continue;
        }
        let value = if a == 0.0 { x[i] } else { cross(p[i], p[i + 1], x[i], x[i + 1]) };
        let direction = if p[i + 1] < p[i] || (a == 0.0 && b < 0.0) { "falling" } else { "rising" };
        // The interval: between the nearest points on either side whose 95 % band excludes
        // 0.5. Between grid points the curve is unknown, so the interval ends on grid points
        // (a step from 0 to 1 between two points gives the whole step).
        let excludes = |j: usize| lo[j] > 0.5 || hi[j] < 0.5;
        let left_point = (0..=i).rev().find(|&j| excludes(j));
        let right_point = (i + 1..n).find(|&j| excludes(j));
        let left = left_point.map_or(x[0], |j| x[j]);
        let right = right_point.map_or(x[n - 1], |j| x[j]);
        let (open, open_right) = (left_point.is_none(), right_point.is_none());
        out.push(Threshold { value, interval: [left, right], direction, open: open || open_right });
    }
    out
}

/// The crossings of 0.5 by a sweep's points in the axis's own units: `values` in any order
/// (sorted here), interpolated linearly in the value, or in `log10` of it on a log axis and
/// converted back.
pub fn thresholds_along(values: &[f64], log: bool, p: &[f64], lo: &[f64], hi: &[f64]) -> Vec<Threshold> {
    let x_of = |v: f64| if log { v.log10() } else { v };
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|a, b| x_of(values[*a]).total_cmp(&x_of(values[*b])));
    let pick = |column: &[f64]| -> Vec<f64> { order.iter().map(|&i| column[i]).collect() };
    let x: Vec<f64> = order.iter().map(|&i| x_of(values[i])).collect();
    let back = |v: f64| if log { 10f64.powf(v) } else { v };
    thresholds(&x, &pick(p), &pick(lo), &pick(hi))
        .into_iter()
        .map(|t| Threshold { value: back(t.value), interval: [back(t.interval[0]), back(t.interval[1])], ..t })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wilson_matches_published_values() {
        // Newcombe (1998), table I: 81/263 → 0.2553 … 0.3662; 0/10 → 0 … 0.2775.
        let [lo, hi] = wilson(81, 263);
        assert!((lo - 0.2553).abs() < 1e-4 && (hi - 0.3662).abs() < 1e-4, "{lo} {hi}");
        let [lo, hi] = wilson(0, 10);
        assert!(lo == 0.0 && (hi - 0.2775).abs() < 1e-4, "{hi}");
        assert_eq!(wilson(0, 0), [0.0, 1.0]);
    }

    #[test]
    fn quantiles_interpolate() {
        assert_eq!(quantile(&[3.0, 1.0, 2.0, 4.0], 0.5), Some(2.5));
        assert_eq!(quantile(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0], 0.9), Some(10.0));
        assert_eq!(quantile(&[], 0.5), None);
    }

    #[test]
    fn a_falling_step_gives_one_threshold_inside_its_band() {
        let x = [1.0, 2.0, 3.0, 4.0, 5.0];
        let p = [1.0, 1.0, 0.75, 0.25, 0.0];
        let lo = [0.8, 0.8, 0.5, 0.1, 0.0];
        let hi = [1.0, 1.0, 0.9, 0.5, 0.2];
        let t = thresholds(&x, &p, &lo, &hi);
        assert_eq!(t.len(), 1);
        assert_eq!(t[0].value, 3.5);
        assert_eq!(t[0].direction, "falling");
        // The bands of x = 3 and 4 contain 0.5; those of x = 2 and 5 do not.
        assert_eq!(t[0].interval, [2.0, 5.0]);
        assert!(!t[0].open);
    }

    #[test]
    fn no_crossing_no_threshold() {
        assert!(thresholds(&[1.0, 2.0], &[1.0, 0.9], &[0.8, 0.7], &[1.0, 1.0]).is_empty());
    }
}
