//! A comparison of control laws on one scene (`plant compare --laws`): `laws.csv`
//! ([`LawRow`]) and the laws' charts.

use super::*;

crate::table::table_row! {
/// One law of a law comparison (`plant compare --laws`): a row of `laws.csv`.
#[derive(Clone, Debug, Serialize)]
pub struct LawRow {
    /// Law name.
    pub law: String,
    /// Controller mode the scene ran in.
    pub mode: ControlMode,
    /// How the run ended.
    pub status: Status,
    /// Time from the shock start to the last rotor – race contact (s); NaN if still touching at the end.
    #[serde(with = "sci")]
    pub recovery_s: f64,
    /// Post-shock mode.
    pub post_shock_mode: MotionMode,
    /// Peak rotor – race force (N).
    #[serde(with = "sci")]
    pub max_contact_force_n: f64,
    /// Time in contact (s).
    #[serde(with = "sci")]
    pub contact_time_s: f64,
    /// Contact fraction over the last 200 revolutions.
    #[serde(with = "sci")]
    pub steady_contact_fraction: f64,
    /// Whirl frequency of the steady response (Hz, negative backward).
    #[serde(with = "sci")]
    pub whirl_hz: f64,
}
}

/// Header of `laws.csv`.
pub const LAWS_HEADER: &str = LawRow::HEADER;

/// Runs the scene once per law (in the scene's controller mode, so a co-simulation scene runs
/// the controller process), and writes `laws.csv` and overlaid plots of the whole run. The
/// scene's `[controller.params]` go to its own law only; the other laws run with their
/// default parameters.
pub fn compare_laws(
    scene_path: &Path,
    sets: &[String],
    laws: &[String],
    out: &Path,
    log: &mut dyn FnMut(&str),
    stop: &AtomicBool,
) -> anyhow::Result<Vec<LawRow>> {
    let base = prepare(out, sets)?;
    let mut rows = Vec::new();
    let mut runs: Vec<(String, RunResult)> = Vec::new();
    let mut probe = None;
    let mut answers = Vec::new();
    let own = with(scene_path, &base, &[])?.controller.law;
    for law in laws {
        // The scene's `[controller.params]` belong to its own law; another law runs on its defaults.
        let mut extra = vec![format!("controller.law=\"{law}\"")];
        if *law != own {
            extra.push("controller.params={}".to_string());
        }
        let scene = with(scene_path, &base, &extra)?;
        let Some(r) = finished(&scene, stop)? else { break };
        let s = Summary::new(&scene, &r);
        let row = LawRow {
            law: law.clone(),
            mode: scene.controller.mode,
            status: s.status,
            recovery_s: s.recovery_s.unwrap_or(f64::NAN),
            post_shock_mode: s.analysis.post_shock_mode,
            max_contact_force_n: s.max_contact_force_n.unwrap_or(f64::NAN),
            contact_time_s: s.contact_time_s,
            steady_contact_fraction: s.analysis.steady_contact_fraction,
            whirl_hz: s.analysis.whirl_hz,
        };
        log(&format!(
            "{law} ({}): {}, {}, {}, peak force {:.0} N, {:.4} s in contact, whirl {:.1} Hz",
            snake_name(&row.mode),
            row.status,
            recovered(row.recovery_s),
            row.post_shock_mode,
            row.max_contact_force_n,
            row.contact_time_s,
            row.whirl_hz
        ));
        rows.push(row);
        let law_sets: Vec<String> = base.iter().cloned().chain(extra.iter().cloned()).collect();
        answers.extend(robust::answer(scene_path, &law_sets, &scene, &s, law, log, stop)?);
        runs.push((law.clone(), r));
        probe = Some(scene);
    }
    if rows.is_empty() {
        return Err(nothing_finished());
    }
    crate::table::write_with_header(&out.join("laws.csv"), LAWS_HEADER, &rows)?;
    robust::write(out, &answers)?;
    if let Some(scene) = probe {
        law_plots(out, &runs, &scene)?;
    }
    interrupted(stop, || format!("{} of {} laws finished, written to laws.csv", rows.len(), laws.len()))?;
    Ok(rows)
}

fn law_plots(out: &Path, runs: &[(String, RunResult)], scene: &Scene) -> anyhow::Result<()> {
    let name = &scene.name;
    let gap = gap_words(scene);
    // Each plane's radius and coil current of each law's run.
    let planes: Vec<(String, crate::trace::Trace)> = runs.iter().flat_map(|(l, r)| plane_traces(l, &r.trace)).collect();
    let radius: Vec<Vec<f64>> = planes.iter().map(|(_, t)| t.radius().iter().map(|v| v * 1e6).collect()).collect();
    let current: Vec<Vec<f64>> = planes
        .iter()
        .map(|(_, t)| t.loads.ix_a.iter().zip(&t.loads.iy_a).map(|(x, y)| x.hypot(*y)).collect())
        .collect();
    let series = |ys: &[Vec<f64>]| -> Vec<(String, Vec<f64>, Vec<f64>)> {
        planes.iter().zip(ys).map(|((l, t), y)| (l.clone(), t.t_s.clone(), y.clone())).collect()
    };
    for (file, title, ylabel, data) in [
        ("laws_radius.png", format!("{name}: rotor radius by law ({gap})"), "radius (µm)", &radius),
        ("laws_current.png", format!("{name}: coil current magnitude by law"), "|i| (A)", &current),
    ] {
        let d = series(data);
        let s: Vec<Series> = d.iter().map(|(l, x, y)| Series { label: l, x, y }).collect();
        plot::lines(&out.join(file), &title, "time (s)", ylabel, &s, Scale::Linear)?;
    }
    let start = scene.first_shock_start();
    let orbits: Vec<(String, Vec<f64>, Vec<f64>)> = planes
        .iter()
        .map(|(l, tr)| {
            let idx: Vec<usize> = (0..tr.len()).filter(|&i| tr.t_s[i] >= start).collect();
            (
                l.clone(),
                idx.iter().map(|&i| tr.motion.dx_m[i] * 1e6).collect(),
                idx.iter().map(|&i| tr.motion.dy_m[i] * 1e6).collect(),
            )
        })
        .collect();
    let groups: Vec<PointGroup> = orbits.iter().map(|(l, x, y)| PointGroup { label: l, x, y }).collect();
    plot::scatter(
        &out.join("laws_orbit.png"),
        &format!("{name}: orbits after the shock, by law"),
        "x (µm)",
        "y (µm)",
        &groups,
        true,
    )?;
    Ok(())
}
