//! One pass over a run's rows, as they are made (`plant run`) or read back
//! (`plant analyze`): the summary's figures, the analysis, and what the
//! run's charts draw, in memory that does not grow with the run's length.
//!
//! The charts of a run are drawn from a bounded, decimated envelope: the
//! run's duration is known up front, so each time trace is kept as the
//! first, smallest, largest and last sample of each of [`CHART_BINS`] bins
//! of the time axis (about four per pixel column of the chart, which then
//! keeps at most four per column); the orbit as every k-th row, at most
//! [`ORBIT_POINTS`].

use crate::analysis::mid_span::{MidSpan, MidSpanAnalyzer};
use crate::analysis::tilt::{TiltAnalysis, TiltAnalyzer};
use crate::analysis::{Analysis, AnalysisData, Analyzer};
use crate::bounded::{MinMaxBins, Strided};
use crate::config::Scene;
use crate::figures::{analysis_spec, plane_analysis_spec, Figures, FiguresBuilder};
use crate::trace::{Record, Row};

/// Bins of the time axis of a run's time charts.
pub const CHART_BINS: usize = 4096;

/// Most orbit points kept for `orbit.png` (a 1.5 s run at 20 kHz keeps all its 30 000 rows).
pub const ORBIT_POINTS: usize = 50_000;

/// What a run's own charts draw of one bearing plane (`orbit.png`, `radius.png`,
/// `race_speed.png`, `currents.png`, `contact_force.png`), bounded.
#[derive(Clone, Debug)]
pub struct ChartData {
    /// Rotor radius (µm) against time (ms).
    pub radius_um: MinMaxBins,
    /// Race speed (rpm) against time (ms).
    pub race_rpm: MinMaxBins,
    /// Coil currents (A) against time (ms).
    pub current_a: [MinMaxBins; 2],
    /// Normal and friction contact forces (N) against time (ms).
    pub force_n: [MinMaxBins; 2],
    orbit: Strided<(f64, f64)>,
    first_finite: Option<(u64, (f64, f64))>,
    last: Option<(f64, f64)>,
}

impl ChartData {
    fn new(duration_s: f64) -> Self {
        let bins = || MinMaxBins::new(0.0, duration_s * 1e3, CHART_BINS);
        Self {
            radius_um: bins(),
            race_rpm: bins(),
            current_a: [bins(), bins()],
            force_n: [bins(), bins()],
            orbit: Strided::new(ORBIT_POINTS),
            first_finite: None,
            last: None,
        }
    }

    fn push(&mut self, r: &Row) {
        let ms = r.t_s * 1e3;
        let (x, y) = (r.motion.dx_m, r.motion.dy_m);
        self.radius_um.push(ms, x.hypot(y) * 1e6);
        self.race_rpm.push(ms, r.loads.race_speed_rad_s * 60.0 / std::f64::consts::TAU);
        self.current_a[0].push(ms, r.loads.ix_a);
        self.current_a[1].push(ms, r.loads.iy_a);
        self.force_n[0].push(ms, r.loads.contact_force_n);
        self.force_n[1].push(ms, r.loads.friction_force_n);
        if self.first_finite.is_none() && x.is_finite() && y.is_finite() {
            self.first_finite = Some((self.orbit.seen(), (x, y)));
        }
        self.orbit.push((x, y));
        self.last = Some((x, y));
    }

    /// The orbit's points (m): every k-th row, with the first finite one and the last
    /// (the chart marks them).
    pub fn orbit(&self) -> (Vec<f64>, Vec<f64>) {
        let stride = self.orbit.stride();
        let mut points = Vec::with_capacity(self.orbit.items().len() + 2);
        if let Some((_, p)) = self.first_finite.filter(|(i, _)| !i.is_multiple_of(stride)) {
            points.push(p);
        }
        points.extend_from_slice(self.orbit.items());
        if let Some(p) = self.last.filter(|_| !(self.orbit.seen() - 1).is_multiple_of(stride)) {
            points.push(p);
        }
        points.into_iter().unzip()
    }
}

/// One bearing plane's consumer: its figures, analysis and charts.
#[derive(Clone, Debug)]
struct PlaneRecorder {
    figures: FiguresBuilder,
    analyzer: Analyzer,
    charts: Option<ChartData>,
}

/// The samples' consumer: one [`PlaneRecorder`] per bearing plane (fed the plane's own row,
/// [`Record::plane`]) and, for a two-plane rotor, the tilt.
#[derive(Clone, Debug)]
pub struct Recorder {
    planes: Vec<PlaneRecorder>,
    tilt: Option<(TiltAnalyzer, Option<MinMaxBins>)>,
    /// The rotor at mid-span (a bending rotor's run with charts), for `orbit_mid.png`: its orbit
    /// only, the row's `dx_m`, `dy_m` replaced by `mid_dx_m`, `mid_dy_m`.
    mid: Option<ChartData>,
    /// The rotor at mid-span's figures (a bending rotor's run).
    mid_span: Option<MidSpanAnalyzer>,
}

/// What a [`Recorder`] made of one bearing plane.
#[derive(Clone, Debug)]
pub struct PlaneRecorded {
    /// The summary's figures.
    pub figures: Figures,
    /// The analysis.
    pub analysis: Analysis,
    /// What the analysis charts draw.
    pub analysis_data: AnalysisData,
    /// What the run's charts draw (when charts were asked for).
    pub charts: Option<ChartData>,
}

/// What a [`Recorder`] made of a run.
#[derive(Clone, Debug)]
pub struct Recorded {
    /// Each bearing plane's (one for the planar model).
    pub planes: Vec<PlaneRecorded>,
    /// The tilt's figures (two-plane runs).
    pub tilt: Option<TiltAnalysis>,
    /// The tilt angle (µrad) against time (ms), for `tilt.png` (two-plane runs with charts).
    pub tilt_chart: Option<MinMaxBins>,
    /// The rotor at mid-span, for `orbit_mid.png` (flexible runs with charts; its orbit only).
    pub mid_chart: Option<ChartData>,
    /// A bending rotor's figures at mid-span (`None` for the rigid rotors, and for a trace
    /// written before the mid-span's columns).
    pub mid_span: Option<MidSpan>,
}

impl Recorded {
    /// The plane whose figures lead the summary: the larger steady contact fraction, then the
    /// larger peak contact force, then plane A (0).
    pub fn governing(&self) -> usize {
        let key = |p: &PlaneRecorded| (p.analysis.steady_contact_fraction, p.figures.max_contact_force_n);
        match self.planes.as_slice() {
            [a, b] if key(b) > key(a) => 1,
            _ => 0,
        }
    }
}

impl Recorder {
    /// A recorder for a run of `scene`; `charts` keeps what the charts draw (and
    /// builds the spectrograms).
    pub fn new(scene: &Scene, charts: bool) -> Self {
        let planes = (0..scene.planes())
            .map(|i| PlaneRecorder {
                figures: FiguresBuilder::new(scene.first_shock_start()),
                analyzer: Analyzer::new(plane_analysis_spec(scene, i), charts.then_some(scene.output_interval)),
                charts: charts.then(|| ChartData::new(scene.duration)),
            })
            .collect();
        let tilt = scene.rotor.tilts().then(|| {
            let bins = charts.then(|| MinMaxBins::new(0.0, scene.duration * 1e3, CHART_BINS));
            (TiltAnalyzer::new(analysis_spec(scene)), bins)
        });
        let mid = (charts && scene.rotor.bends()).then(|| ChartData::new(scene.duration));
        let mid_span = scene.rotor.mid_span_weight().map(MidSpanAnalyzer::new);
        Self { planes, tilt, mid, mid_span }
    }

    /// The next sample.
    pub fn push(&mut self, r: &Record) {
        for (i, plane) in self.planes.iter_mut().enumerate() {
            let row = r.plane(i);
            plane.figures.push(&row);
            plane.analyzer.push(&row);
            if let Some(c) = &mut plane.charts {
                c.push(&row);
            }
        }
        if let Some((tilt, bins)) = &mut self.tilt {
            tilt.push(r);
            if let (Some(bins), Some([a, b])) = (bins, r.slopes()) {
                bins.push(r.a.t_s * 1e3, a.hypot(b) * 1e6);
            }
        }
        if let Some(m) = &mut self.mid_span {
            m.push(r);
        }
        if let (Some(c), Some(m)) = (&mut self.mid, r.mid) {
            let mut row = r.a;
            row.motion.dx_m = m.mid_dx_m;
            row.motion.dy_m = m.mid_dy_m;
            c.push(&row);
        }
    }

    /// What was recorded; rows at or after `failure_time` (s) are left out of the maxima.
    pub fn finish(self, failure_time: Option<f64>) -> Recorded {
        let planes = self
            .planes
            .into_iter()
            .map(|p| {
                let (analysis, analysis_data) = p.analyzer.finish();
                PlaneRecorded { figures: p.figures.finish(failure_time), analysis, analysis_data, charts: p.charts }
            })
            .collect();
        let (tilt, tilt_chart) = match self.tilt {
            Some((t, bins)) => (Some(t.finish()), bins),
            None => (None, None),
        };
        let mid_span = self.mid_span.and_then(|m| m.finish(failure_time));
        Recorded { planes, tilt, tilt_chart, mid_chart: self.mid, mid_span }
    }
}
