//! The sampled law against the continuous PD at each rate (`compare.csv`, [`RateRow`]): the
//! deviation from the continuous run after the shock, the damping of the levitated loop from a
//! free decay, the time to recover and the post-shock mode, in-process and co-simulated.

use super::*;

crate::table::table_row! {
/// One compared configuration: a row of `compare.csv`.
#[derive(Clone, Debug, Serialize)]
pub struct RateRow {
    /// Controller rate (Hz); 0 for the continuous run.
    #[serde(with = "plain")]
    pub rate_hz: f64,
    /// `continuous`, `sampled` or `lockstep`.
    pub mode: ControlMode,
    /// How the run ended.
    pub status: Status,
    /// RMS deviation of the rotor displacement from the continuous run (m).
    #[serde(with = "sci")]
    pub rms_dev_m: f64,
    /// Max deviation (m).
    #[serde(with = "sci")]
    pub max_dev_m: f64,
    /// Damping ratio of the levitated loop measured from a free decay.
    #[serde(with = "sci")]
    pub damping_ratio: f64,
    /// Time from the shock start to the last contact (s); NaN if still in contact at the end.
    #[serde(with = "sci")]
    pub recover_s: f64,
    /// Post-shock mode.
    pub post_shock_mode: MotionMode,
}
}

/// Window after the shock for the deviation (s).
pub const WINDOW: f64 = 0.1;

/// Distance of the rotor displacement from the reference's over the window (m): (RMS, max);
/// infinite for a run that did not complete.
fn deviation(r: &RunResult, reference: &RunResult, start: f64) -> (f64, f64) {
    if r.run.outcome != Outcome::Completed {
        return (f64::INFINITY, f64::INFINITY);
    }
    if r.trace.planes() == 1 {
        return crate::trace::window_error(&r.trace, &reference.trace, start, start + WINDOW, 1.0);
    }
    // The worse of the two bearing planes.
    (0..r.trace.planes()).fold((0.0, 0.0), |(rms, max), i| {
        let (a, b) = (r.trace.plane(i), reference.trace.plane(i));
        let (e_rms, e_max) = crate::trace::window_error(&a, &b, start, start + WINDOW, 1.0);
        (f64::max(rms, e_rms), f64::max(max, e_max))
    })
}

/// Runs the comparison and writes `compare.csv` and the plots into `out`.
pub fn compare(
    scene_path: &Path,
    sets: &[String],
    rates: &[f64],
    cosim: bool,
    out: &Path,
    log: &mut dyn FnMut(&str),
    stop: &AtomicBool,
) -> anyhow::Result<Vec<RateRow>> {
    let base = prepare(out, sets)?;
    let continuous = with(scene_path, &base, &["controller.mode=\"continuous\"".into()])?;
    let start = continuous.first_shock_start();
    // All traces on the same grid: the output rate of the scene.
    let reference = finished(&continuous, stop)?.ok_or_else(nothing_finished)?;
    let shocks = continuous.shock_count();
    let decay = |extra: &[String]| free_decay(scene_path, &base, extra, shocks, stop).map(|d| d.map(|(xi, _, _)| xi));
    let row = |rate: f64, mode: ControlMode, r: &RunResult, scene: &Scene, xi: f64| {
        let (rms, max) = if mode == ControlMode::Continuous { (0.0, 0.0) } else { deviation(r, &reference, start) };
        let s = Summary::new(scene, r);
        RateRow {
            rate_hz: rate,
            mode,
            status: s.status,
            rms_dev_m: rms,
            max_dev_m: max,
            damping_ratio: xi,
            recover_s: recovery(r, start).unwrap_or(f64::NAN),
            post_shock_mode: s.analysis.post_shock_mode,
        }
    };
    let Some(xi) = decay(&["controller.mode=\"continuous\"".into()])? else { return Err(nothing_finished()) };
    let mut rows = vec![row(0.0, ControlMode::Continuous, &reference, &continuous, xi)];
    log(&format!("continuous: damping ratio {:.4}", rows[0].damping_ratio));
    // Each run's robustness answer, when asked for (`--robustness N`; robust.rs).
    let mut answers = Vec::new();
    let continuous_sets: Vec<String> = base.iter().cloned().chain(["controller.mode=\"continuous\"".into()]).collect();
    let summary = Summary::new(&continuous, &reference);
    answers.extend(robust::answer(scene_path, &continuous_sets, &continuous, &summary, "continuous", log, stop)?);
    let mut traces: Vec<(String, RunResult)> = vec![("continuous".into(), reference.clone())];
    let modes = if cosim { vec![ControlMode::Sampled, ControlMode::Lockstep] } else { vec![ControlMode::Sampled] };
    'rates: for &rate in rates {
        for &mode in &modes {
            let name = snake_name(&mode);
            let extra = vec![format!("controller.mode=\"{name}\""), format!("controller.rate_hz={rate:?}")];
            let scene = with(scene_path, &base, &extra)?;
            let Some(r) = finished(&scene, stop)? else { break 'rates };
            let xi = if mode == ControlMode::Sampled {
                let Some(xi) = decay(&extra)? else { break 'rates };
                xi
            } else {
                rows.last().map_or(f64::NAN, |r| r.damping_ratio)
            };
            let rw = row(rate, mode, &r, &scene, xi);
            log(&format!(
                "{name} at {rate} Hz: {}, deviation rms {:.2e} m max {:.2e} m, damping ratio {:.4}, {}, {}",
                rw.status,
                rw.rms_dev_m,
                rw.max_dev_m,
                rw.damping_ratio,
                recovered(rw.recover_s),
                rw.post_shock_mode
            ));
            rows.push(rw);
            let sets: Vec<String> = base.iter().cloned().chain(extra.iter().cloned()).collect();
            let label = format!("{name} {rate} Hz");
            answers.extend(robust::answer(scene_path, &sets, &scene, &Summary::new(&scene, &r), &label, log, stop)?);
            if mode == ControlMode::Sampled {
                traces.push((format!("sampled {} kHz", rate / 1e3), r));
            }
        }
    }
    crate::table::write_with_header(&out.join("compare.csv"), COMPARE_HEADER, &rows)?;
    robust::write(out, &answers)?;
    plots(out, &traces, start, &continuous)?;
    let planned = 1 + rates.len() * modes.len();
    interrupted(stop, || format!("{} of {planned} configurations finished, written to compare.csv", rows.len()))?;
    Ok(rows)
}

/// Header of `compare.csv`.
pub const COMPARE_HEADER: &str = RateRow::HEADER;

/// The first [`WINDOW`] after the shock of one run, in ms and µm.
struct Window {
    t_ms: Vec<f64>,
    radius_um: Vec<f64>,
    x_um: Vec<f64>,
    y_um: Vec<f64>,
}

impl Window {
    /// Of a trace in the planar columns (one bearing plane's, [`crate::trace::Trace::plane`]).
    fn of(tr: &crate::trace::Trace, start: f64) -> Self {
        let idx: Vec<usize> = (0..tr.len()).filter(|&i| tr.t_s[i] >= start && tr.t_s[i] <= start + WINDOW).collect();
        Window {
            t_ms: idx.iter().map(|&i| (tr.t_s[i] - start) * 1e3).collect(),
            radius_um: idx.iter().map(|&i| tr.motion.dx_m[i].hypot(tr.motion.dy_m[i]) * 1e6).collect(),
            x_um: idx.iter().map(|&i| tr.motion.dx_m[i] * 1e6).collect(),
            y_um: idx.iter().map(|&i| tr.motion.dy_m[i] * 1e6).collect(),
        }
    }
}

fn plots(out: &Path, traces: &[(String, RunResult)], start: f64, scene: &Scene) -> anyhow::Result<()> {
    let (gap, name) = (gap_words(scene), &scene.name);
    let data: Vec<(String, Window)> =
        traces.iter().flat_map(|(l, r)| plane_traces(l, &r.trace)).map(|(l, t)| (l, Window::of(&t, start))).collect();
    let radius: Vec<Series> = data.iter().map(|(l, d)| Series { label: l, x: &d.t_ms, y: &d.radius_um }).collect();
    plot::lines(
        &out.join("compare_radius.png"),
        &format!("{name}: rotor radius, first {:.0} ms after the shock ({gap})", WINDOW * 1e3),
        "time after the shock (ms)",
        "radius (µm)",
        &radius,
        Scale::Linear,
    )?;
    let orbits: Vec<PointGroup> = data.iter().map(|(l, d)| PointGroup { label: l, x: &d.x_um, y: &d.y_um }).collect();
    plot::scatter(
        &out.join("compare_orbit.png"),
        &format!("{name}: orbits, first {:.0} ms after the shock", WINDOW * 1e3),
        "x (µm)",
        "y (µm)",
        &orbits,
        true,
    )?;
    Ok(())
}
