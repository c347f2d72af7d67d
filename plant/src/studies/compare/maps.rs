//! Stability maps of the sampled law (`plant compare --maps`): the damping measured over
//! rate and damping, and over rate and delay; `stability_map.csv` ([`MapPoint`]).

use super::*;

crate::table::table_row! {
/// One point of a stability map: a row of `stability_map.csv`.
#[derive(Clone, Debug, Serialize)]
pub struct MapPoint {
    /// `rate_damping` or `rate_delay`.
    pub map: &'static str,
    /// Controller rate (Hz).
    #[serde(with = "plain")]
    pub rate_hz: f64,
    /// Design damping ratio or delay in samples.
    #[serde(with = "plain")]
    pub value: f64,
    /// Damping ratio measured on the free decay (NaN if it diverged).
    #[serde(with = "sci")]
    pub damping_measured: f64,
    /// `unstable`, or `stable (<post-shock mode>)`.
    pub class: String,
}
}

/// Header of `stability_map.csv`.
pub const MAP_HEADER: &str = MapPoint::HEADER;

/// Stability maps of the sampled law: rate × design damping ratio and rate × delay (samples).
/// A point is unstable when its free decay grows (or diverges); a stable point is labelled
/// with the post-shock mode of the scene run at that setting.
pub fn stability_maps(
    scene_path: &Path,
    sets: &[String],
    rates: &[f64],
    out: &Path,
    log: &mut dyn FnMut(&str),
    stop: &AtomicBool,
) -> anyhow::Result<Vec<MapPoint>> {
    let base = prepare(out, sets)?;
    let probe = with(scene_path, &base, &[])?;
    let shocks = probe.shock_count();
    let mut points = Vec::new();
    let grids: [(&'static str, &'static str, Vec<f64>); 2] = [
        ("rate_damping", "controller.damping_ratio", vec![0.005, 0.01, 0.02, 0.03, 0.05, 0.1]),
        ("rate_delay", "controller.delay_samples", vec![0.0, 1.0, 2.0, 3.0]),
    ];
    let planned: usize = grids.iter().map(|g| g.2.len() * rates.len()).sum();
    'maps: for (map, key, values) in grids {
        for &rate in rates {
            for &v in &values {
                let value = if key.ends_with("delay_samples") { format!("{}", v as u32) } else { format!("{v:?}") };
                let extra = vec![
                    "controller.mode=\"sampled\"".to_string(),
                    format!("controller.rate_hz={rate:?}"),
                    format!("{key}={value}"),
                ];
                let Some((decay_xi, touched, completed)) = free_decay(scene_path, &base, &extra, shocks, stop)? else {
                    break 'maps;
                };
                let xi = if completed || touched { decay_xi } else { f64::NAN };
                let class = if xi.is_nan() || xi <= 0.0 || touched {
                    "unstable".to_string()
                } else {
                    let scene = with(scene_path, &base, &extra)?;
                    let Some(r) = finished(&scene, stop)? else { break 'maps };
                    let s = Summary::new(&scene, &r);
                    if r.run.outcome == Outcome::Completed {
                        format!("stable ({})", snake_name(&s.analysis.post_shock_mode))
                    } else {
                        "stable (diverged after the shock)".to_string()
                    }
                };
                log(&format!("{map}: {rate} Hz, {key} = {value}: measured damping {xi:.4}, {class}"));
                points.push(MapPoint { map, rate_hz: rate, value: v, damping_measured: xi, class });
            }
        }
    }
    crate::table::write_with_header(&out.join("stability_map.csv"), MAP_HEADER, &points)?;
    for (map, ylabel) in [("rate_damping", "design damping ratio ξ_e"), ("rate_delay", "delay (samples)")] {
        let mut classes: Vec<String> = points.iter().filter(|p| p.map == map).map(|p| p.class.clone()).collect();
        classes.sort();
        classes.dedup();
        let groups_data: Vec<(String, Vec<f64>, Vec<f64>)> = classes
            .iter()
            .map(|c| {
                let sel: Vec<&MapPoint> = points.iter().filter(|p| p.map == map && &p.class == c).collect();
                (c.clone(), sel.iter().map(|p| p.rate_hz / 1e3).collect(), sel.iter().map(|p| p.value).collect())
            })
            .collect();
        let groups: Vec<PointGroup> =
            groups_data.iter().map(|g| PointGroup { label: &g.0, x: &g.1, y: &g.2 }).collect();
        plot::scatter(
            &out.join(format!("stability_{map}.png")),
            &format!("{}: sampled {} — stability by rate and {}", probe.name, probe.controller.law, ylabel),
            "controller rate (kHz)",
            ylabel,
            &groups,
            false,
        )
        .or_else(|e| match e {
            // A map interrupted before its first point has nothing to draw.
            plot::PlotError::NoData { .. } if stop.load(Ordering::Relaxed) => Ok(()),
            e => Err(e),
        })?;
    }
    interrupted(stop, || format!("{} of {planned} map points finished, written to stability_map.csv", points.len()))?;
    Ok(points)
}
