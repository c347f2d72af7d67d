//! Amplitude spectra of the orbit, with whirl direction, and the short-time
//! Fourier transform.
//!
//! One-sided spectra of a real signal (dx or dy) and the two-sided spectrum of
//! the complex orbit `z = dx + j dy`: a circular whirl `r e^{j 2π f t}` shows
//! as amplitude `r` at `+f` when it is forward (turning with the rotor, which
//! spins toward +θ) and at `−f` when it is backward. A Hann window is applied
//! and amplitudes are corrected for its coherent gain, so a sinusoid of
//! amplitude `A` at a bin frequency reads `A`. The mean is removed.

use rustfft::{num_complex::Complex, FftPlanner};

/// Amplitude against frequency.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Spectrum {
    /// Frequencies (Hz), ascending; negative = backward whirl (complex spectra).
    pub freq_hz: Vec<f64>,
    /// Amplitude at each frequency, in the signal's unit.
    pub amplitude: Vec<f64>,
}

/// A spectral peak.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Peak {
    /// Frequency (Hz), refined between bins; negative = backward whirl.
    pub freq_hz: f64,
    /// Amplitude at the peak bin.
    pub amplitude: f64,
}

fn hann(n: usize) -> Vec<f64> {
    if n < 2 {
        return vec![1.0; n];
    }
    (0..n).map(|i| 0.5 - 0.5 * (std::f64::consts::TAU * i as f64 / n as f64).cos()).collect()
}

fn windowed_fft(x: &[f64], y: Option<&[f64]>) -> (Vec<Complex<f64>>, f64) {
    let n = x.len();
    let w = hann(n);
    let mean_x = x.iter().sum::<f64>() / n as f64;
    let mean_y = y.map_or(0.0, |y| y.iter().sum::<f64>() / n as f64);
    let mut buf: Vec<Complex<f64>> =
        (0..n).map(|i| Complex::new((x[i] - mean_x) * w[i], y.map_or(0.0, |y| (y[i] - mean_y) * w[i]))).collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut buf);
    (buf, w.iter().sum())
}

/// One-sided amplitude spectrum of a real signal sampled every `dt` seconds.
///
/// ```
/// let dt = 1e-4;
/// let x: Vec<f64> = (0..4000).map(|i| 3.0 * (std::f64::consts::TAU * 250.0 * i as f64 * dt).cos()).collect();
/// let s = plant::analysis::spectrum::amplitude_spectrum(&x, dt);
/// let k = s.amplitude.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1)).unwrap().0;
/// assert!((s.freq_hz[k] - 250.0).abs() < 1e-9 && (s.amplitude[k] - 3.0).abs() < 1e-9);
/// ```
pub fn amplitude_spectrum(x: &[f64], dt: f64) -> Spectrum {
    let n = x.len();
    if n < 4 {
        return Spectrum::default();
    }
    let (buf, gain) = windowed_fft(x, None);
    let df = 1.0 / (n as f64 * dt);
    let half = n / 2;
    Spectrum {
        freq_hz: (0..=half).map(|k| k as f64 * df).collect(),
        amplitude: (0..=half).map(|k| if k == 0 { buf[0].norm() / gain } else { 2.0 * buf[k].norm() / gain }).collect(),
    }
}

/// Two-sided amplitude spectrum of `z = x + j y` (positive frequencies =
/// forward whirl), ascending in frequency.
///
/// ```
/// // A backward whirl of radius 2 at 60 Hz.
/// let dt = 1e-4;
/// let t = |i: usize| std::f64::consts::TAU * 60.0 * i as f64 * dt;
/// let x: Vec<f64> = (0..5000).map(|i| 2.0 * t(i).cos()).collect();
/// let y: Vec<f64> = (0..5000).map(|i| -2.0 * t(i).sin()).collect();
/// let s = plant::analysis::spectrum::whirl_spectrum(&x, &y, dt);
/// let k = s.amplitude.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1)).unwrap().0;
/// assert!((s.freq_hz[k] + 60.0).abs() < 1e-9 && (s.amplitude[k] - 2.0).abs() < 1e-9);
/// ```
pub fn whirl_spectrum(x: &[f64], y: &[f64], dt: f64) -> Spectrum {
    let n = x.len().min(y.len());
    if n < 4 {
        return Spectrum::default();
    }
    let (buf, gain) = windowed_fft(&x[..n], Some(&y[..n]));
    let df = 1.0 / (n as f64 * dt);
    // Bins n/2+1 … n−1 are the negative frequencies; put them first.
    let order = (n / 2 + 1..n).chain(0..=n / 2);
    let mut s = Spectrum::default();
    for k in order {
        let f = if k > n / 2 { k as f64 - n as f64 } else { k as f64 };
        s.freq_hz.push(f * df);
        s.amplitude.push(buf[k].norm() / gain);
    }
    s
}

/// The `count` largest local maxima above `floor` × the largest amplitude,
/// at least `min_separation_hz` apart, largest first. Frequencies are refined
/// by a parabola through the log amplitudes of the three bins around a peak.
pub fn peaks(s: &Spectrum, count: usize, floor: f64, min_separation_hz: f64) -> Vec<Peak> {
    let a = &s.amplitude;
    let top = a.iter().copied().fold(0.0, f64::max);
    let mut candidates: Vec<Peak> = Vec::new();
    for k in 1..a.len().saturating_sub(1) {
        if a[k] > a[k - 1] && a[k] >= a[k + 1] && a[k] > floor * top && a[k] > 0.0 {
            let (l, c, r) = (a[k - 1].max(1e-300).ln(), a[k].ln(), a[k + 1].max(1e-300).ln());
            let denom = l - 2.0 * c + r;
            let shift = if denom < 0.0 { (0.5 * (l - r) / denom).clamp(-0.5, 0.5) } else { 0.0 };
            let df = s.freq_hz[k + 1] - s.freq_hz[k];
            candidates.push(Peak { freq_hz: s.freq_hz[k] + shift * df, amplitude: a[k] });
        }
    }
    candidates.sort_by(|p, q| q.amplitude.total_cmp(&p.amplitude));
    let mut out: Vec<Peak> = Vec::new();
    for p in candidates {
        if out.len() == count {
            break;
        }
        if out.iter().all(|q| (q.freq_hz - p.freq_hz).abs() >= min_separation_hz) {
            out.push(p);
        }
    }
    out
}

/// A spectrogram of the complex orbit: power in dB (re 1 m²) on a time ×
/// frequency grid.
#[derive(Clone, Debug, Default)]
pub struct Spectrogram {
    /// Window centre times (s).
    pub time_s: Vec<f64>,
    /// Frequencies (Hz), ascending, negative = backward.
    pub freq_hz: Vec<f64>,
    /// `db[f][t]`: 20 log10 of the amplitude (m), floored at −200 dB.
    pub db: Vec<Vec<f64>>,
}

/// Short-time Fourier transform of `z = x + j y` sampled every `dt` from
/// `t0`, with Hann windows of `window` samples every `hop` samples, keeping
/// `|f| ≤ f_max_hz`.
pub fn stft(x: &[f64], y: &[f64], t0: f64, dt: f64, window: usize, hop: usize, f_max_hz: f64) -> Spectrogram {
    let n = x.len().min(y.len());
    let mut out = Spectrogram::default();
    if window < 4 || hop == 0 || n < window {
        return out;
    }
    let first = whirl_spectrum(&x[..window], &y[..window], dt);
    let keep: Vec<usize> = (0..first.freq_hz.len()).filter(|&k| first.freq_hz[k].abs() <= f_max_hz).collect();
    out.freq_hz = keep.iter().map(|&k| first.freq_hz[k]).collect();
    out.db = vec![Vec::new(); keep.len()];
    let mut start = 0;
    while start + window <= n {
        let s = whirl_spectrum(&x[start..start + window], &y[start..start + window], dt);
        out.time_s.push(t0 + (start as f64 + window as f64 / 2.0) * dt);
        for (row, &k) in keep.iter().enumerate() {
            out.db[row].push((20.0 * s.amplitude[k].max(1e-10).log10()).max(-200.0));
        }
        start += hop;
    }
    out
}

/// Most time columns a [`StftBuilder`] keeps: more than a chart has pixels.
pub const MAX_STFT_COLUMNS: usize = 1024;

/// The short-time Fourier transform of [`stft`], computed as the samples
/// come, in bounded memory: it keeps the last `window` samples and at most
/// [`MAX_STFT_COLUMNS`] time columns. When a run has more columns than that,
/// neighbouring columns are merged pairwise, keeping the larger value of each
/// cell (as the heat map does with cells that share a pixel), so peaks stay
/// visible; a run with fewer columns gives exactly [`stft`]'s grid.
#[derive(Clone, Debug)]
pub struct StftBuilder {
    dt: f64,
    window: usize,
    hop: usize,
    f_max_hz: f64,
    t0: Option<f64>,
    /// Samples since `t0`.
    count: usize,
    x: Vec<f64>,
    y: Vec<f64>,
    /// Bins kept (|f| ≤ f_max), found from the first window.
    keep: Vec<usize>,
    out: Spectrogram,
    /// Raw columns per kept column.
    factor: usize,
    /// The column being merged: its first and last raw centre, its cells, how many raw columns.
    pending: Option<(f64, f64, Vec<f64>, usize)>,
    /// First and last raw centre of each kept column.
    spans: Vec<(f64, f64)>,
}

impl StftBuilder {
    /// Windows of `window` samples every `hop` samples of a signal sampled every `dt`,
    /// keeping `|f| ≤ f_max_hz`.
    pub fn new(dt: f64, window: usize, hop: usize, f_max_hz: f64) -> Self {
        Self {
            dt,
            window,
            hop,
            f_max_hz,
            t0: None,
            count: 0,
            x: Vec::with_capacity(window),
            y: Vec::with_capacity(window),
            keep: Vec::new(),
            out: Spectrogram::default(),
            factor: 1,
            pending: None,
            spans: Vec::new(),
        }
    }

    /// The next sample of `z = x + j y`, at time `t` (only the first time is used: the
    /// samples are taken as evenly spaced by `dt`).
    pub fn push(&mut self, t: f64, x: f64, y: f64) {
        if self.window < 4 || self.hop == 0 {
            return;
        }
        let t0 = *self.t0.get_or_insert(t);
        self.x.push(x);
        self.y.push(y);
        self.count += 1;
        if self.x.len() < self.window {
            return;
        }
        let s = whirl_spectrum(&self.x, &self.y, self.dt);
        if self.out.freq_hz.is_empty() && self.keep.is_empty() {
            self.keep = (0..s.freq_hz.len()).filter(|&k| s.freq_hz[k].abs() <= self.f_max_hz).collect();
            self.out.freq_hz = self.keep.iter().map(|&k| s.freq_hz[k]).collect();
            self.out.db = vec![Vec::new(); self.keep.len()];
        }
        let start = self.count - self.window;
        let centre = t0 + (start as f64 + self.window as f64 / 2.0) * self.dt;
        let cells: Vec<f64> =
            self.keep.iter().map(|&k| (20.0 * s.amplitude[k].max(1e-10).log10()).max(-200.0)).collect();
        self.add_column(centre, cells);
        self.x.drain(..self.hop.min(self.x.len()));
        self.y.drain(..self.hop.min(self.y.len()));
    }

    fn add_column(&mut self, centre: f64, cells: Vec<f64>) {
        let (first, last, merged, n) = match self.pending.take() {
            None => (centre, centre, cells, 1),
            Some((first, _, mut merged, n)) => {
                merged.iter_mut().zip(&cells).for_each(|(m, c)| *m = m.max(*c));
                (first, centre, merged, n + 1)
            }
        };
        if n < self.factor {
            self.pending = Some((first, last, merged, n));
            return;
        }
        if self.spans.len() == MAX_STFT_COLUMNS {
            // Merge neighbours pairwise: half the columns, each twice as wide.
            let half = MAX_STFT_COLUMNS / 2;
            for i in 0..half {
                self.spans[i] = (self.spans[2 * i].0, self.spans[2 * i + 1].1);
                for row in &mut self.out.db {
                    row[i] = row[2 * i].max(row[2 * i + 1]);
                }
            }
            self.spans.truncate(half);
            self.out.db.iter_mut().for_each(|row| row.truncate(half));
            self.factor *= 2;
            if n < self.factor {
                self.pending = Some((first, last, merged, n));
                return;
            }
        }
        self.spans.push((first, last));
        for (row, v) in self.out.db.iter_mut().zip(merged) {
            row.push(v);
        }
    }

    /// The spectrogram: one column per kept column, at the middle of the raw window
    /// centres it holds.
    pub fn finish(mut self) -> Spectrogram {
        if let Some((first, last, merged, _)) = self.pending.take() {
            self.spans.push((first, last));
            for (row, v) in self.out.db.iter_mut().zip(merged) {
                row.push(v);
            }
        }
        self.out.time_s = self.spans.iter().map(|&(a, b)| if a == b { a } else { 0.5 * (a + b) }).collect();
        self.out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn whirl(f_hz: f64, r: f64, n: usize, dt: f64) -> (Vec<f64>, Vec<f64>) {
        let ph = |i: usize| std::f64::consts::TAU * f_hz * i as f64 * dt;
        ((0..n).map(|i| r * ph(i).cos()).collect(), (0..n).map(|i| r * ph(i).sin()).collect())
    }

    #[test]
    fn forward_and_backward_whirls_land_on_their_sides() {
        let dt = 5e-5;
        let (x1, y1) = whirl(500.0, 2e-6, 8000, dt);
        let (x2, y2) = whirl(-65.0, 30e-6, 8000, dt);
        let x: Vec<f64> = x1.iter().zip(&x2).map(|(a, b)| a + b).collect();
        let y: Vec<f64> = y1.iter().zip(&y2).map(|(a, b)| a + b).collect();
        let p = peaks(&whirl_spectrum(&x, &y, dt), 2, 0.01, 10.0);
        assert_eq!(p.len(), 2);
        assert!((p[0].freq_hz + 65.0).abs() < 0.5, "{p:?}");
        assert!((p[1].freq_hz - 500.0).abs() < 0.5, "{p:?}");
        // Off-bin frequency: amplitude within the Hann scalloping loss (≤ 15 %).
        assert!((p[0].amplitude - 30e-6).abs() < 0.16 * 30e-6, "{p:?}");
        assert!((p[1].amplitude - 2e-6).abs() < 1e-3 * 2e-6, "{p:?}");
    }

    #[test]
    fn parabolic_refinement_finds_off_bin_frequencies() {
        let dt = 1e-3;
        let x: Vec<f64> = (0..1000).map(|i| (std::f64::consts::TAU * 123.4 * i as f64 * dt).sin()).collect();
        let p = peaks(&amplitude_spectrum(&x, dt), 1, 0.1, 1.0);
        assert!((p[0].freq_hz - 123.4).abs() < 0.05, "{p:?}");
    }

    #[test]
    fn stft_follows_a_frequency_step() {
        let dt = 1e-4;
        let n = 20000;
        let f = |i: usize| if i < n / 2 { 100.0 } else { -300.0 };
        let mut phase = 0.0;
        let (mut x, mut y) = (Vec::new(), Vec::new());
        for i in 0..n {
            phase += std::f64::consts::TAU * f(i) * dt;
            x.push(f64::cos(phase));
            y.push(f64::sin(phase));
        }
        let s = stft(&x, &y, 0.0, dt, 1024, 512, 1000.0);
        let loudest = |col: usize| {
            let row = (0..s.freq_hz.len()).max_by(|&a, &b| s.db[a][col].total_cmp(&s.db[b][col])).unwrap();
            s.freq_hz[row]
        };
        assert!((loudest(0) - 100.0).abs() < 10.0);
        assert!((loudest(s.time_s.len() - 1) + 300.0).abs() < 10.0);
        assert!(s.freq_hz.iter().all(|f| f.abs() <= 1000.0));
    }

    #[test]
    fn online_stft_equals_the_batch_one_and_stays_bounded() {
        let dt = 1e-4;
        let n = 20000;
        let (x, y): (Vec<f64>, Vec<f64>) =
            (0..n).map(|i| (i as f64 * 0.3).sin() * (1.0 + i as f64 * 1e-4)).map(|v| (v, 0.5 * v)).unzip();
        let batch = stft(&x, &y, 0.0, dt, 256, 64, 2000.0);
        let mut online = StftBuilder::new(dt, 256, 64, 2000.0);
        for i in 0..n {
            online.push(i as f64 * dt, x[i], y[i]);
        }
        let online = online.finish();
        assert!(batch.time_s.len() < MAX_STFT_COLUMNS);
        assert_eq!(online.freq_hz, batch.freq_hz);
        assert_eq!(online.db, batch.db);
        for (a, b) in online.time_s.iter().zip(&batch.time_s) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }

        // Eight times as many columns as kept: merged by eight, the maxima kept.
        let long = 64 * (8 * MAX_STFT_COLUMNS) + 256 - 64;
        let mut online = StftBuilder::new(dt, 256, 64, 2000.0);
        let mut peak_at = 0.0;
        for i in 0..long {
            let t = i as f64 * dt;
            // One loud burst in the middle.
            let loud = if (i / 64) == 4 * MAX_STFT_COLUMNS { 1e3 } else { 1.0 };
            if loud > 1.0 {
                peak_at = t;
            }
            online.push(t, loud * (i as f64 * 0.3).sin(), 0.0);
        }
        let g = online.finish();
        assert_eq!(g.time_s.len(), MAX_STFT_COLUMNS);
        let top = g.db.iter().flatten().copied().fold(f64::NEG_INFINITY, f64::max);
        assert!(top > 20.0 * 100.0f64.log10(), "the burst was merged away: top {top} dB");
        let col = (0..g.time_s.len()).find(|&c| g.db.iter().any(|r| r[c] == top)).unwrap();
        assert!((g.time_s[col] - peak_at).abs() < 8.0 * 64.0 * dt, "{} vs {peak_at}", g.time_s[col]);
    }
}
