//! Independent numerical quadrature, used by the tests to check the
//! closed-form integrals (test-only).

/// Composite Simpson rule of `f` on `[a, b]` with `n` intervals (`n` is
/// rounded up to even).
pub(crate) fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let n = (n.max(2) + 1) & !1;
    if b <= a {
        return 0.0;
    }
    let h = (b - a) / n as f64;
    let mut sum = f(a) + f(b);
    for i in 1..n {
        let w = if i % 2 == 1 { 4.0 } else { 2.0 };
        sum += w * f(a + h * i as f64);
    }
    sum * h / 3.0
}

/// Simpson of `f` on `[0, t]`, split at the `breaks` (where `f` or its
/// derivatives jump) so each piece is smooth; `n` intervals per piece.
pub(crate) fn simpson_piecewise(f: &impl Fn(f64) -> f64, breaks: &[f64], t: f64, n: usize) -> f64 {
    let mut lo = 0.0;
    let mut total = 0.0;
    for &b in breaks.iter().chain(std::iter::once(&f64::INFINITY)) {
        let hi = b.min(t);
        if hi > lo {
            total += simpson(f, lo, hi, n);
            lo = hi;
        }
        if lo >= t {
            break;
        }
    }
    total
}

/// `d(t) = ∫₀ᵗ v`, `v(s) = ∫₀ˢ a`, both by piecewise composite Simpson
/// ("Simpson twice"), `n` intervals per smooth piece.
pub(crate) fn displacement_by_nested_simpson(a: impl Fn(f64) -> f64, breaks: &[f64], t: f64, n: usize) -> f64 {
    let v = |s: f64| simpson_piecewise(&a, breaks, s, n);
    simpson_piecewise(&v, breaks, t, n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn simpson_exact_for_cubics() {
        let i = simpson(|x| x * x * x - 2.0 * x, 0.0, 2.0, 2);
        assert!((i - 0.0).abs() < 1e-14);
    }

    #[test]
    fn nested_gives_t_cubed_over_six_for_unit_jerk() {
        let d = displacement_by_nested_simpson(|s| s, &[0.5], 1.0, 10);
        assert!((d - 1.0 / 6.0).abs() < 1e-14);
    }
}
