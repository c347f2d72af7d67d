//! Stores of fixed greatest size for a run's samples, so that what a run
//! keeps to draw does not grow with its length:
//!
//! * [`Strided`]: every k-th item, k doubling whenever the store fills
//!   (orbits, Poincaré points of the transient);
//! * [`MinMaxBins`]: per bin of a known abscissa range, the first, smallest,
//!   largest and last sample (time traces drawn per pixel column: every peak
//!   and every envelope stays).

/// Every `stride`-th item pushed, at most `cap` of them; when full, every
/// other one is dropped and the stride doubles.
#[derive(Clone, Debug)]
pub struct Strided<T> {
    cap: usize,
    stride: u64,
    seen: u64,
    items: Vec<T>,
}

impl<T> Strided<T> {
    /// A store of at most `cap` (≥ 2) items.
    pub fn new(cap: usize) -> Self {
        Self { cap: cap.max(2), stride: 1, seen: 0, items: Vec::new() }
    }

    /// Offers the next item.
    pub fn push(&mut self, item: T) {
        if self.seen.is_multiple_of(self.stride) {
            if self.items.len() == self.cap {
                let mut i = 0;
                self.items.retain(|_| {
                    i += 1;
                    i % 2 == 1
                });
                self.stride *= 2;
            }
            if self.seen.is_multiple_of(self.stride) {
                self.items.push(item);
            }
        }
        self.seen += 1;
    }

    /// The items kept, in order.
    pub fn items(&self) -> &[T] {
        &self.items
    }

    /// The stride now: the items kept are those offered at multiples of it.
    pub fn stride(&self) -> u64 {
        self.stride
    }

    /// Items offered so far.
    pub fn seen(&self) -> u64 {
        self.seen
    }

    /// The items kept.
    pub fn into_items(self) -> Vec<T> {
        self.items
    }
}

/// One bin of [`MinMaxBins`]: `(x, y)` of its first, smallest, largest and last finite sample.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Bin {
    index: usize,
    first: (f64, f64),
    min: (f64, f64),
    max: (f64, f64),
    last: (f64, f64),
    /// A non-finite sample fell into the bin: the line breaks after it.
    broken: bool,
    any: bool,
}

/// Per-bin extremes of a series over `[x0, x1]` split into `bins` equal bins,
/// filled as samples come in increasing `x`.
#[derive(Clone, Debug)]
pub struct MinMaxBins {
    x0: f64,
    per_unit: f64,
    bins: usize,
    data: Vec<Bin>,
}

impl MinMaxBins {
    /// `bins` bins over `[x0, x1]` (samples outside go to the end bins).
    pub fn new(x0: f64, x1: f64, bins: usize) -> Self {
        let span = x1 - x0;
        let per_unit = if span > 0.0 && span.is_finite() { bins as f64 / span } else { 0.0 };
        Self { x0, per_unit, bins: bins.max(1), data: Vec::new() }
    }

    /// The next sample (x increasing).
    pub fn push(&mut self, x: f64, y: f64) {
        let index = (((x - self.x0) * self.per_unit).floor().max(0.0) as usize).min(self.bins - 1);
        let bin = match self.data.last_mut() {
            Some(b) if b.index == index => b,
            _ => {
                let p = (x, y);
                self.data.push(Bin { index, first: p, min: p, max: p, last: p, broken: false, any: false });
                self.data.last_mut().expect("just pushed")
            }
        };
        if !(x.is_finite() && y.is_finite()) {
            bin.broken = true;
            return;
        }
        let p = (x, y);
        if !bin.any {
            *bin = Bin { first: p, min: p, max: p, last: p, any: true, ..*bin };
            return;
        }
        if y < bin.min.1 {
            bin.min = p;
        }
        if y > bin.max.1 {
            bin.max = p;
        }
        bin.last = p;
    }

    /// The kept samples in order of `x`, a NaN after each bin that held a non-finite
    /// sample (so that a line breaks there), as `(x, y)` columns.
    pub fn points(&self) -> (Vec<f64>, Vec<f64>) {
        let (mut xs, mut ys) = (Vec::with_capacity(4 * self.data.len()), Vec::with_capacity(4 * self.data.len()));
        for b in &self.data {
            if b.any {
                let mut kept = [b.first, b.min, b.max, b.last];
                kept.sort_by(|p, q| p.0.total_cmp(&q.0));
                let mut previous: Option<(f64, f64)> = None;
                for p in kept {
                    if previous != Some(p) {
                        xs.push(p.0);
                        ys.push(p.1);
                        previous = Some(p);
                    }
                }
            }
            if b.broken {
                xs.push(b.last.0);
                ys.push(f64::NAN);
            }
        }
        (xs, ys)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strided_keeps_a_bounded_even_sample_with_the_first_item() {
        let mut s = Strided::new(100);
        for i in 0..10_000u64 {
            s.push(i);
        }
        let items = s.items();
        assert!(items.len() <= 100 && items.len() > 50, "{}", items.len());
        assert_eq!(items[0], 0);
        let stride = items[1] - items[0];
        assert!(items.windows(2).all(|w| w[1] - w[0] == stride), "{items:?}");
        let mut short = Strided::new(100);
        (0..10u64).for_each(|i| short.push(i));
        assert_eq!(short.items(), (0..10).collect::<Vec<_>>().as_slice());
    }

    #[test]
    fn bins_keep_every_peak_and_break_at_bad_samples() {
        let mut b = MinMaxBins::new(0.0, 1.0, 10);
        for i in 0..1000 {
            let x = i as f64 / 1000.0;
            let y = if i == 123 {
                50.0
            } else if i == 877 {
                -30.0
            } else if i == 500 {
                f64::NAN
            } else {
                (x * 20.0).sin()
            };
            b.push(x, y);
        }
        let (x, y) = b.points();
        assert!(x.len() <= 10 * 5);
        assert!(x.iter().zip(&y).any(|p| *p.0 == 0.123 && *p.1 == 50.0));
        assert!(x.iter().zip(&y).any(|p| *p.0 == 0.877 && *p.1 == -30.0));
        assert_eq!(y.iter().filter(|v| v.is_nan()).count(), 1);
        assert_eq!((x[0], y[0]), (0.0, 0.0));
        assert!(x.windows(2).all(|w| w[0] <= w[1]));
    }
}
