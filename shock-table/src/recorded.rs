//! Measured acceleration record.
//!
//! Samples `(t_i, a_i)`, `i = 0..n`, times strictly increasing, `t_0 ≥ 0`
//! (time from the pulse start). The acceleration is interpolated linearly;
//! on `t_i ≤ t < t_{i+1}`, with `s = t − t_i` and
//! `k_i = (a_{i+1} − a_i)/(t_{i+1} − t_i)`:
//!
//! ```text
//! a(t) = a_i + k_i s
//! v(t) = v_i + a_i s + k_i s²/2
//! d(t) = d_i + v_i s + a_i s²/2 + k_i s³/6
//! ```
//!
//! the exact integrals of the piecewise-linear acceleration, with `v_0 =
//! d_0 = 0` and the knot values `v_i`, `d_i` accumulated once at
//! construction. Evaluation finds the segment by binary search
//! (`O(log n)`), or in `O(1)` when the samples are uniformly spaced.
//!
//! Before `t_0` everything is zero (the acceleration steps to `a_0` at
//! `t_0`). After the last sample `t_{n−1}` the acceleration is zero, the
//! velocity is held at `v_{n−1}` and the displacement grows linearly,
//! `d = d_{n−1} + v_{n−1}(t − t_{n−1})`: a record that does not integrate
//! to zero velocity leaves the base moving (detrend it first if that is not
//! wanted).
//!
//! CSV files have the header `t_s,accel_m_s2` and one sample per line;
//! blank lines and lines starting with `#` are skipped. Only regular files of
//! at most [`MAX_RECORD_BYTES`] are read (a device such as `/dev/zero`, a
//! FIFO or a folder is refused at once).

use std::path::{Path, PathBuf};

use crate::error::ShockError;
use crate::kinematics::Kinematics;

/// Header line of a record CSV file.
pub const RECORD_CSV_HEADER: &str = "t_s,accel_m_s2";

/// Largest record file (bytes): 64 MiB, about two million samples at full precision.
pub const MAX_RECORD_BYTES: u64 = 64 << 20;

/// Relative tolerance on the spacing for a record to count as uniformly
/// sampled (`O(1)` lookup).
const UNIFORM_TOL: f64 = 1e-9;

/// Measured acceleration record, linearly interpolated (see the module
/// doc).
#[derive(Clone, Debug, PartialEq)]
pub struct Recorded {
    /// Sample times, s, strictly increasing, `t[0] ≥ 0`.
    t: Vec<f64>,
    /// Accelerations at the samples, m/s².
    a: Vec<f64>,
    /// Velocity at the samples, m/s (exact integral).
    v: Vec<f64>,
    /// Displacement at the samples, m (exact integral).
    d: Vec<f64>,
    /// `1/Δt` if the samples are uniform, else 0 (binary search).
    inv_dt: f64,
}

/// Check one sample; `prev` is the previous sample time. Returns a message
/// naming the column, value and unit.
fn check_sample(prev: Option<f64>, t: f64, a: f64) -> Result<(), String> {
    if !t.is_finite() {
        return Err(format!("t_s = {t} s: must be finite"));
    }
    if !a.is_finite() {
        return Err(format!("accel_m_s2 = {a} m/s²: must be finite"));
    }
    match prev {
        None if t < 0.0 => Err(format!("t_s = {t} s: the first sample must be at t >= 0 (time from the pulse start)")),
        Some(p) if t <= p => Err(format!("t_s = {t} s: times must be strictly increasing (previous sample at {p} s)")),
        _ => Ok(()),
    }
}

impl Recorded {
    /// Record from sample times `t` (s, strictly increasing, first ≥ 0) and
    /// accelerations `a` (m/s²), at least two samples, all finite.
    ///
    /// ```
    /// use shock_table::Recorded;
    /// // constant 2 m/s² for one second: v = 2t, d = t²
    /// let r = Recorded::from_samples(vec![0.0, 0.5, 1.0], vec![2.0; 3]).unwrap();
    /// let k = r.eval(0.75);
    /// assert!((k.vel - 1.5).abs() < 1e-15 && (k.disp - 0.5625).abs() < 1e-15);
    /// ```
    pub fn from_samples(t: Vec<f64>, a: Vec<f64>) -> Result<Self, ShockError> {
        let err = |message: String| ShockError::Record { path: None, line: None, message };
        if t.len() != a.len() {
            return Err(err(format!("{} times but {} accelerations: lengths must match", t.len(), a.len())));
        }
        let mut prev = None;
        for (i, (&ti, &ai)) in t.iter().zip(&a).enumerate() {
            check_sample(prev, ti, ai).map_err(|m| err(format!("sample {i}: {m}")))?;
            prev = Some(ti);
        }
        if t.len() < 2 {
            return Err(err(format!("{} sample(s): a record needs at least 2", t.len())));
        }
        Ok(Self::build(t, a))
    }

    /// Integrate the validated samples.
    fn build(t: Vec<f64>, a: Vec<f64>) -> Self {
        let n = t.len();
        let mut v = Vec::with_capacity(n);
        let mut d = Vec::with_capacity(n);
        v.push(0.0);
        d.push(0.0);
        for i in 0..n - 1 {
            let h = t[i + 1] - t[i];
            let k = (a[i + 1] - a[i]) / h;
            v.push(v[i] + a[i] * h + k * h * h / 2.0);
            d.push(d[i] + v[i] * h + a[i] * h * h / 2.0 + k * h * h * h / 6.0);
        }
        let dt = (t[n - 1] - t[0]) / (n - 1) as f64;
        let uniform = t.iter().enumerate().all(|(i, &ti)| (ti - (t[0] + dt * i as f64)).abs() <= UNIFORM_TOL * dt);
        let inv_dt = if uniform { 1.0 / dt } else { 0.0 };
        Self { t, a, v, d, inv_dt }
    }

    /// Read a record from a CSV file with header `t_s,accel_m_s2` (see the
    /// module doc). Errors name the file and the line.
    pub fn from_csv(path: &Path) -> Result<Self, ShockError> {
        let io = |error| ShockError::Io { path: path.to_path_buf(), error };
        let refuse = |message: String| ShockError::Record { path: Some(path.to_path_buf()), line: None, message };
        let text = crate::input::read_text(path, MAX_RECORD_BYTES).map_err(|e| match e.kind() {
            std::io::ErrorKind::InvalidInput => refuse(format!("{e}: a record must be a CSV file")),
            _ => io(e),
        })?;
        Self::parse_csv(&text, Some(path))
    }

    /// Parse CSV text (see [`from_csv`](Self::from_csv)); `path` is used in
    /// error messages only.
    pub fn parse_csv(text: &str, path: Option<&Path>) -> Result<Self, ShockError> {
        let err =
            |line: Option<usize>, message: String| ShockError::Record { path: path.map(PathBuf::from), line, message };
        let mut t = Vec::new();
        let mut a = Vec::new();
        let mut header_seen = false;
        for (i, raw) in text.lines().enumerate() {
            let line_no = i + 1;
            let line = raw.trim_start_matches('\u{feff}').trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            if !header_seen {
                if fields != ["t_s", "accel_m_s2"] {
                    return Err(err(Some(line_no), format!("header is `{line}`, expected `{RECORD_CSV_HEADER}`")));
                }
                header_seen = true;
                continue;
            }
            if fields.len() != 2 {
                return Err(err(
                    Some(line_no),
                    format!("{} field(s) in `{line}`, expected 2 (t_s,accel_m_s2)", fields.len()),
                ));
            }
            let parse = |s: &str, col: &str| {
                s.parse::<f64>().map_err(|_| err(Some(line_no), format!("{col} = `{s}`: not a number")))
            };
            let ti = parse(fields[0], "t_s")?;
            let ai = parse(fields[1], "accel_m_s2")?;
            check_sample(t.last().copied(), ti, ai).map_err(|m| err(Some(line_no), m))?;
            t.push(ti);
            a.push(ai);
        }
        if !header_seen {
            return Err(err(None, format!("empty file: expected the header `{RECORD_CSV_HEADER}`")));
        }
        if t.len() < 2 {
            return Err(err(None, format!("{} sample(s): a record needs at least 2", t.len())));
        }
        Ok(Self::build(t, a))
    }

    /// The same record with the acceleration (and so velocity and
    /// displacement) multiplied by `factor` (dimensionless).
    pub fn scaled(&self, factor: f64) -> Self {
        let mul = |x: &[f64]| x.iter().map(|&y| y * factor).collect();
        Self { t: self.t.clone(), a: mul(&self.a), v: mul(&self.v), d: mul(&self.d), inv_dt: self.inv_dt }
    }

    /// Sample times, s.
    pub fn times(&self) -> &[f64] {
        &self.t
    }

    /// Sample accelerations, m/s².
    pub fn accels(&self) -> &[f64] {
        &self.a
    }

    /// `true` if the samples are uniformly spaced (O(1) lookup).
    pub fn is_uniform(&self) -> bool {
        self.inv_dt > 0.0
    }

    /// Time of the last sample, s (the pulse's duration).
    pub fn duration(&self) -> f64 {
        self.t[self.t.len() - 1]
    }

    /// Velocity after the last sample, m/s.
    pub fn final_velocity(&self) -> f64 {
        self.v[self.v.len() - 1]
    }

    /// Index `i` of the segment `[t_i, t_{i+1})` holding `t`, for
    /// `t_0 ≤ t < t_{n−1}`.
    #[inline]
    fn segment(&self, t: f64) -> usize {
        let last = self.t.len() - 2;
        if self.inv_dt > 0.0 {
            // O(1) guess, corrected by one step for rounding at the knots.
            let mut i = (((t - self.t[0]) * self.inv_dt) as usize).min(last);
            if t < self.t[i] && i > 0 {
                i -= 1;
            } else if i < last && t >= self.t[i + 1] {
                i += 1;
            }
            i
        } else {
            (self.t.partition_point(|&x| x <= t) - 1).min(last)
        }
    }

    /// Kinematics at time `t` (s) from the pulse start.
    #[inline]
    pub fn eval(&self, t: f64) -> Kinematics {
        let n = self.t.len();
        if t < self.t[0] {
            return Kinematics::default();
        }
        if t >= self.t[n - 1] {
            let (v, d) = (self.v[n - 1], self.d[n - 1]);
            return Kinematics { accel: 0.0, vel: v, disp: d + v * (t - self.t[n - 1]) };
        }
        let i = self.segment(t);
        let s = t - self.t[i];
        let k = (self.a[i + 1] - self.a[i]) / (self.t[i + 1] - self.t[i]);
        let (a, v, d) = (self.a[i], self.v[i], self.d[i]);
        Kinematics { accel: a + k * s, vel: v + s * (a + s * k / 2.0), disp: d + s * (v + s * (a / 2.0 + s * k / 6.0)) }
    }

    /// Acceleration at `t` (s), m/s².
    #[inline]
    pub fn accel(&self, t: f64) -> f64 {
        let n = self.t.len();
        if t < self.t[0] || t >= self.t[n - 1] {
            return 0.0;
        }
        let i = self.segment(t);
        let k = (self.a[i + 1] - self.a[i]) / (self.t[i + 1] - self.t[i]);
        self.a[i] + k * (t - self.t[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numeric::{displacement_by_nested_simpson, simpson_piecewise};

    fn close(x: f64, y: f64, tol: f64) -> bool {
        (x - y).abs() <= tol * y.abs().max(1.0)
    }

    #[test]
    fn constant_accel_gives_analytic_v_d() {
        let t: Vec<f64> = (0..=100).map(|i| i as f64 * 0.01).collect();
        let r = Recorded::from_samples(t, vec![2.0; 101]).unwrap();
        assert!(r.is_uniform());
        for &x in &[0.0, 0.013, 0.5, 0.999] {
            let k = r.eval(x);
            assert!(close(k.accel, 2.0, 1e-14));
            assert!(close(k.vel, 2.0 * x, 1e-13), "v({x}) = {}", k.vel);
            assert!(close(k.disp, x * x, 1e-13), "d({x}) = {}", k.disp);
        }
    }

    #[test]
    fn linear_accel_gives_analytic_v_d_nonuniform() {
        // a = 3t on irregular knots; v = 1.5 t², d = t³/2 exactly.
        let t = vec![0.0, 0.1, 0.35, 0.4, 0.9, 1.0];
        let a: Vec<f64> = t.iter().map(|x| 3.0 * x).collect();
        let r = Recorded::from_samples(t, a).unwrap();
        assert!(!r.is_uniform());
        for &x in &[0.05, 0.1, 0.2, 0.37, 0.8, 0.9999] {
            let k = r.eval(x);
            assert!(close(k.accel, 3.0 * x, 1e-14));
            assert!(close(k.vel, 1.5 * x * x, 1e-14), "v({x})");
            assert!(close(k.disp, 0.5 * x * x * x, 1e-14), "d({x})");
        }
    }

    #[test]
    fn after_last_sample_velocity_held_displacement_linear() {
        let r = Recorded::from_samples(vec![0.0, 1.0], vec![2.0, 2.0]).unwrap();
        let k = r.eval(3.0);
        assert_eq!(k.accel, 0.0);
        assert!(close(k.vel, 2.0, 1e-15));
        assert!(close(k.disp, 1.0 + 2.0 * 2.0, 1e-15));
        assert_eq!(r.final_velocity(), 2.0);
    }

    #[test]
    fn zero_before_first_sample() {
        let r = Recorded::from_samples(vec![0.5, 1.0], vec![2.0, 2.0]).unwrap();
        assert_eq!(r.eval(0.49), Kinematics::default());
        assert_eq!(r.accel(0.2), 0.0);
        let k = r.eval(0.75);
        assert!(close(k.vel, 0.5, 1e-15) && close(k.disp, 0.0625, 1e-15));
    }

    #[test]
    fn uniform_and_binary_search_agree() {
        // Times i/1000 are not exact multiples of Δt in binary, so the O(1)
        // guess must be corrected at the knots.
        let t: Vec<f64> = (0..257).map(|i| i as f64 / 1000.0).collect();
        let a: Vec<f64> = t.iter().map(|x| (40.0 * x).sin() * 9.0).collect();
        let uni = Recorded::from_samples(t.clone(), a).unwrap();
        assert!(uni.is_uniform());
        let mut bin = uni.clone();
        bin.inv_dt = 0.0; // force binary search
        for &ti in &t {
            for x in [ti, ti + 3e-4, ti - 1e-17] {
                assert_eq!(uni.eval(x), bin.eval(x), "at {x}");
                if x >= t[0] && x < t[256] {
                    let i = uni.segment(x);
                    assert!(t[i] <= x && x < t[i + 1], "segment of {x}");
                }
            }
        }
        let mut t2 = t;
        t2[1] += 1e-6;
        let a2 = vec![0.0; 257];
        assert!(!Recorded::from_samples(t2, a2).unwrap().is_uniform());
    }

    #[test]
    fn exact_integrals_match_numerical() {
        let t = vec![0.0, 0.002, 0.005, 0.006, 0.01];
        let a = vec![0.0, 50.0, -20.0, 10.0, 5.0];
        let r = Recorded::from_samples(t.clone(), a.clone()).unwrap();
        // Independent linear interpolation (closed at the last sample, so the
        // quadrature does not see the step to zero after the record).
        let interp = |x: f64| {
            let i = (1..t.len()).find(|&i| x <= t[i]).unwrap_or(t.len() - 1);
            let w = (x - t[i - 1]) / (t[i] - t[i - 1]);
            a[i - 1] + w * (a[i] - a[i - 1])
        };
        for &x in &[0.001, 0.0055, 0.0099, 0.01] {
            let v = simpson_piecewise(&interp, &t, x, 200);
            let d = displacement_by_nested_simpson(interp, &t, x, 100);
            let k = r.eval(x);
            assert!((k.vel - v).abs() < 1e-13, "v({x}): {} vs {v}", k.vel);
            assert!((k.disp - d).abs() < 1e-14, "d({x}): {} vs {d}", k.disp);
        }
    }

    #[test]
    fn csv_round_trip_and_comments() {
        let text = "# hit\nt_s,accel_m_s2\n0,2\n\n0.5, 2\n1.0 ,2\n";
        let r = Recorded::parse_csv(text, None).unwrap();
        assert_eq!(r.times(), &[0.0, 0.5, 1.0]);
        assert!(close(r.eval(1.0).disp, 1.0, 1e-15));
    }

    #[test]
    fn malformed_csv_names_line() {
        let p = Some(Path::new("hit.csv"));
        let cases = [
            ("time,a\n0,1\n", "hit.csv: line 1: header is `time,a`"),
            ("t_s,accel_m_s2\n0,1\n0.1\n", "hit.csv: line 3: 1 field(s)"),
            ("t_s,accel_m_s2\n0,1\n0.1,x\n", "hit.csv: line 3: accel_m_s2 = `x`"),
            (
                "t_s,accel_m_s2\n0,1\n0.2,1\n# c\n0.2,1\n",
                "hit.csv: line 5: t_s = 0.2 s: times must be strictly increasing",
            ),
            ("t_s,accel_m_s2\n-1,1\n0,1\n", "hit.csv: line 2: t_s = -1 s"),
            ("t_s,accel_m_s2\n0,NaN\n1,1\n", "hit.csv: line 2: accel_m_s2 = NaN m/s²"),
            ("t_s,accel_m_s2\n0,1\n", "hit.csv: 1 sample(s)"),
            ("", "hit.csv: empty file"),
        ];
        for (text, want) in cases {
            let got = Recorded::parse_csv(text, p).unwrap_err().to_string();
            assert!(got.starts_with(want), "got `{got}`, want `{want}…`");
        }
    }

    #[test]
    fn from_samples_rejects_bad_input() {
        let m = |t: Vec<f64>, a: Vec<f64>| Recorded::from_samples(t, a).unwrap_err().to_string();
        assert!(m(vec![0.0, 1.0], vec![0.0]).contains("lengths must match"));
        assert!(m(vec![0.0, 0.0], vec![0.0; 2]).starts_with("sample 1: t_s = 0 s"));
        assert!(m(vec![0.0], vec![0.0]).contains("at least 2"));
    }

    #[test]
    fn scaled_scales_everything() {
        let r = Recorded::from_samples(vec![0.0, 1.0], vec![1.0, 3.0]).unwrap();
        let s = r.scaled(-2.0);
        let (k, ks) = (r.eval(0.7), s.eval(0.7));
        assert_eq!(ks.accel, -2.0 * k.accel);
        assert_eq!(ks.vel, -2.0 * k.vel);
        assert_eq!(ks.disp, -2.0 * k.disp);
    }

    #[test]
    fn devices_and_folders_are_refused_at_once() {
        for path in ["/dev/zero", "/"] {
            let e = Recorded::from_csv(Path::new(path)).unwrap_err().to_string();
            assert!(e.contains("not a regular file") && e.contains(path), "{e}");
        }
    }

    #[test]
    fn from_csv_missing_file_is_io() {
        let e = Recorded::from_csv(Path::new("/nonexistent/shock.csv")).unwrap_err();
        assert!(e.is_io());
    }
}
