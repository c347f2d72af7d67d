//! Peak finding: the peak of `|S|` between the measured frequencies.

use super::{Peak, Point};

/// The peak of `|S|` over the points (sorted by frequency): the vertex of the parabola through
/// the largest and its neighbours in (ln f, dB), or the largest point itself at an end.
pub fn peak_of(points: &[Point]) -> Option<Peak> {
    let i = (0..points.len()).max_by(|&a, &b| points[a].s_db.total_cmp(&points[b].s_db))?;
    let p = &points[i];
    let at = |f: f64, db: f64, spacing: f64| Peak { f_hz: f, s_abs: 10f64.powf(db / 20.0), s_db: db, spacing };
    if i == 0 || i + 1 == points.len() {
        let spacing = if points.len() > 1 {
            let j = if i == 0 { 1 } else { i - 1 };
            (points[j].f_hz / p.f_hz).ln().abs()
        } else {
            f64::NAN
        };
        return Some(at(p.f_hz, p.s_db, spacing));
    }
    let (a, c) = (&points[i - 1], &points[i + 1]);
    let (x0, x1, x2) = (a.f_hz.ln(), p.f_hz.ln(), c.f_hz.ln());
    let (y0, y1, y2) = (a.s_db, p.s_db, c.s_db);
    let spacing = (x1 - x0).max(x2 - x1);
    // The parabola through three points: its vertex.
    let d0 = (y1 - y0) / (x1 - x0);
    let d1 = (y2 - y1) / (x2 - x1);
    let curv = (d1 - d0) / (x2 - x0);
    if curv >= 0.0 {
        return Some(at(p.f_hz, p.s_db, spacing));
    }
    let xv = 0.5 * (x0 + x1) - d0 / (2.0 * curv);
    let xv = xv.clamp(x0, x2);
    let yv = y0 + d0 * (xv - x0) + curv * (xv - x0) * (xv - x1);
    Some(at(xv.exp(), yv.max(y1), spacing))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_parabola_finds_a_peak_between_points() {
        let f0 = 50.0;
        let pts: Vec<Point> = [49.0, 50.3, 51.6]
            .iter()
            .map(|f: &f64| {
                let db = 30.0 - 400.0 * (f / f0).ln().powi(2);
                Point { f_hz: *f, s: [0.0; 2], s_db: db, t_db: db, amplitude_v: 0.0, windows: 2, settled: true }
            })
            .collect();
        let p = peak_of(&pts).expect("peak");
        assert!((p.f_hz / f0 - 1.0).abs() < 1e-9 && (p.s_db - 30.0).abs() < 1e-9, "{p:?}");
    }
}
