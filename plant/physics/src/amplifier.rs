//! The power amplifier and coil of one AMB axis (MODEL.md §12): the coil's electrical state, the
//! amplifier's voltage limit and its PI current loop. The controller's command is the loop's
//! current reference; the bearing's force follows the coil's real current.
//!
//! ```text
//! L di/dt = v − R i − k_b ẋ                       (coil, back-EMF k_b ẋ optional)
//! v = clamp(K_p (i_ref − i) + q, −V_dc, V_dc)     (PI current loop, voltage limit)
//! dq/dt = K_I (i_ref − i)                         (integral; held while the voltage is limited
//!                                                  and the error would push it further: anti-windup)
//! ```
//!
//! The design: the PI's zero cancels the coil's pole (`K_I / K_p = R / L`), so the open loop is
//! `K_p / (L s)` and the closed loop, unsaturated and without back-EMF, is first order
//! `i / i_ref = ω_c / (s + ω_c)` with `K_p = L ω_c`, `K_I = R ω_c`, `ω_c = 2π f_c` the stated
//! bandwidth: a step of the reference is followed as `i(t) = i_ref (1 − e^{−ω_c t})`. A step
//! large enough to reach the voltage limit is followed at the coil's slew
//! `di/dt = (±V_dc − R i)/L` until the error is small again. The cancelled coil pole stays, at
//! `−R/L`, in the integral's state (it is not excited by the reference).

/// One axis's amplifier and coil, designed for a stated current-loop bandwidth.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Amplifier {
    /// Bus voltage V_dc (V): the amplifier's output is limited to ±V_dc.
    pub bus_voltage: f64,
    /// Coil inductance L (H).
    pub inductance: f64,
    /// Coil resistance R (Ω).
    pub resistance: f64,
    /// Closed current-loop bandwidth ω_c (rad/s).
    pub bandwidth: f64,
    /// Back-EMF constant k_b (V·s/m); 0: none.
    pub back_emf: f64,
    /// Proportional gain K_p = L ω_c (V/A).
    pub kp: f64,
    /// Integral gain K_I = R ω_c (V/(A·s)).
    pub ki: f64,
}

/// What the amplifier does at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AmplifierRates {
    /// di/dt (A/s).
    pub current_rate: f64,
    /// dq/dt (V/s).
    pub integral_rate: f64,
    /// The coil voltage v (V).
    pub voltage: f64,
    /// Whether v is at the limit.
    pub saturated: bool,
}

impl Amplifier {
    /// The amplifier of bus voltage `bus_voltage` (V) on a coil of `inductance` (H) and
    /// `resistance` (Ω), its PI designed for the bandwidth `bandwidth_hz` (Hz), with back-EMF
    /// constant `back_emf` (V·s/m).
    pub fn design(bus_voltage: f64, inductance: f64, resistance: f64, bandwidth_hz: f64, back_emf: f64) -> Self {
        let w = std::f64::consts::TAU * bandwidth_hz;
        Self { bus_voltage, inductance, resistance, bandwidth: w, back_emf, kp: inductance * w, ki: resistance * w }
    }

    /// The integral state that holds the current `current` (A) at rest (zero error): `q = R i`.
    pub fn steady_integral(&self, current: f64) -> f64 {
        self.resistance * current
    }

    /// The rates for reference `reference` (A), coil current `current` (A), integral `integral`
    /// (V), and the rotor's velocity `velocity` (m/s) at the bearing along the axis.
    #[inline]
    pub fn rates(&self, reference: f64, current: f64, integral: f64, velocity: f64) -> AmplifierRates {
        let error = reference - current;
        let wanted = self.kp * error + integral;
        let voltage = wanted.clamp(-self.bus_voltage, self.bus_voltage);
        let saturated = wanted != voltage;
        // Anti-windup: no integration while limited and the error pushes further into the limit.
        let integral_rate = if saturated && error * wanted > 0.0 { 0.0 } else { self.ki * error };
        AmplifierRates {
            current_rate: (voltage - self.resistance * current - self.back_emf * velocity) / self.inductance,
            integral_rate,
            voltage,
            saturated,
        }
    }

    /// The full-power bandwidth `V_dc / (2π L i_max)` (Hz) for the current limit `i_max` (A):
    /// the highest frequency of a sine of amplitude `i_max` the voltage limit lets through.
    pub fn full_power_bandwidth_hz(&self, current_limit: f64) -> f64 {
        self.bus_voltage / (std::f64::consts::TAU * self.inductance * current_limit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// RK4 on the amplifier alone (rotor at rest), reference `reference` from `(i0, q0)`.
    fn simulate(a: &Amplifier, reference: f64, i0: f64, t_end: f64, h: f64, mut each: impl FnMut(f64, f64, bool)) {
        let f = |y: [f64; 2]| {
            let r = a.rates(reference, y[0], y[1], 0.0);
            [r.current_rate, r.integral_rate]
        };
        let mut y = [i0, a.steady_integral(i0)];
        let mut t = 0.0;
        while t < t_end - 1e-15 {
            let k1 = f(y);
            let k2 = f([y[0] + h / 2.0 * k1[0], y[1] + h / 2.0 * k1[1]]);
            let k3 = f([y[0] + h / 2.0 * k2[0], y[1] + h / 2.0 * k2[1]]);
            let k4 = f([y[0] + h * k3[0], y[1] + h * k3[1]]);
            for j in 0..2 {
                y[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
            }
            t += h;
            each(t, y[0], a.rates(reference, y[0], y[1], 0.0).saturated);
        }
    }

    #[test]
    fn a_small_step_is_first_order_at_the_design_bandwidth() {
        // 10 mH, 0.5 Ω, 2 kHz loop, 300 V bus: a 0.1 A step asks K_p 0.1 = 12.6 V, far from the limit.
        let a = Amplifier::design(300.0, 10e-3, 0.5, 2000.0, 0.0);
        let w = a.bandwidth;
        let mut worst: f64 = 0.0;
        simulate(&a, 0.6, 0.5, 2e-3, 1e-7, |t, i, sat| {
            assert!(!sat);
            let exact = 0.5 + 0.1 * (1.0 - (-w * t).exp());
            worst = worst.max((i - exact).abs());
        });
        assert!(worst < 1e-9, "largest deviation from 1 − e^(−ω_c t): {worst:e} A");
    }

    #[test]
    fn a_large_step_slews_at_the_bus_voltage_over_the_inductance() {
        // A 2 A step from 0 asks K_p 2 = 251 V from a 60 V bus: limited, the coil follows
        // L di/dt = V_dc − R i, i(t) = V/R − (V/R − i_0) e^{−R t / L}, until the error is small.
        let a = Amplifier::design(60.0, 10e-3, 0.5, 2000.0, 0.0);
        let (v, r, l) = (a.bus_voltage, a.resistance, a.inductance);
        let mut left_at = None;
        let mut worst: f64 = 0.0;
        simulate(&a, 2.0, 0.0, 1e-3, 1e-7, |t, i, sat| {
            if sat && left_at.is_none() {
                let exact = v / r - (v / r) * (-r * t / l).exp();
                worst = worst.max((i - exact).abs());
            } else if left_at.is_none() {
                left_at = Some(t);
            }
        });
        assert!(worst < 1e-9, "largest deviation from the saturated closed form: {worst:e} A");
        // The integral is held while limited (q = R i_0 = 0), so it leaves the limit when
        // K_p e falls to V_dc: at i = 2 − V_dc / K_p.
        let t = left_at.expect("the step leaves the limit");
        let i_then = v / r - (v / r) * (-r * t / l).exp();
        let expect = 2.0 - v / a.kp;
        assert!((i_then - expect).abs() < 2e-3, "left the limit at i = {i_then} A, expected near {expect} A");
        // The initial slew is V_dc / L = 6000 A/s: 0.1 ms for the first 0.6 A, near enough.
        assert!((v / l - 6000.0).abs() < 1e-9);
    }

    #[test]
    fn the_design_places_the_zero_on_the_coil_pole() {
        let a = Amplifier::design(150.0, 8e-3, 0.4, 1500.0, 0.0);
        assert!((a.ki / a.kp - a.resistance / a.inductance).abs() < 1e-9);
        assert!((a.kp / a.inductance - std::f64::consts::TAU * 1500.0).abs() < 1e-6);
        assert!((a.full_power_bandwidth_hz(2.0) - 150.0 / (std::f64::consts::TAU * 8e-3 * 2.0)).abs() < 1e-9);
    }
}
