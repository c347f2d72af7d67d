//! Rainflow counting of a load history, online (ASTM E1049-85 §5.4.4, the three-point rule on
//! a stack of reversals): each sample is pushed as it comes, so a run's ball loads are counted
//! without keeping them. Written here rather than taken from a crate: it runs per ball and per
//! output sample inside a member's run, and must hold only its stack of reversals (the crates
//! count a whole series held in memory).
//!
//! Reversals smaller than `gate` are ignored (a hysteresis filter: load changes below the gate
//! are not cycles worth counting and would only grow the stack). At the end the reversals left
//! on the stack (the residue) count as half cycles, as E1049 does.

/// An online rainflow counter that counts cycles whose range is at least `threshold`.
#[derive(Clone, Debug)]
pub struct Rainflow {
    gate: f64,
    threshold: f64,
    /// Reversals not yet closed into cycles.
    stack: Vec<f64>,
    /// The last sample, and the direction of travel since the last reversal (+1, −1, 0 unknown).
    last: Option<f64>,
    rising: i8,
    /// Full cycles counted (half cycles count 0.5) with range ≥ threshold.
    cycles: f64,
    /// The largest range seen in a counted cycle or half cycle.
    largest: f64,
}

impl Rainflow {
    /// A counter ignoring reversals below `gate` and counting ranges ≥ `threshold`.
    pub fn new(gate: f64, threshold: f64) -> Self {
        Self { gate, threshold, stack: Vec::new(), last: None, rising: 0, cycles: 0.0, largest: 0.0 }
    }

    /// The next sample of the history.
    pub fn push(&mut self, x: f64) {
        if !x.is_finite() {
            return;
        }
        let Some(last) = self.last else {
            self.last = Some(x);
            self.stack.push(x);
            return;
        };
        // The peak or valley being followed is `last` (the top of the stack is the reversal
        // before it); a move against the direction by at least `gate` makes `last` a reversal.
        let d = x - last;
        match self.rising {
            0 => {
                if d.abs() >= self.gate {
                    self.rising = if d > 0.0 { 1 } else { -1 };
                    self.last = Some(x);
                }
            }
            1 => {
                if x >= last {
                    self.last = Some(x);
                } else if last - x >= self.gate {
                    self.reversal(last);
                    self.rising = -1;
                    self.last = Some(x);
                }
            }
            _ => {
                if x <= last {
                    self.last = Some(x);
                } else if x - last >= self.gate {
                    self.reversal(last);
                    self.rising = 1;
                    self.last = Some(x);
                }
            }
        }
    }

    /// A new reversal: the three-point rule closes cycles on the stack.
    fn reversal(&mut self, r: f64) {
        self.stack.push(r);
        while self.stack.len() >= 3 {
            let n = self.stack.len();
            let (a, b, c) = (self.stack[n - 3], self.stack[n - 2], self.stack[n - 1]);
            let (x, y) = ((c - b).abs(), (b - a).abs());
            if x < y {
                break;
            }
            if n == 3 {
                // Y includes the starting point: a half cycle, and the start is dropped.
                self.count(y, 0.5);
                self.stack.remove(0);
            } else {
                self.count(y, 1.0);
                self.stack.truncate(n - 3);
                self.stack.push(c);
            }
        }
    }

    fn count(&mut self, range: f64, weight: f64) {
        if range >= self.threshold {
            self.cycles += weight;
            self.largest = self.largest.max(range);
        }
    }

    /// Closes the history: the last sample is a reversal, the residue counts as half cycles.
    /// Returns `(cycles with range ≥ threshold, the largest such range)`.
    pub fn finish(mut self) -> (f64, f64) {
        if let Some(last) = self.last {
            if self.rising != 0 {
                self.reversal(last);
            }
        }
        let residue: Vec<f64> = self.stack.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
        for r in residue {
            self.count(r, 0.5);
        }
        (self.cycles, self.largest)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn count(xs: &[f64], threshold: f64) -> f64 {
        let mut r = Rainflow::new(1e-9, threshold);
        xs.iter().for_each(|x| r.push(*x));
        r.finish().0
    }

    #[test]
    fn astm_e1049_example() {
        // ASTM E1049-85, Fig. 6 / X4: -2, 1, -3, 5, -1, 3, -4, 4, -2 gives ranges
        // 3 (0.5), 4 (1.5), 6 (0.5), 8 (1.0), 9 (0.5): 4 cycles in all.
        let h = [-2.0, 1.0, -3.0, 5.0, -1.0, 3.0, -4.0, 4.0, -2.0];
        assert_eq!(count(&h, 0.0), 4.0);
        assert_eq!(count(&h, 4.0), 3.5); // all but the range of 3
        assert_eq!(count(&h, 8.0), 1.5); // 8 (1.0) and 9 (0.5)
        assert_eq!(count(&h, 10.0), 0.0);
    }

    #[test]
    fn samples_between_reversals_and_small_wiggles_do_not_count() {
        // A sampled sine of amplitude 1 over 10 periods with a small ripple: 10 cycles of range 2.
        let xs: Vec<f64> = (0..=2000)
            .map(|i| {
                let t = i as f64 / 200.0;
                (std::f64::consts::TAU * t).sin() + 0.01 * (std::f64::consts::TAU * 37.0 * t).sin()
            })
            .collect();
        let mut r = Rainflow::new(0.05, 1.5);
        xs.iter().for_each(|x| r.push(*x));
        let (n, largest) = r.finish();
        assert!((n - 10.0).abs() <= 0.5, "{n}");
        assert!((largest - 2.0).abs() < 0.03, "{largest}");
    }
}
