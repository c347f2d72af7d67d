//! What of a long trace is drawn: per-pixel-column extremes for lines,
//! a stride for orbits, finite pieces split at bad samples.

use super::axes::AXIS_LIMIT;

/// Reduces a trace to at most four points per pixel column and run.
///
/// The x range `[x_lo, x_hi]` is split into `columns` equal columns. Of
/// each run of consecutive samples in one column the first, smallest,
/// largest and last sample are kept, in their original order. Samples that
/// are non-finite or rejected by `keep` are dropped and end the current
/// piece of line; the result is the list of pieces.
pub(crate) fn decimate_min_max(
    x: &[f64],
    y: &[f64],
    x_lo: f64,
    x_hi: f64,
    columns: usize,
    keep: impl Fn(f64, f64) -> bool,
) -> Vec<Vec<(f64, f64)>> {
    struct Run {
        col: i64,
        first: usize,
        min: usize,
        max: usize,
        last: usize,
    }
    fn flush(run: Option<Run>, x: &[f64], y: &[f64], piece: &mut Vec<(f64, f64)>) {
        if let Some(r) = run {
            let mut idx = [r.first, r.min, r.max, r.last];
            idx.sort_unstable();
            let mut prev = usize::MAX;
            for i in idx {
                if i != prev {
                    piece.push((x[i], y[i]));
                    prev = i;
                }
            }
        }
    }

    let columns = columns.max(1);
    let span = x_hi - x_lo;
    let per_unit = if span > 0.0 { columns as f64 / span } else { 0.0 };
    let max_col = columns as i64 - 1;
    let mut pieces = Vec::new();
    let mut piece = Vec::new();
    let mut run: Option<Run> = None;

    for (i, (&xi, &yi)) in x.iter().zip(y).enumerate() {
        if !xi.is_finite() || !yi.is_finite() || !keep(xi, yi) {
            flush(run.take(), x, y, &mut piece);
            if !piece.is_empty() {
                pieces.push(std::mem::take(&mut piece));
            }
            continue;
        }
        let col = (((xi - x_lo) * per_unit).floor() as i64).clamp(0, max_col);
        match &mut run {
            Some(r) if r.col == col => {
                if yi < y[r.min] {
                    r.min = i;
                }
                if yi > y[r.max] {
                    r.max = i;
                }
                r.last = i;
            }
            _ => {
                flush(run.take(), x, y, &mut piece);
                run = Some(Run { col, first: i, min: i, max: i, last: i });
            }
        }
    }
    flush(run, x, y, &mut piece);
    if !piece.is_empty() {
        pieces.push(piece);
    }
    pieces
}

/// Every `stride`-th index of `0..n` plus the last one, with the stride
/// chosen so that at most about `max_points` indices remain.
pub(crate) fn stride_indices(n: usize, max_points: usize) -> impl Iterator<Item = usize> {
    let stride = if n > max_points { n.div_ceil(max_points.max(1)) } else { 1 };
    let last_extra = n.checked_sub(1).filter(|last| last % stride != 0);
    (0..n).step_by(stride).chain(last_extra)
}

/// Splits an x-y trace, scaled by `scale`, into pieces of finite points
/// (within ±[`AXIS_LIMIT`]), at the given indices.
pub(crate) fn finite_pieces(
    x: &[f64],
    y: &[f64],
    indices: impl Iterator<Item = usize>,
    scale: f64,
) -> Vec<Vec<(f64, f64)>> {
    let mut pieces = Vec::new();
    let mut piece = Vec::new();
    for i in indices {
        let (xi, yi) = (x[i] * scale, y[i] * scale);
        if xi.abs() <= AXIS_LIMIT && yi.abs() <= AXIS_LIMIT {
            piece.push((xi, yi));
        } else if !piece.is_empty() {
            pieces.push(std::mem::take(&mut piece));
        }
    }
    if !piece.is_empty() {
        pieces.push(piece);
    }
    pieces
}
