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
//!
//! A unipolar amplifier ([`Amplifier::unipolar_rates`], MODEL.md §12.3) drives one magnet's
//! coil with the same PI and coil, its output limited to `0..V_dc` ([`Bridge::OneQuadrant`]) or
//! `−V_dc..V_dc` ([`Bridge::TwoQuadrant`]), its current never below zero.

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

/// The voltages a unipolar amplifier's bridge can put on its magnet's coil (MODEL.md §12.3);
/// the current only ever flows one way.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Bridge {
    /// `0..V_dc`: a buck stage (one switch, one freewheeling diode). The current rises at
    /// `(V_dc − R i)/L` at most and falls at `R i / L` at most (plus the motional voltage): with
    /// `v = 0` it decays as `e^{−t R/L}`.
    OneQuadrant,
    /// `−V_dc..V_dc` while the current flows: the asymmetric half bridge (two switches, two
    /// diodes) of most unipolar AMB amplifiers, which drives the current down at
    /// `(V_dc + R i)/L` by returning the coil's energy to the bus.
    TwoQuadrant,
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

    /// The rates of one magnet's coil behind a unipolar amplifier (MODEL.md §12.3): the same PI
    /// and coil as [`Amplifier::rates`], with the output limited to `floor..V_dc` by the bridge
    /// (`floor` 0 or `−V_dc`) and a current that cannot reverse.
    ///
    /// `reference` (A) is clamped at 0 (a unipolar amplifier is never asked for a negative
    /// current); `emf` (V) is the coil's motional voltage, `L di/dt = v − R i − emf` (positive
    /// when the rotor closes this magnet's gap; [`Amplifier::back_emf`] is the axis's, the
    /// caller gives each magnet its share). A coil with no current that the voltage would drive
    /// negative stays at zero: the bridge's diodes stop conducting, `di/dt = 0`, and the coil's
    /// terminal voltage is then its motional voltage (`v − R·0 − emf = 0`); a current the
    /// integrator left a little below zero is read as zero. The output counts as limited when the PI asks for more than `V_dc`, or for less
    /// than `floor` while the coil conducts (a coil off at a zero reference is not limited).
    #[inline]
    pub fn unipolar_rates(
        &self,
        bridge: Bridge,
        reference: f64,
        current: f64,
        integral: f64,
        emf: f64,
    ) -> AmplifierRates {
        let floor = match bridge {
            Bridge::OneQuadrant => 0.0,
            Bridge::TwoQuadrant => -self.bus_voltage,
        };
        let on = current.max(0.0);
        let error = reference.max(0.0) - on;
        let wanted = self.kp * error + integral;
        let mut voltage = wanted.clamp(floor, self.bus_voltage);
        let mut current_rate = (voltage - self.resistance * on - emf) / self.inductance;
        let off = current <= 0.0 && current_rate <= 0.0;
        if off {
            current_rate = 0.0;
            voltage = emf;
        }
        let saturated = wanted > self.bus_voltage || (wanted < floor && !off);
        let integral_rate = if saturated && error * wanted > 0.0 { 0.0 } else { self.ki * error };
        AmplifierRates { current_rate, integral_rate, voltage, saturated }
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
    fn simulate(a: &Amplifier, reference: f64, i0: f64, t_end: f64, h: f64, each: impl FnMut(f64, f64, bool)) {
        let rates = |i: f64, q: f64| a.rates(reference, i, q, 0.0);
        integrate(rates, [i0, a.steady_integral(i0)], t_end, h, each);
    }

    /// RK4 on `(i, q)` under `rates`, from `y`, calling `each(t, i, saturated)` after each step.
    fn integrate(
        rates: impl Fn(f64, f64) -> AmplifierRates,
        mut y: [f64; 2],
        t_end: f64,
        h: f64,
        mut each: impl FnMut(f64, f64, bool),
    ) {
        let f = |y: [f64; 2]| {
            let r = rates(y[0], y[1]);
            [r.current_rate, r.integral_rate]
        };
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
            each(t, y[0], rates(y[0], y[1]).saturated);
        }
    }

    /// The realistic scene's magnet coil: 150 V bus, 58 mH, 1 Ω, 1.5 kHz loop, no back-EMF.
    fn magnet() -> Amplifier {
        Amplifier::design(150.0, 58e-3, 1.0, 1500.0, 0.0)
    }

    #[test]
    fn a_magnet_follows_a_small_step_of_its_bias_at_the_design_bandwidth() {
        // From the 2 A bias to 2.1 A: K_p 0.1 + R 2 = 56.7 V, inside 0..150 V: first order.
        // Down to 1.9 A asks 2 − 54.7 = −52.7 V: first order with the two-quadrant bridge only;
        // the one-quadrant stage is first order for a fall of less than R i / K_p = 3.7 mA.
        let a = magnet();
        let w = a.bandwidth;
        let mut worst: f64 = 0.0;
        let steps = [
            (Bridge::OneQuadrant, 2.0, 2.1),
            (Bridge::OneQuadrant, 2.0, 1.997),
            (Bridge::TwoQuadrant, 2.0, 2.1),
            (Bridge::TwoQuadrant, 2.0, 1.9),
        ];
        for (bridge, from, to) in steps {
            let rates = |i: f64, q: f64| a.unipolar_rates(bridge, to, i, q, 0.0);
            integrate(rates, [from, a.steady_integral(from)], 3e-3, 1e-7, |t, i, sat| {
                assert!(!sat, "{bridge:?} {from} → {to} A limited at {t} s");
                let exact = from + (to - from) * (1.0 - (-w * t).exp());
                worst = worst.max((i - exact).abs());
            });
        }
        assert!(worst < 1e-9, "largest deviation from 1 − e^(−ω_c t): {worst:e} A");
    }

    #[test]
    fn a_one_quadrant_magnet_is_limited_by_a_small_fall() {
        // 2 → 1.9 A: the PI asks −52.7 V, the stage gives 0 V: limited at once.
        let a = magnet();
        let r = a.unipolar_rates(Bridge::OneQuadrant, 1.9, 2.0, a.steady_integral(2.0), 0.0);
        assert!(r.saturated && r.voltage == 0.0);
        assert!((r.current_rate + 2.0 * a.resistance / a.inductance).abs() < 1e-12);
    }

    #[test]
    fn a_magnet_rises_at_the_bus_voltage_less_its_resistive_drop() {
        // 0.5 A → 4 A asks K_p 3.5 = 1913 V: the bus's 150 V, L di/dt = V_dc − R i,
        // i(t) = V/R − (V/R − i_0) e^{−R t/L}; the first slew (V_dc − R i_0)/L = 2578 A/s.
        let a = magnet();
        let (v, r, l) = (a.bus_voltage, a.resistance, a.inductance);
        let i0 = 0.5;
        let (mut worst, mut limited): (f64, f64) = (0.0, 0.0);
        let rates = |i: f64, q: f64| a.unipolar_rates(Bridge::OneQuadrant, 4.0, i, q, 0.0);
        let first = rates(i0, a.steady_integral(i0));
        assert!(first.saturated && first.voltage == v);
        assert!((first.current_rate - (v - r * i0) / l).abs() < 1e-9 * first.current_rate);
        integrate(rates, [i0, a.steady_integral(i0)], 2e-3, 1e-7, |t, i, sat| {
            if sat {
                limited = t;
                let exact = v / r - (v / r - i0) * (-r * t / l).exp();
                worst = worst.max((i - exact).abs());
            }
        });
        assert!(worst < 1e-9, "largest deviation from the saturated rise: {worst:e} A");
        // 3.5 A at ≈ 2.6 kA/s takes about 1.3 ms.
        assert!((1.2e-3..1.5e-3).contains(&limited), "at the limit until {limited} s");
    }

    #[test]
    fn a_one_quadrant_magnet_falls_only_as_its_own_time_constant() {
        // 3 A → 0 A: the PI asks a large negative voltage; the buck stage gives 0 V, so
        // L di/dt = −R i, i(t) = i_0 e^{−t R/L} (τ = L/R = 58 ms) until K_p i < R i_0, i.e. to
        // 5.5 mA. The two-quadrant bridge applies −V_dc: i(t) = −V/R + (i_0 + V/R) e^{−R t/L}
        // (it would reach zero after (L/R) ln(1 + R i_0 / V_dc) = 1.15 ms) until the PI
        // takes over near zero.
        let a = magnet();
        let (v, r, l) = (a.bus_voltage, a.resistance, a.inductance);
        let i0 = 3.0;
        let mut worst: f64 = 0.0;
        let mut last = (0.0, i0);
        let rates = |i: f64, q: f64| a.unipolar_rates(Bridge::OneQuadrant, 0.0, i, q, 0.0);
        integrate(rates, [i0, a.steady_integral(i0)], 0.1, 1e-6, |t, i, sat| {
            if sat {
                worst = worst.max((i - i0 * (-r * t / l).exp()).abs());
                last = (t, i);
            }
            assert!(i >= 0.0, "negative current {i} A at {t} s");
        });
        assert!(worst < 1e-9, "largest deviation from i_0 e^(−t R/L): {worst:e} A");
        // Limited (at 0 V) for the whole decay to K_p i = R i_0: t = (L/R) ln(K_p / R) = 0.35 s
        // is past the 0.1 s simulated, so the whole run was at the floor.
        assert!(last.0 > 0.099, "left the floor at {} s", last.0);
        // After 0.1 s, still 3 e^{−0.1/0.058} = 0.53 A: the magnet cannot let go any faster.
        assert!((last.1 - i0 * (-r * 0.1 / l).exp()).abs() < 1e-6 && last.1 > 0.5);

        let mut left = None;
        let rates = |i: f64, q: f64| a.unipolar_rates(Bridge::TwoQuadrant, 0.0, i, q, 0.0);
        integrate(rates, [i0, a.steady_integral(i0)], 3e-3, 1e-7, |t, i, sat| {
            if sat && left.is_none() {
                let exact = -v / r + (i0 + v / r) * (-r * t / l).exp();
                assert!((i - exact).abs() < 1e-9, "two-quadrant fall at {t} s: {i} A against {exact} A");
            } else if left.is_none() {
                left = Some((t, i));
            }
            assert!(i > 0.0, "negative current {i} A at {t} s");
        });
        // The integral is held at R i_0 while limited: the PI leaves −V_dc when
        // K_p i = V_dc + R i_0, at i = 0.28 A, after (L/R) ln((i_0 + V/R)/(i + V/R)) = 1.04 ms.
        let (t, i) = left.expect("the two-quadrant fall leaves the limit");
        let i_leave = (v + r * i0) / a.kp;
        let t_leave = l / r * ((i0 + v / r) / (i_leave + v / r)).ln();
        assert!((i - i_leave).abs() < 2e-3, "left −V_dc at {i} A, expected {i_leave} A");
        assert!((t - t_leave).abs() < 1e-6, "left −V_dc at {t} s, expected {t_leave} s");
    }

    #[test]
    fn a_magnet_current_never_reverses() {
        // A coil at zero current, asked for nothing, with the motional voltage of a rotor
        // moving toward it fast (216 V pushing the current negative) and the two-quadrant
        // bridge's −V_dc: the current stays at zero and the coil is not limited.
        let a = Amplifier::design(150.0, 58e-3, 1.0, 1500.0, 216.0);
        for bridge in [Bridge::OneQuadrant, Bridge::TwoQuadrant] {
            for (current, integral) in [(0.0, 0.0), (-1e-9, -5.0), (0.0, -200.0)] {
                let r = a.unipolar_rates(bridge, 0.0, current, integral, 216.0);
                assert_eq!(r.current_rate, 0.0, "{bridge:?} at {current} A");
                assert_eq!(r.voltage, 216.0, "an open coil's terminal voltage is its motional voltage");
                assert!(!r.saturated);
            }
            // A small current driven down hard reaches zero and stays there.
            let rates = |i: f64, q: f64| a.unipolar_rates(bridge, 0.0, i, q, 216.0);
            let mut lowest: f64 = 1.0;
            integrate(rates, [0.05, a.steady_integral(0.05)], 2e-3, 1e-7, |_, i, _| lowest = lowest.min(i));
            // Within a step of RK4 the state can dip by h·|di/dt| ≈ 1e-7 s · 6.3e3 A/s at most.
            assert!(lowest > -1e-3 && lowest <= 0.0, "lowest current {lowest} A");
        }
        // Without the clamp the same coil's current would be driven negative.
        let bipolar = a.rates(0.0, 0.0, 0.0, 1.0);
        assert!(bipolar.current_rate < 0.0);
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
