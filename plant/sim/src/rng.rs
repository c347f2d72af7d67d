//! The one seeded generator of the testbed: SplitMix64 (Steele, Lea, Flood
//! 2014), for everything that must be random yet the same on every machine:
//! sensor noise, random soak programmes, ensemble draws, benchmark inputs.
//!
//! Written by hand rather than taken from `rand`: the values are part of the
//! outputs (a programme's shocks, an ensemble's members), so they must not
//! change with a dependency's version, and the generator is ten lines.
//!
//! Independent streams (one per ensemble member, say) come from
//! [`SplitMix64::stream`]: the seed and the stream index are mixed through
//! the generator's own finaliser, so neighbouring indices give unrelated
//! sequences.

/// SplitMix64: 64 bits of state, period 2^64, passes BigCrush.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SplitMix64(u64);

/// The Weyl increment of SplitMix64 (2^64 / φ).
const GOLDEN: u64 = 0x9E37_79B9_7F4A_7C15;

/// SplitMix64's output function (a bijection of `u64`).
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

impl SplitMix64 {
    /// Generator from a seed.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The generator's whole state: [`SplitMix64::new`] of it goes on with the same numbers.
    pub fn state(&self) -> u64 {
        self.0
    }

    /// Stream `index` of `seed`: an independent generator per member, shard
    /// or axis, the same wherever it is made.
    ///
    /// ```
    /// use plant_sim::rng::SplitMix64;
    /// let (mut a, mut b) = (SplitMix64::stream(7, 0), SplitMix64::stream(7, 1));
    /// assert_ne!(a.next_u64(), b.next_u64());
    /// assert_eq!(SplitMix64::stream(7, 1).next_u64(), SplitMix64::stream(7, 1).next_u64());
    /// ```
    pub fn stream(seed: u64, index: u64) -> Self {
        Self(mix(seed ^ mix(index.wrapping_add(1).wrapping_mul(GOLDEN))))
    }

    /// Next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(GOLDEN);
        mix(self.0)
    }

    /// Uniform in `[0, 1)` (53 random bits).
    #[inline]
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in `[lo, hi)`.
    ///
    /// ```
    /// let u = plant_sim::rng::SplitMix64::new(7).uniform([1.0, 20.0]);
    /// assert!((1.0..20.0).contains(&u));
    /// ```
    #[inline]
    pub fn uniform(&mut self, [lo, hi]: [f64; 2]) -> f64 {
        lo + self.unit() * (hi - lo)
    }

    /// Two independent standard normal numbers (Box–Muller).
    pub fn normal_pair(&mut self) -> [f64; 2] {
        // 1 − unit() is in (0, 1]: the logarithm is finite.
        let (u1, u2) = (1.0 - self.unit(), self.unit());
        let r = (-2.0 * u1.ln()).sqrt();
        let (s, c) = (std::f64::consts::TAU * u2).sin_cos();
        [r * c, r * s]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_reference_sequence() {
        // The test vector of rand_xoshiro's SplitMix64 (from Vigna's reference C code).
        let mut r = SplitMix64::new(1477776061723855037);
        let expected: [u64; 5] =
            [1985237415132408290, 2979275885539914483, 13511426838097143398, 8488337342461049707, 15141737807933549159];
        for e in expected {
            assert_eq!(r.next_u64(), e);
        }
    }

    #[test]
    fn normal_pairs_have_unit_variance() {
        let mut r = SplitMix64::new(3);
        let n = 100_000;
        let (mut sum, mut sum2) = (0.0, 0.0);
        for _ in 0..n / 2 {
            for z in r.normal_pair() {
                sum += z;
                sum2 += z * z;
            }
        }
        let mean = sum / n as f64;
        let var = sum2 / n as f64 - mean * mean;
        assert!(mean.abs() < 0.02 && (var - 1.0).abs() < 0.02, "mean {mean}, variance {var}");
    }

    #[test]
    fn streams_differ_and_repeat() {
        let firsts: Vec<u64> = (0..64).map(|i| SplitMix64::stream(42, i).next_u64()).collect();
        let mut sorted = firsts.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), firsts.len());
        assert_eq!(SplitMix64::stream(42, 5), SplitMix64::stream(42, 5));
    }
}
