//! `plant linear`: the plant of a scene linearised about its levitated state at a spin speed,
//! written for a control engineer's tools (python-control, MATLAB, numpy): from each axis'
//! current command (A) to each axis' sensor signal (V), as a continuous state-space system
//! ([`model`]) and as the discrete system the digital controller sees (zero-order hold at the
//! controller's rate, its command delay as states: [`discrete`]); `linear.json`,
//! `linear.npz` and `linear.mat` ([`files`]; docs/guide/linear.md). The law's linear form on it ([`law`]) gives
//! the closed loop's sensitivity, the very one `plant assess`'s closed forms draw, and each
//! axis' gain and phase margins ([`margins`]), written into `linear.json` beside the law.

pub mod discrete;
pub mod files;
pub mod law;
pub mod margins;
pub mod model;

use crate::argument::BadArgument;
use crate::config::load_scene;
use anyhow::Context;
use std::path::{Path, PathBuf};

/// The band the margins are looked for in (Hz): from near DC (a PD's open loop is real there)
/// to 20 kHz (a sampled law's to just below its Nyquist frequency).
pub const MARGIN_BAND_HZ: (f64, f64) = (0.01, 2e4);

/// What `plant linear` is asked.
pub struct Request<'a> {
    /// The scene file.
    pub scene: &'a Path,
    /// `--set` overrides.
    pub set: &'a [String],
    /// Spin speed (Hz); `None`: the scene's `rotor.speed_hz`.
    pub speed_hz: Option<f64>,
    /// Output folder (default `runs/linear-<scene name>`).
    pub out: Option<&'a Path>,
}

/// The model of a request, computed whole before anything is written.
pub struct Built {
    /// The continuous plant.
    pub plant: model::LinearPlant,
    /// The discrete system and its states.
    pub discrete: (model::System, Vec<model::Signal>),
    /// Its period (s).
    pub period: f64,
    /// Command delay (ticks).
    pub delay: u32,
}

/// The linear model of `scene` at `speed_hz` (Hz): bad input named.
pub fn build(scene: &crate::config::Scene, speed_hz: f64) -> anyhow::Result<Built> {
    let plant = model::continuous(scene, speed_hz).map_err(|e| BadArgument(e.to_string()))?;
    let (period, delay) = (scene.controller.period, scene.controller.delay_samples);
    let discrete = discrete::zoh(&plant, period, delay);
    let finite = |m: &nalgebra::DMatrix<f64>| m.iter().all(|v| v.is_finite());
    for (what, sys) in [("continuous", &plant.system), ("discrete", &discrete.0)] {
        if ![&sys.a, &sys.b, &sys.c, &sys.d].into_iter().all(finite) {
            let e = model::LinearError::NotFinite { scene: scene.name.clone(), speed_hz, what };
            return Err(BadArgument(e.to_string()).into());
        }
    }
    Ok(Built { plant, discrete, period, delay })
}

/// Refuses an output folder that is a file or a link (nothing is written through a link).
fn check_out(dir: &Path) -> anyhow::Result<()> {
    match std::fs::symlink_metadata(dir) {
        Ok(m) if m.file_type().is_symlink() => Err(BadArgument(format!(
            "--out {}: a symbolic link; give a folder (the files are not written through a link)",
            dir.display()
        ))
        .into()),
        Ok(m) if !m.is_dir() => {
            Err(BadArgument(format!("--out {}: a file, not a folder; give a folder", dir.display())).into())
        }
        _ => Ok(()),
    }
}

/// Runs `plant linear`: the files written.
pub fn command(req: &Request<'_>) -> anyhow::Result<Vec<PathBuf>> {
    let scene = load_scene(req.scene, req.set)?;
    let speed_hz = req.speed_hz.unwrap_or_else(|| {
        // The scene holds rad/s: `500 Hz` comes back as 499.99999999999994; said as given.
        let hz = scene.rotor.speed() / std::f64::consts::TAU;
        let round = (hz * 1e6).round() / 1e6;
        if (round - hz).abs() <= 1e-12 * hz.abs() {
            round
        } else {
            hz
        }
    });
    let built = build(&scene, speed_hz)?;
    let dir =
        req.out.map(Path::to_path_buf).unwrap_or_else(|| PathBuf::from("runs").join(format!("linear-{}", scene.name)));
    check_out(&dir)?;
    if let Some(file) = dir.ancestors().skip(1).find(|d| std::fs::metadata(d).is_ok_and(|m| !m.is_dir())) {
        return Err(BadArgument(format!(
            "--out {}: {} is a file, not a folder; give a folder",
            dir.display(),
            file.display()
        ))
        .into());
    }
    let law = law::of(&scene);
    let margins = law
        .as_ref()
        .map(|l| margins::margins(l, &built.plant.system, &built.discrete.0, MARGIN_BAND_HZ.0, MARGIN_BAND_HZ.1))
        .unwrap_or_default();
    let export = files::Export {
        plant: &built.plant,
        discrete: &built.discrete.0,
        discrete_states: &built.discrete.1,
        period: built.period,
        delay: built.delay,
        // In `controller.mode = "continuous"` the law is the continuous PD whatever
        // `controller.law` names.
        law: law.as_ref().map(|l| match l {
            law::LinearLaw::Continuous(_) => ("continuous_pd", l),
            law::LinearLaw::Sampled { .. } | law::LinearLaw::StateSpace { .. } => (scene.controller.law.as_str(), l),
        }),
        margins: &margins,
    };
    let json = files::json(&export);
    let npz = files::npz(&export).context("packing linear.npz")?;
    let mat = files::mat(&export).context("packing linear.mat")?;
    let _claim = crate::claim::claim(&dir, true)?;
    let mut written = Vec::new();
    for (name, bytes) in [("linear.json", json), ("linear.npz", npz), ("linear.mat", mat)] {
        let path = dir.join(name);
        crate::outfile::write(&path, &bytes).with_context(|| format!("writing {}", path.display()))?;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
pub(crate) mod tests;
