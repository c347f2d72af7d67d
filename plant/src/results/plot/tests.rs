//! Tests of the charts and their helpers.

use super::axes::*;
use super::decimate::*;
use super::*;

/// A fresh directory under the system temp dir, unique per test,
/// removed when dropped.
struct Scratch(PathBuf);

impl Scratch {
    fn join(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        // PLOT_KEEP=1 keeps the charts to look at.
        if std::env::var_os("PLOT_KEEP").is_none() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

fn temp_dir(name: &str) -> Scratch {
    let dir = std::env::temp_dir().join(format!(
        "plant-plot-{}-{}-{}",
        name,
        std::process::id(),
        std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map(|d| d.as_nanos()).unwrap_or(0)
    ));
    std::fs::create_dir_all(&dir).expect("create temp dir");
    Scratch(dir)
}

/// A decoded RGB image.
struct Image {
    width: usize,
    height: usize,
    rgb: Vec<[u8; 3]>,
}

impl Image {
    fn read(path: &Path) -> Self {
        let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
        decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
        let mut reader = decoder.read_info().unwrap_or_else(|e| panic!("{} is not a PNG: {e}", path.display()));
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let channels = info.color_type.samples();
        assert!(channels >= 3, "{}: {:?}", path.display(), info.color_type);
        let rgb = buf[..info.buffer_size()].chunks(channels).map(|p| [p[0], p[1], p[2]]).collect();
        Self { width: info.width as usize, height: info.height as usize, rgb }
    }

    /// Pixels of colour `c` inside the plotting region: right of the y labels (130 px),
    /// below the title strip (60 px), above the x labels (80 px).
    fn count_inside(&self, c: RGBColor) -> usize {
        let mut n = 0;
        for y in 60..self.height.saturating_sub(80) {
            for x in 130..self.width.saturating_sub(30) {
                n += usize::from(self.rgb[y * self.width + x] == [c.0, c.1, c.2]);
            }
        }
        n
    }

    fn distinct_colours(&self) -> usize {
        let mut seen: Vec<[u8; 3]> = self.rgb.clone();
        seen.sort_unstable();
        seen.dedup();
        seen.len()
    }
}

/// The chart is a PNG of the expected size in which the data were drawn: at least
/// `min_pixels` pixels of the first series' colour in the plotting region, and more than
/// background, grid and text colours.
fn assert_drawn(path: &Path, size: (u32, u32), colour: RGBColor, min_pixels: usize) -> Image {
    let img = Image::read(path);
    assert_eq!((img.width, img.height), (size.0 as usize, size.1 as usize), "{}", path.display());
    let n = img.count_inside(colour);
    assert!(n >= min_pixels, "{}: only {n} pixels of the data colour {colour:?}", path.display());
    assert!(img.distinct_colours() > 20, "{}: {} colours", path.display(), img.distinct_colours());
    img
}

#[test]
fn lines_writes_png_linear_and_log() {
    let dir = temp_dir("lines");
    let t: Vec<f64> = (0..5000).map(|i| i as f64 * 1e-4).collect();
    let a: Vec<f64> = t.iter().map(|t| (80.0 * t).sin()).collect();
    let b: Vec<f64> = t.iter().map(|t| 1.0 + t * 10.0).collect();
    let s = [Series { label: "a", x: &t, y: &a }, Series { label: "b", x: &t, y: &b }];
    let p = dir.join("lin.png");
    lines(&p, "two", "t (s)", "v", &s, Scale::Linear).unwrap();
    // Six periods of a sine across the plot: thousands of pixels of its line, and the
    // second series too.
    let img = assert_drawn(&p, WIDE_SIZE, colour(0), 3000);
    assert!(img.count_inside(colour(1)) > 1000);
    let p = dir.join("log.png");
    lines(&p, "log", "t (s)", "v", &s, Scale::Log10).unwrap();
    // On a log axis only the positive half-waves of the sine are drawn; the ramp in full.
    assert_drawn(&p, WIDE_SIZE, colour(0), 1000);
    assert!(Image::read(&p).count_inside(colour(1)) > 1000);
}

#[test]
fn orbit_scatter_heatmap_write_png() {
    let dir = temp_dir("others");
    let n = 2000;
    let x: Vec<f64> = (0..n).map(|i| 1e-4 * (i as f64 * 0.05).cos()).collect();
    let y: Vec<f64> = (0..n).map(|i| 1e-4 * (i as f64 * 0.05).sin()).collect();
    let p = dir.join("orbit.png");
    orbit(&p, "orbit", &x, &y, 2e-4).unwrap();
    // A circle of half the clearance: its circumference in pixels, at least.
    assert_drawn(&p, SQUARE_SIZE, colour(0), 600);

    let g = [PointGroup { label: "g", x: &x, y: &y }];
    for eq in [true, false] {
        let p = dir.join(&format!("scatter-{eq}.png"));
        scatter(&p, "scatter", "x", "y", &g, eq).unwrap();
        assert_drawn(&p, if eq { SQUARE_SIZE } else { WIDE_SIZE }, colour(0), 1000);
    }

    let gx: Vec<f64> = (0..50).map(f64::from).collect();
    let gy: Vec<f64> = (0..30).map(|i| f64::from(i) * 10.0).collect();
    let z: Vec<Vec<f64>> = gy.iter().map(|yy| gx.iter().map(|xx| xx * yy).collect()).collect();
    let p = dir.join("heat.png");
    heatmap(&p, "heat", "x", "y", &gx, &gy, &z, "z").unwrap();
    // The lowest cells in the bottom colour of the map, and a gradient: many colours.
    let img = assert_drawn(&p, WIDE_SIZE, super::heatmap::viridis(0.0), 100);
    assert!(img.count_inside(super::heatmap::viridis(1.0)) > 10);
    assert!(img.distinct_colours() > 200, "{} colours", img.distinct_colours());
}

#[test]
fn decimation_keeps_single_spike_min_and_max() {
    let n = 1_000_000;
    let x: Vec<f64> = (0..n).map(|i| i as f64).collect();
    let mut y: Vec<f64> = (0..n).map(|i| (i as f64 * 0.01).sin() * 0.1).collect();
    y[123_457] = 50.0;
    y[876_543] = -30.0;
    let pieces = decimate_min_max(&x, &y, 0.0, n as f64, 1000, |_, _| true);
    assert_eq!(pieces.len(), 1);
    let kept = &pieces[0];
    assert!(kept.len() <= 4 * 1000, "kept {} points", kept.len());
    assert!(kept.contains(&(123_457.0, 50.0)));
    assert!(kept.contains(&(876_543.0, -30.0)));
    assert_eq!(kept.first(), Some(&(0.0, y[0])));
    assert_eq!(kept.last(), Some(&((n - 1) as f64, y[n - 1])));
    // Order of samples is preserved.
    assert!(kept.windows(2).all(|w| w[0].0 < w[1].0));
}

#[test]
fn decimation_splits_at_non_finite_and_rejected_values() {
    let x = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
    let y = [1.0, f64::NAN, 2.0, 3.0, -1.0, 4.0];
    let pieces = decimate_min_max(&x, &y, 0.0, 5.0, 100, |_, v| v > 0.0);
    assert_eq!(pieces, vec![vec![(0.0, 1.0)], vec![(2.0, 2.0), (3.0, 3.0)], vec![(5.0, 4.0)]]);
}

#[test]
fn stride_keeps_first_and_last() {
    let idx: Vec<usize> = stride_indices(1_000_001, 200_000).collect();
    assert_eq!(idx.first(), Some(&0));
    assert_eq!(idx.last(), Some(&1_000_000));
    assert!(idx.len() <= 200_002);
    let idx: Vec<usize> = stride_indices(10, 200_000).collect();
    assert_eq!(idx, (0..10).collect::<Vec<_>>());
}

#[test]
fn nan_input_draws_the_finite_data() {
    let dir = temp_dir("nan");
    let x = [0.0, 1.0, f64::NAN, 3.0, 4.0, f64::INFINITY];
    let y = [1.0, f64::NAN, 2.0, 3.0, f64::NEG_INFINITY, 5.0];
    let s = [Series { label: "s", x: &x, y: &y }];
    let p = dir.join("nan-lines.png");
    lines(&p, "nan", "x", "y", &s, Scale::Linear).unwrap();
    // The finite samples survive: a dot at x = 0 and the segment from 3 to... its line.
    assert!(Image::read(&p).count_inside(colour(0)) > 10);
    // Each chart draws its finite data and leaves the rest out.
    let drawn = |p: &Path, c: RGBColor| Image::read(p).count_inside(c);
    let p = dir.join("nan-log.png");
    lines(&p, "nan", "x", "y", &s, Scale::Log10).unwrap();
    assert!(drawn(&p, colour(0)) > 0, "log lines: nothing drawn");
    let o = [1e-5, f64::NAN, 2e-5, 3e-5];
    let p = dir.join("nan-orbit.png");
    orbit(&p, "o", &o, &o, f64::NAN).unwrap();
    assert!(drawn(&p, colour(0)) > 0, "orbit: nothing drawn");
    let g = [PointGroup { label: "g", x: &x, y: &y }];
    let p = dir.join("nan-scatter.png");
    scatter(&p, "s", "x", "y", &g, true).unwrap();
    assert!(drawn(&p, colour(0)) > 0, "scatter: nothing drawn");
    let z = vec![vec![f64::NAN, 1.0], vec![2.0, f64::INFINITY]];
    let p = dir.join("nan-heat.png");
    heatmap(&p, "h", "x", "y", &[0.0, 1.0], &[0.0, 1.0], &z, "z").unwrap();
    // The two finite cells span the colour map: the lowest at its bottom, the highest at its top.
    let (low, high) = (drawn(&p, super::heatmap::viridis(0.0)), drawn(&p, super::heatmap::viridis(1.0)));
    assert!(low > 100 && high > 100, "heat map cells: {low} and {high} pixels");
    // All non-finite is no data, not a panic.
    let all_nan = [f64::NAN; 4];
    let s = [Series { label: "s", x: &all_nan, y: &all_nan }];
    assert!(matches!(lines(&dir.join("x.png"), "t", "x", "y", &s, Scale::Linear), Err(PlotError::NoData { .. })));
}

#[test]
fn empty_input_is_an_error() {
    let dir = temp_dir("empty");
    let p = dir.join("e.png");
    assert!(matches!(lines(&p, "t", "x", "y", &[], Scale::Linear), Err(PlotError::NoData { .. })));
    let s = [Series { label: "s", x: &[], y: &[] }];
    assert!(matches!(lines(&p, "t", "x", "y", &s, Scale::Log10), Err(PlotError::NoData { .. })));
    assert!(matches!(orbit(&p, "t", &[], &[], 1e-4), Err(PlotError::NoData { .. })));
    assert!(matches!(scatter(&p, "t", "x", "y", &[], false), Err(PlotError::NoData { .. })));
    assert!(matches!(heatmap(&p, "t", "x", "y", &[], &[], &[], "z"), Err(PlotError::NoData { .. })));
    // Non-positive only, on a log axis.
    let v = [0.0, -1.0];
    let s = [Series { label: "s", x: &v, y: &v }];
    assert!(matches!(lines(&p, "t", "x", "y", &s, Scale::Log10), Err(PlotError::NoData { .. })));
    assert!(!p.exists());
}

/// Pins two plotters traps: an axis span that overflows to infinity
/// makes its tick search loop forever, and an overflowing midpoint
/// gives NaN bounds, which it asserts against.
#[test]
fn extreme_values_neither_panic_nor_hang() {
    // Run in a thread so that a hang fails the test (after five minutes: the machine may be
    // loaded) instead of stalling CI.
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let dir = temp_dir("extreme");
        let x = [0.0, 1.0, 2.0];
        let mut results = Vec::new();
        for y in [[-1e308, 1e308, 0.0], [1e308; 3], [1e-300, 2e-300, 1e300]] {
            let s = [Series { label: "s", x: &x, y: &y }];
            results.push(lines(&dir.join("e.png"), "t", "x", "y", &s, Scale::Linear));
            results.push(lines(&dir.join("l.png"), "t", "x", "y", &s, Scale::Log10));
            let g = [PointGroup { label: "g", x: &y, y: &y }];
            results.push(scatter(&dir.join("s.png"), "t", "x", "y", &g, true));
            results.push(orbit(&dir.join("o.png"), "t", &y, &y, 1e-4));
            results.push(heatmap(&dir.join("h.png"), "t", "x", "y", &x, &x[..1], &[y.to_vec()], "z"));
        }
        let _ = tx.send(results.into_iter().map(|r| r.map_err(|e| e.to_string())).collect::<Vec<_>>());
    });
    let results = rx.recv_timeout(std::time::Duration::from_secs(300)).expect("the charts hung (or panicked)");
    // Every chart is drawn: the data are finite, only extreme.
    for (i, r) in results.iter().enumerate() {
        assert!(r.is_ok(), "chart {i}: {r:?}");
    }
}

#[test]
fn unwritable_path_is_a_draw_error() {
    let dir = temp_dir("nodir");
    let p = dir.join("missing-subdir").join("x.png");
    let x = [0.0, 1.0];
    let s = [Series { label: "s", x: &x, y: &x }];
    let err = lines(&p, "t", "x", "y", &s, Scale::Linear).unwrap_err();
    assert!(matches!(err, PlotError::Draw { .. }), "{err}");
    assert!(err.to_string().contains("missing-subdir"), "{err}");
}

#[test]
fn mismatched_lengths_are_bad_input() {
    let dir = temp_dir("bad");
    let p = dir.join("b.png");
    let s = [Series { label: "s", x: &[1.0, 2.0], y: &[1.0] }];
    assert!(matches!(lines(&p, "t", "x", "y", &s, Scale::Linear), Err(PlotError::BadInput { .. })));
    let z = vec![vec![1.0, 2.0]];
    assert!(matches!(heatmap(&p, "t", "x", "y", &[0.0, 1.0, 2.0], &[0.0], &z, "z"), Err(PlotError::BadInput { .. })));
}

#[test]
fn constant_series_gets_a_nonzero_range() {
    assert_eq!(padded(0.0, 0.0), (-1.0, 1.0));
    let (lo, hi) = padded(5.0, 5.0);
    assert!(lo < 5.0 && hi > 5.0);
    let (lo, hi) = log_padded(3.0, 3.0);
    assert!(lo < 3.0 && hi > 3.0);
    let dir = temp_dir("const");
    let x = [0.0, 1.0, 2.0];
    let y = [2.5; 3];
    let s = [Series { label: "c", x: &x, y: &y }];
    // The constant line is drawn across the plot, on both scales.
    for (name, scale) in [("c.png", Scale::Linear), ("cl.png", Scale::Log10)] {
        lines(&dir.join(name), "c", "x", "y", &s, scale).unwrap();
        assert_drawn(&dir.join(name), WIDE_SIZE, colour(0), 500);
    }
}

#[test]
fn a_log_axis_labels_values_below_its_lowest_power_of_ten() {
    // 0.015 … 1.8: plotters' own key points label 0.1 and 1 only, leaving the data under 0.1
    // beside an unlabelled stretch; ours label 1, 2, 5 × 10ᵏ over two decades.
    let (bold, light) = log_key_points(0.015, 1.8);
    let want = [0.02, 0.05, 0.1, 0.2, 0.5, 1.0];
    assert_eq!(bold.len(), want.len(), "{bold:?}");
    for (b, w) in bold.iter().zip(want) {
        assert!((b / w - 1.0).abs() < 1e-12, "{bold:?}");
    }
    assert!(light.len() > bold.len() && light.iter().all(|v| (0.015..=1.8).contains(v)));
    // Within one decade every 1…9 × 10ᵏ is labelled; over nine decades every power; over
    // forty decades at most thirteen powers.
    assert_eq!(log_key_points(0.15, 0.95).0.len(), 8);
    assert_eq!(log_key_points(3e-8, 50.0).0.len(), 9);
    let (wide, _) = log_key_points(1e-20, 1e20);
    assert!(wide.len() >= 2 && wide.len() <= 13, "{wide:?}");
}

#[test]
fn tick_labels_are_short() {
    let f = linear_ticks(0.0, 1.5);
    assert_eq!(f(&0.2), "0.2");
    assert_eq!(f(&1.0), "1.0");
    let f = linear_ticks(-2e-6, 2e-6);
    assert_eq!(f(&5e-7), "5e-7");
    assert_eq!(f(&1e-22), "0");
    let f = linear_ticks(0.0, 1000.0);
    assert_eq!(f(&200.0), "200");
    assert_eq!(short_number(250.0), "250");
    assert_eq!(short_number(12.5), "12.5");
}

#[test]
fn equal_axes_have_equal_scale() {
    let ((x0, x1), (y0, y1)) = equalise((0.0, 2.0), (0.0, 1.0), 400, 300);
    assert!(((x1 - x0) / 400.0 - (y1 - y0) / 300.0).abs() < 1e-12);
    assert!(x1 - x0 >= 2.0 && y1 - y0 >= 1.0);
}

/// Probability curves: every curve drawn in its colour, and a curve whose slices differ in
/// length refused.
#[test]
fn probability_draws_every_curve_and_refuses_uneven_slices() {
    let dir = temp_dir("probability");
    let x: Vec<f64> = (1..=20).map(f64::from).collect();
    let falling: Vec<f64> = x.iter().map(|x| if *x < 4.0 { 1.0 } else { 0.0 }).collect();
    let rising: Vec<f64> = x.iter().map(|x| (x / 20.0).min(1.0)).collect();
    let lo: Vec<f64> = falling.iter().map(|p| (p - 0.2f64).max(0.0)).collect();
    let hi: Vec<f64> = falling.iter().map(|p| (p + 0.2f64).min(1.0)).collect();
    let lo2: Vec<f64> = rising.iter().map(|p| (p - 0.1f64).max(0.0)).collect();
    let hi2: Vec<f64> = rising.iter().map(|p| (p + 0.1f64).min(1.0)).collect();
    let curves = [
        ProbabilityCurve { label: "falling", x: &x, p: &falling, lo: &lo, hi: &hi },
        ProbabilityCurve { label: "rising", x: &x, p: &rising, lo: &lo2, hi: &hi2 },
    ];
    let p = dir.join("p.png");
    probability(&p, "two curves", "peak (G)", &curves, 0.25).unwrap();
    let img = assert_drawn(&p, (1200, 900), colour(0), 500);
    assert!(img.count_inside(colour(1)) > 500, "the second curve is not drawn");
    let short = [ProbabilityCurve { label: "short", x: &x, p: &rising[..3], lo: &lo2, hi: &hi2 }];
    let e = probability(&dir.join("bad.png"), "bad", "x", &short, 0.0).unwrap_err();
    assert!(matches!(e, PlotError::BadInput { .. }), "{e}");
    let nothing = [ProbabilityCurve { label: "none", x: &[f64::NAN], p: &[0.5], lo: &[0.4], hi: &[0.6] }];
    assert!(matches!(probability(&dir.join("n.png"), "n", "x", &nothing, 0.0), Err(PlotError::NoData { .. })));
}

/// The top row of the plotting area: where the y axis begins, the first dark vertical run of
/// 30 rows or more near x = 130 px (legend marks and text are shorter; data drawn on the axis
/// may break the run further down, never above its start).
fn plot_top(img: &Image) -> usize {
    let dark = |x: usize, y: usize| img.rgb[y * img.width + x].iter().all(|v| *v < 60);
    let mut top = usize::MAX;
    for x in 120..140 {
        let mut run = 0;
        for y in 0..img.height {
            run = if dark(x, y) { run + 1 } else { 0 };
            if run == 30 {
                top = top.min(y + 1 - 30);
                break;
            }
        }
    }
    assert!(top < img.height / 3, "no y axis found near the top: {top}");
    top
}

/// Pixels of colour `c` above row `top`.
fn count_above(img: &Image, c: RGBColor, top: usize) -> usize {
    img.rgb[..top * img.width].iter().filter(|p| **p == [c.0, c.1, c.2]).count()
}

/// Every chart kind with a legend puts it above the plot, never over the data: each series'
/// legend mark lies above the y axis' top, and no data are drawn there.
#[test]
fn legends_lie_above_the_plot() {
    let dir = temp_dir("legends");
    let t: Vec<f64> = (0..2000).map(|i| i as f64 * 1e-3).collect();
    let ys: Vec<Vec<f64>> = (0..3).map(|k| t.iter().map(|t| (t * 7.0 + k as f64).sin() + k as f64).collect()).collect();
    let s: Vec<Series> = ys.iter().map(|y| Series { label: "a series", x: &t, y }).collect();
    let p = dir.join("lines.png");
    lines(&p, "lines", "t (s)", "v", &s, Scale::Linear).unwrap();
    let g = [PointGroup { label: "one", x: &t, y: &ys[0] }, PointGroup { label: "two", x: &t, y: &ys[1] }];
    let q = dir.join("scatter.png");
    scatter(&q, "scatter", "x", "y", &g, false).unwrap();
    let pos: Vec<f64> = t.iter().map(|t| t + 0.01).collect();
    let r = dir.join("loglog.png");
    loglog(
        &r,
        "loglog",
        "x",
        "y",
        &[Series { label: "line", x: &pos, y: &pos }],
        &[PointGroup { label: "crosses", x: &pos[..10], y: &pos[..10] }],
    )
    .unwrap();
    for (path, n) in [(&p, 3), (&q, 2), (&r, 2)] {
        let img = Image::read(path);
        let top = plot_top(&img);
        for i in 0..n {
            let above = count_above(&img, colour(i), top);
            assert!(above >= 10, "{}: series {i}'s legend mark is not above the plot (row {top})", path.display());
        }
    }
}

/// Twenty series, twenty looks: the palette's ten colours solid, then dashed.
#[test]
fn each_of_twenty_series_has_a_style_of_its_own() {
    let styles: Vec<_> = (0..20).map(super::lines::series_style).collect();
    for (i, a) in styles.iter().enumerate() {
        for b in &styles[i + 1..] {
            assert_ne!(a, b, "series {i} repeats a style");
        }
    }
    assert!(!styles[9].dashed && styles[10].dashed);
}

/// A Campbell diagram draws each mode's points in its colour; with bending modes, the
/// rigid-body modes get a panel of their own on the left (their points in both halves), the
/// bending modes only the right one.
#[test]
fn campbell_puts_the_rigid_body_modes_beside_the_bending_modes() {
    let dir = temp_dir("campbell");
    let speeds: Vec<f64> = (0..21).map(|i| i as f64 * 10.0).collect();
    let rigid: Vec<f64> = speeds.iter().map(|s| 50.0 + 0.05 * s).collect();
    let bending: Vec<f64> = speeds.iter().map(|s| 500.0 + 0.1 * s).collect();
    let mode = |label: &str, k: usize, y: &'static [f64], rigid: bool, x: &'static [f64]| ModePoints {
        label: label.into(),
        colour: colour(k),
        shape: Shape::Circle,
        open: false,
        x,
        y,
        rigid,
    };
    let (speeds, rigid, bending): (&'static [f64], &'static [f64], &'static [f64]) =
        (speeds.leak(), rigid.leak(), bending.leak());
    let p = dir.join("flexible.png");
    campbell(&p, "flexible", &[mode("rigid", 0, rigid, true, speeds), mode("bending", 2, bending, false, speeds)])
        .unwrap();
    let img = Image::read(&p);
    assert_eq!((img.width, img.height), (1800, 900));
    let top = plot_top(&img) + 2;
    let half = |c: RGBColor, right: bool| {
        let xs = if right { img.width / 2..img.width } else { 0..img.width / 2 };
        (top..img.height - 80)
            .flat_map(|y| xs.clone().map(move |x| (x, y)))
            .filter(|(x, y)| img.rgb[y * img.width + x] == [c.0, c.1, c.2])
            .count()
    };
    let counts = (half(colour(0), false), half(colour(0), true), half(colour(2), true), half(colour(2), false));
    assert!(counts.0 > 200 && counts.1 > 200, "rigid-body points in both panels: {counts:?}, top {top}");
    assert!(half(colour(2), true) > 200, "bending points on the right");
    assert_eq!(half(colour(2), false), 0, "no bending point on the rigid-body panel");
    let q = dir.join("rigid.png");
    campbell(&q, "rigid", &[mode("rigid", 0, rigid, true, speeds)]).unwrap();
    assert_drawn(&q, WIDE_SIZE, colour(0), 200);
    assert!(matches!(campbell(&dir.join("none.png"), "none", &[]), Err(PlotError::NoData { .. })));
    let short = ModePoints { x: &speeds[..3], ..mode("short", 0, rigid, true, speeds) };
    assert!(matches!(campbell(&dir.join("bad.png"), "bad", &[short]), Err(PlotError::BadInput { .. })));
}
