//! Bad input that is not a scene key: an argument of a command that cannot be used (exit 2,
//! [`crate::exit`]). A leaf: any module may refuse with it without importing the exit map,
//! which imports the commands' own error types.

/// An argument of a command that cannot be used (bad input: exit 2).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct BadArgument(pub String);

// The value parsers of the commands' flags, one per class of value (issue 40 item 8). clap's own
// parsers name the flag and the value but not what the value means: "invalid digit found in
// string" for `--runs -1`, "cannot parse float from empty string" for `--seconds ""`. These say
// what the flag counts or measures, its unit and its range, in the user's own text (a refused
// 1e300 is echoed as typed, not as 301 digits). clap prefixes "invalid value 'V' for '--flag'"
// and exits 2.

/// A whole number from `lo` to `hi`, where `what` says what it counts ("a number of realtime
/// runs"): a flag's value parser.
pub fn count<T>(
    what: &'static str,
    lo: u64,
    hi: u64,
) -> impl Fn(&str) -> Result<T, String> + Clone + Send + Sync + 'static
where
    T: TryFrom<u64> + Clone + Send + Sync + 'static,
{
    move |s: &str| {
        let refuse = || format!("`{s}` is not {what}: a whole number from {lo} to {hi}");
        // Parsed wide, so that `-0` and `+3` mean what clap's own parser took them for.
        let n: i128 = s.trim().parse().map_err(|_| refuse())?;
        if !(i128::from(lo)..=i128::from(hi)).contains(&n) {
            return Err(refuse());
        }
        T::try_from(n as u64).map_err(|_| refuse())
    }
}

/// A finite number in `unit` from `lo` to `hi` (either may be infinite: no bound that side),
/// where `what` says what it measures ("a spin speed"): a flag's value parser.
pub fn number(
    what: &'static str,
    unit: &'static str,
    lo: f64,
    hi: f64,
) -> impl Fn(&str) -> Result<f64, String> + Clone + Send + Sync + 'static {
    move |s: &str| {
        let range = match (lo.is_finite(), hi.is_finite()) {
            (true, true) => format!("a finite number from {} to {} {unit}", shown(lo), shown(hi)),
            (true, false) => format!("a finite number of at least {} {unit}", shown(lo)),
            (false, true) => format!("a finite number of at most {} {unit}", shown(hi)),
            (false, false) => format!("a finite number in {unit}"),
        };
        let refuse = || format!("`{s}` is not {what}: {range}");
        let v: f64 = s.trim().parse().map_err(|_| refuse())?;
        if !(v.is_finite() && v >= lo && v <= hi) {
            return Err(refuse());
        }
        Ok(v)
    }
}

/// A number as a message shows it: as Rust prints it where that is short, in exponent form
/// where it is not (1e300 would print as 301 digits, 1e-300 as 302); the physics' own, which its
/// messages use too.
pub use plant_physics::number::shown;

#[cfg(test)]
mod tests {
    use super::*;

    /// Every hostile text is refused with its meaning, range and unit, in the user's own text;
    /// the bounds themselves are taken.
    #[test]
    fn the_value_parsers_name_meaning_range_and_unit() {
        let runs = count::<usize>("a number of realtime runs", 1, 1000);
        for bad in ["-1", "0", "-0", "1001", "nan", "inf", "1e300", "1e-300", "", "abc", "2.5"] {
            let e = runs(bad).expect_err(bad);
            assert_eq!(e, format!("`{bad}` is not a number of realtime runs: a whole number from 1 to 1000"));
        }
        assert_eq!((runs("1"), runs("1000"), runs(" 7 "), runs("+7")), (Ok(1), Ok(1000), Ok(7), Ok(7)));
        assert_eq!(count::<u32>("a number of perturbed runs", 0, 256)("-0"), Ok(0), "clap's u32 took -0 as 0");
        let fmi = count::<u8>("an FMI version", 2, 3);
        assert_eq!(fmi("3"), Ok(3));
        assert!(fmi("259").is_err(), "past the type: refused, not wrapped");
        let speed = number("a spin speed", "Hz", 0.0, 1e5);
        for bad in ["-1", "nan", "inf", "-inf", "1e300", "100000.5", "", "abc"] {
            assert_eq!(
                speed(bad).expect_err(bad),
                format!("`{bad}` is not a spin speed: a finite number from 0 to 100000 Hz")
            );
        }
        assert_eq!((speed("0"), speed("-0"), speed("1e-300"), speed("1e5")), (Ok(0.0), Ok(-0.0), Ok(1e-300), Ok(1e5)));
        let any = number("a time", "s", f64::NEG_INFINITY, f64::INFINITY);
        assert_eq!(any("nan").expect_err("nan"), "`nan` is not a time: a finite number in s");
        assert_eq!(any("-1"), Ok(-1.0));
        assert_eq!(
            number("a rate", "Hz", 1.0, f64::INFINITY)("0").expect_err("0"),
            "`0` is not a rate: a finite number of at least 1 Hz"
        );
        assert_eq!(
            (shown(1e300), shown(1e-300), shown(0.5), shown(-1.0), shown(1e5)),
            ("1e300".into(), "1e-300".into(), "0.5".into(), "-1".into(), "100000".into())
        );
    }
}
