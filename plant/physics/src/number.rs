//! A number as a message shows it.

/// A number as a message shows it: as Rust prints it where that is short, in exponent form
/// where it is not (1e300 would print as 301 digits, 1e-300 as 302).
pub fn shown(v: f64) -> String {
    let plain = v.to_string();
    if plain.len() <= 16 {
        plain
    } else {
        format!("{v:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::shown;

    #[test]
    fn long_numbers_read_in_exponent_form_and_short_ones_as_rust_prints_them() {
        assert_eq!(shown(1e-300), "1e-300");
        assert_eq!(shown(1e300), "1e300");
        assert_eq!(shown(2.4823161653662018e-30), "2.4823161653662018e-30");
        assert_eq!(shown(1.5), "1.5");
        assert_eq!(shown(0.002), "0.002");
    }

    /// The divergence message's step size (issue 40: it printed 46 digits).
    #[test]
    fn the_step_size_underflow_names_its_step_in_exponent_form() {
        let e =
            crate::integrate::IntegrationError::StepSizeUnderflow { t: 0.0, h: 2.4823161653662018e-30, state: vec![] };
        assert_eq!(e.to_string(), "step size underflow at t = 0 s (h = 2.4823161653662018e-30 s): []");
    }
}
