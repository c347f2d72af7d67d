//! Peak finding: frequencies added around the largest `|S|` until the resolution is reached,
//! and the peak of `|S|` between the measured frequencies.

use super::{near_rotation, Measure, Peak, Point};

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

impl Measure<'_> {
    /// Adds a frequency near the largest `|S|` until its neighbours are within the resolution:
    /// the vertex of the parabola through it and its neighbours (in ln f, dB) while that lies
    /// half a resolution or more from it, then the points one resolution either side of it. At
    /// an end of the grid, the interval beside it is halved.
    pub(super) fn refine(&mut self) {
        let mut pts: Vec<(f64, f64)> = self.points.iter().map(|p| (p.f_hz.ln(), p.s_db)).collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let Some(i) = (0..pts.len()).max_by(|&a, &b| pts[a].1.total_cmp(&pts[b].1)) else { return };
        let res = self.settings.resolution;
        // Points added around one peak, at most: a guard, the rule ends long before.
        if self.refined >= 64 {
            return;
        }
        let add = |x: f64, me: &mut Self| {
            let f = x.exp();
            let clear = pts.iter().all(|p| (p.0 - x).abs() > 0.25 * res);
            let ok = clear && !near_rotation(f, me.speed_hz) && f <= me.f_max;
            if ok {
                me.queue.push_back(f);
            }
            ok
        };
        if i == 0 || i + 1 == pts.len() {
            let j = if i == 0 { 1 } else { i - 1 };
            if let Some(n) = pts.get(j) {
                if (n.0 - pts[i].0).abs() > res {
                    add(0.5 * (n.0 + pts[i].0), self);
                }
            }
            self.refined += self.queue.len();
            return;
        }
        let ((x0, y0), (x1, y1), (x2, y2)) = (pts[i - 1], pts[i], pts[i + 1]);
        let (left, right) = (x1 - x0, x2 - x1);
        if left <= res * (1.0 + 1e-9) && right <= res * (1.0 + 1e-9) {
            return;
        }
        let d0 = (y1 - y0) / left;
        let d1 = (y2 - y1) / right;
        let curv = (d1 - d0) / (x2 - x0);
        let vertex = (curv < 0.0).then(|| (0.5 * (x0 + x1) - d0 / (2.0 * curv)).clamp(x0, x2));
        let at_vertex = vertex.is_some_and(|xv| (xv - x1).abs() >= 0.5 * res && add(xv, self));
        if !at_vertex {
            if left > res * (1.0 + 1e-9) {
                add(x1 - res.min(0.5 * left), self);
            }
            if right > res * (1.0 + 1e-9) {
                add(x1 + res.min(0.5 * right), self);
            }
        }
        self.refined += self.queue.len();
    }
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
