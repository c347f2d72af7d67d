//! `plant campbell`: the whirl modes of a scene's rotor on its continuous PD against spin
//! speed, the Campbell diagram, through the rotor seam ([`Rotor::linearised`]): the two-plane
//! rotor's four (the linearisation of docs/MODEL.md §10.4, [`plant_physics::two_plane::linear`])
//! or a flexible rotor's rigid-body and bending modes (§13.7, [`plant_physics::flex::linear`]);
//! and, for the two-plane rotor, the same frequencies recovered from simulated free decays of
//! the full model at a few speeds (a flexible rotor's bending modes lie far above what the
//! decays sample: its diagram is the linearisation alone, and the log says so).
//!
//! **Free decay.** The scene at the speed asked for, without unbalance or shock, the PD inside
//! the derivative, the races parked (no contact happens), started 10 µm off centre and tilted
//! by 30 µrad about y: a planar start excites each mode's forward and backward whirl alike.
//! The rotor's motion at its centre of mass `ζ = x + j y` and its tilt `l φ = l (a + j b)`
//! (`l` the half span) over 0.5 s, sampled at 1 kHz, are then fitted with damped complex
//! exponentials by the matrix pencil method ([`matrix_pencil`]): each gives a frequency with
//! its sign (the whirl) and a damping ratio, independently of the linearisation. Each linear
//! mode is matched with the fitted one of the same whirl nearest in frequency.
//!
//! Writes `campbell.csv` (speed, mode, whirl, frequency, damping ratio), `campbell.png` and
//! `decay.csv` (each decay mode against the linear one).

use crate::config::{load_scene, Rotor, Scene};
use crate::machine::Linearised;
use crate::plot;
use crate::run::{plane_gains, run, Outcome, Quiet};
use anyhow::Context;
use nalgebra::{Complex, DMatrix};
use plant_physics::flex::linear::ModeKind;
use plant_physics::two_plane::linear::{LinearRotor, Mode, Shape, Whirl};
use serde::{Serialize, Serializer};
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};

type C64 = Complex<f64>;

/// What a mode is, as `campbell.csv` writes it: `cylindrical`, `conical` (the rigid-body
/// modes), `bending_1`, `bending_2`, … (a flexible rotor's bending modes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ModeName(pub ModeKind);

impl ModeName {
    /// The name written.
    pub fn name(&self) -> String {
        match self.0 {
            ModeKind::Cylindrical => "cylindrical".into(),
            ModeKind::Conical => "conical".into(),
            ModeKind::Bending(n) => format!("bending_{n}"),
        }
    }
}

impl Serialize for ModeName {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.name())
    }
}

crate::table::table_row! {
/// One mode at one speed: a row of `campbell.csv`.
#[derive(Clone, Debug, Serialize)]
pub struct ModeRow {
    /// Spin speed (Hz).
    pub speed_hz: f64,
    /// `cylindrical`, `conical`, or `bending_<n>`.
    pub mode: ModeName,
    /// `forward` or `backward` (`mixed` for a mode whose nodes whirl each way).
    pub whirl: plant_physics::flex::Whirl,
    /// Damped natural frequency (Hz).
    pub frequency_hz: f64,
    /// Damping ratio.
    pub damping_ratio: f64,
}
}

crate::table::table_row! {
/// A mode of a free decay against the linearisation's: a row of `decay.csv`.
#[derive(Clone, Debug, Serialize)]
pub struct DecayRow {
    /// Spin speed (Hz).
    pub speed_hz: f64,
    /// `cylindrical` or `conical`.
    pub mode: Shape,
    /// `forward` or `backward`.
    pub whirl: Whirl,
    /// The linearisation's frequency (Hz).
    pub linear_hz: f64,
    /// The free decay's (Hz).
    pub decay_hz: f64,
    /// `(decay − linear) / linear`.
    pub error_rel: f64,
    /// The linearisation's damping ratio.
    pub linear_damping_ratio: f64,
    /// The free decay's.
    pub decay_damping_ratio: f64,
}
}

/// What `plant campbell` is asked.
pub struct Request<'a> {
    /// A two-plane scene file.
    pub scene: &'a Path,
    /// `--set` overrides.
    pub set: &'a [String],
    /// Output folder (default `runs/campbell-<scene name>`).
    pub out: Option<&'a Path>,
    /// Highest spin speed of the diagram (Hz).
    pub max_speed_hz: f64,
    /// Speeds of the diagram, 0 to `max_speed_hz`.
    pub points: usize,
    /// Speeds of the free decays (Hz).
    pub decay_speeds_hz: &'a [f64],
}

/// The linearised rotor of a two-plane scene with its continuous PD at each plane.
pub fn linear_rotor(scene: &Scene) -> anyhow::Result<LinearRotor> {
    let Rotor::TwoPlane(machine) = &scene.rotor else {
        return Err(crate::exit::BadArgument(format!(
            "{}: plant campbell needs a two-plane scene (rotor.model = \"two_plane\"); this one is {}",
            scene.name,
            scene.rotor.model().name()
        ))
        .into());
    };
    ideal_loop(scene)?;
    let gains = plane_gains(scene)?;
    Ok(LinearRotor::from_gains(machine, &[gains[0], gains[1]]))
}

/// The scene's rotor linearised on its continuous PD at each plane, through the rotor seam
/// ([`Rotor::linearised`]): the two-plane rotor's four whirl modes, or a flexible rotor's with
/// its bending modes.
pub fn linearised(scene: &Scene) -> anyhow::Result<Box<dyn Linearised>> {
    ideal_loop(scene)?;
    let gains = plane_gains(scene)?;
    scene.rotor.linearised(&gains).ok_or_else(|| {
        crate::exit::BadArgument(format!(
            "{}: plant campbell needs a two-plane scene (rotor.model = \"two_plane\") or a flexible one \
             (\"flexible\"); this one is {}",
            scene.name,
            scene.rotor.model().name()
        ))
        .into()
    })
}

/// Refuses a scene whose loop is not the ideal one the linearisation is.
fn ideal_loop(scene: &Scene) -> anyhow::Result<()> {
    // The linearisation is the rotor on the ideal loop: an amplifier's coil and current loop
    // and a sensor's filter would add states it does not have, and runout forces the free
    // decays at 1× and 2× the spin. Refused rather than drawn wrong; the range does not act
    // on motions about the centre smaller than it, and stays.
    let hw = &scene.hardware;
    let mut parts = Vec::new();
    if hw.amplified() {
        parts.push("amb.amplifier = true");
    }
    if hw.front_end.low_pass.is_some() {
        parts.push("sensor.bandwidth_hz > 0");
    }
    if !hw.front_end.runout.is_empty() {
        parts.push("sensor.runout");
    }
    if !parts.is_empty() {
        return Err(crate::exit::BadArgument(format!(
            "{}: plant campbell linearises the rotor on the ideal loop, without the amplifier's and the \
             sensor's states, and its free decays carry no runout; this scene has {} on: switch it off \
             (--set amb.amplifier=false --set sensor.bandwidth_hz=0 --set 'sensor.runout=[]') for the \
             ideal loop's diagram",
            scene.name,
            parts.join(", ")
        ))
        .into());
    }
    Ok(())
}

/// The diagram's rows: the modes at each speed (the two-plane rotor's four; a flexible rotor's
/// rigid-body and bending modes, ascending).
pub fn diagram(rotor: &dyn Linearised, speeds_hz: &[f64]) -> anyhow::Result<Vec<ModeRow>> {
    let mut rows = Vec::with_capacity(4 * speeds_hz.len());
    for &hz in speeds_hz {
        for m in rotor.whirl_modes(hz * TAU)? {
            rows.push(ModeRow {
                speed_hz: hz,
                mode: ModeName(m.kind),
                whirl: m.whirl,
                frequency_hz: m.frequency_hz,
                damping_ratio: m.damping_ratio,
            });
        }
    }
    Ok(rows)
}

/// A fitted damped complex exponential `e^{λt}`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fitted {
    /// λ (1/s).
    pub lambda: C64,
}

impl Fitted {
    /// Signed frequency `Im λ / 2π` (Hz): positive forward, negative backward.
    pub fn frequency_hz(&self) -> f64 {
        self.lambda.im / TAU
    }

    /// Damping ratio `−Re λ / |λ|`.
    pub fn damping_ratio(&self) -> f64 {
        -self.lambda.re / self.lambda.norm()
    }
}

/// Fits the channels `signals` (each sampled every `dt` s, all of one length) with the damped
/// complex exponentials they share, by the matrix pencil method (Hua & Sarkar): the stacked
/// Hankel matrices of the channels (pencil parameter a third of the length), their right
/// singular vectors above `rel_threshold` of the largest singular value (at most `max_order`),
/// and the eigenvalues `z_k = e^{λ_k dt}` of the shifted pencil `W₂ W₁⁺`.
pub fn matrix_pencil(signals: &[Vec<C64>], dt: f64, rel_threshold: f64, max_order: usize) -> Vec<Fitted> {
    let n = signals.iter().map(Vec::len).min().unwrap_or(0);
    if n < 8 || dt <= 0.0 {
        return Vec::new();
    }
    let l = n / 3;
    let rows = n - l;
    let mut y = DMatrix::<C64>::zeros(rows * signals.len(), l + 1);
    for (c, s) in signals.iter().enumerate() {
        for i in 0..rows {
            for j in 0..=l {
                y[(c * rows + i, j)] = s[i + j];
            }
        }
    }
    let svd = y.svd(false, true);
    let Some(v_t) = svd.v_t else { return Vec::new() };
    let top = svd.singular_values.iter().copied().fold(0.0, f64::max);
    let order = svd.singular_values.iter().filter(|s| **s > rel_threshold * top).count().min(max_order);
    if order == 0 {
        return Vec::new();
    }
    // The singular values come sorted, largest first.
    let w = v_t.rows(0, order);
    let (w1, w2) = (w.columns(0, l).into_owned(), w.columns(1, l).into_owned());
    let Ok(pinv) = w1.pseudo_inverse(1e-12) else { return Vec::new() };
    let pencil = w2 * pinv;
    let Some(z) = pencil.eigenvalues() else { return Vec::new() };
    z.iter().filter(|z| z.norm() > 0.0).map(|z| Fitted { lambda: z.ln() / dt }).collect()
}

/// The free decay of `scene` at `speed_hz` (module doc): the fitted modes, or why there are none.
pub fn free_decay(scene: &Scene, speed_hz: f64) -> anyhow::Result<Vec<Fitted>> {
    let Rotor::TwoPlane(machine) = &scene.rotor else { anyhow::bail!("a two-plane scene") };
    let mut sets: Vec<String> = [
        format!("rotor.speed_hz={speed_hz:?}"),
        "rotor.eccentricity_um=0.0".into(),
        "rotor.couple_unbalance_urad=0.0".into(),
        "controller.mode=\"continuous\"".into(),
        "touchdown.race_when_clear=\"parked\"".into(),
        "initial.unbalance_orbit=false".into(),
        "initial.rotor_x_um=10.0".into(),
        "initial.slope_x_urad=30.0".into(),
        "scene.duration_s=0.5".into(),
        "output.rate_hz=20000.0".into(),
        "output.plots=false".into(),
    ]
    .into();
    sets.extend((0..scene.shock_count()).map(|i| format!("shock[{i}].start_s=1000.0")));
    let decay = scene.reload(&sets)?;
    let r = run(&decay, &mut Quiet)?;
    anyhow::ensure!(
        r.run.outcome == Outcome::Completed,
        "the free decay at {speed_hz} Hz did not complete: {:?}",
        r.run.outcome
    );
    anyhow::ensure!(
        r.trace.loads.contact_force_n.iter().all(|f| *f == 0.0),
        "the free decay at {speed_hz} Hz touched a race: not a free decay"
    );
    let (za, zb) = (machine.planes[0].station, machine.planes[1].station);
    let half = 0.5 * (zb - za);
    let step = 20; // 20 kHz → 1 kHz
    let (mut zeta, mut tilt) = (Vec::new(), Vec::new());
    for rec in r.trace.records().step_by(step) {
        let b = rec.b.context("a two-plane trace")?;
        let phi = C64::new(b.tilt.slope_x_rad, b.tilt.slope_y_rad);
        let at_a = C64::new(rec.a.motion.dx_m, rec.a.motion.dy_m);
        zeta.push(at_a - phi * za);
        tilt.push(phi * half);
    }
    let dt = decay.output_interval * step as f64;
    Ok(matrix_pencil(&[zeta, tilt], dt, 1e-5, 8))
}

/// Each linear mode against the fitted mode of the same whirl nearest in frequency.
pub fn match_modes(speed_hz: f64, linear: &[Mode; 4], fitted: &[Fitted]) -> Vec<DecayRow> {
    linear
        .iter()
        .map(|m| {
            let sign = if m.whirl == Whirl::Forward { 1.0 } else { -1.0 };
            let nearest = fitted.iter().filter(|f| f.frequency_hz() * sign > 0.0).min_by(|a, b| {
                let d = |f: &Fitted| (f.frequency_hz().abs() - m.frequency_hz).abs();
                d(a).total_cmp(&d(b))
            });
            let (decay_hz, decay_damping) =
                nearest.map_or((f64::NAN, f64::NAN), |f| (f.frequency_hz().abs(), f.damping_ratio()));
            DecayRow {
                speed_hz,
                mode: m.shape,
                whirl: m.whirl,
                linear_hz: m.frequency_hz,
                decay_hz,
                error_rel: (decay_hz - m.frequency_hz) / m.frequency_hz,
                linear_damping_ratio: m.damping_ratio,
                decay_damping_ratio: decay_damping,
            }
        })
        .collect()
}

/// Header of `campbell.csv`.
pub const CAMPBELL_HEADER: &str = ModeRow::HEADER;
/// Header of `decay.csv`.
pub const DECAY_HEADER: &str = DecayRow::HEADER;

/// `plant campbell` (module doc); returns the files written.
pub fn command(req: &Request, log: &mut dyn FnMut(&str)) -> anyhow::Result<Vec<PathBuf>> {
    let scene = load_scene(req.scene, req.set)?;
    let rotor = linearised(&scene)?;
    if !(req.max_speed_hz.is_finite() && req.max_speed_hz >= 0.0 && req.max_speed_hz <= 1e5) {
        return Err(crate::exit::BadArgument(format!(
            "--max-speed-hz {}: must be between 0 and 1e5 Hz",
            req.max_speed_hz
        ))
        .into());
    }
    if !(2..=10_000).contains(&req.points) {
        return Err(crate::exit::BadArgument(format!("--points {}: must be between 2 and 10000", req.points)).into());
    }
    if let Some(bad) = req.decay_speeds_hz.iter().find(|s| !(s.is_finite() && **s >= 0.0 && **s <= 1e5)) {
        return Err(
            crate::exit::BadArgument(format!("--decay-speeds-hz {bad}: each must be between 0 and 1e5 Hz")).into()
        );
    }
    let out = crate::output::out_dir(req.out, &format!("campbell-{}", scene.name));
    let _claim = crate::claim::claim(&out, true)?;
    crate::outfile::clear_earlier(&out, FILES)?;
    let speeds: Vec<f64> = (0..req.points).map(|i| req.max_speed_hz * i as f64 / (req.points - 1) as f64).collect();
    let rows = diagram(rotor.as_ref(), &speeds)?;
    let csv = out.join("campbell.csv");
    crate::table::write_with_header(&csv, CAMPBELL_HEADER, &rows)?;
    let png = out.join("campbell.png");
    chart(&png, &scene.name, &rows)?;
    let mut written = vec![csv, png];
    // The free decays check the rigid rotor's four modes (a flexible rotor's bending modes lie
    // far above what the decays sample).
    let rigid = linear_rotor(&scene).ok();
    if !req.decay_speeds_hz.is_empty() && rigid.is_none() {
        log(&format!(
            "{}: no free decays: they check the two-plane rotor's linearisation; this rotor is {}",
            scene.name,
            scene.rotor.model().name()
        ));
    }
    if let (false, Some(rigid)) = (req.decay_speeds_hz.is_empty(), rigid) {
        let mut decay_rows = Vec::new();
        for &hz in req.decay_speeds_hz {
            let fitted = free_decay(&scene, hz)?;
            let linear = rigid.modes(hz * TAU)?;
            for row in match_modes(hz, &linear, &fitted) {
                log(&format!(
                    "{hz:>6} Hz {:<8} {:<11} linear {:>8.3} Hz (ξ {:.4})  free decay {:>8.3} Hz (ξ {:.4})  {:+.2e}",
                    crate::summary::snake_name(&row.whirl),
                    crate::summary::snake_name(&row.mode),
                    row.linear_hz,
                    row.linear_damping_ratio,
                    row.decay_hz,
                    row.decay_damping_ratio,
                    row.error_rel
                ));
                decay_rows.push(row);
            }
        }
        let decay = out.join("decay.csv");
        crate::table::write_with_header(&decay, DECAY_HEADER, &decay_rows)?;
        written.push(decay);
    }
    Ok(written)
}

/// The files `plant campbell` writes into its folder (`decay.csv` with `--decay-speeds-hz`
/// only): an earlier diagram's are removed first, so that no free decay of another call is
/// left beside this one's diagram.
pub const FILES: &[&str] = &["campbell.csv", "campbell.png", "decay.csv"];

/// `campbell.png`: each mode's frequency against the spin speed as points (a name per speed
/// comes from the mode's shape there, and lines would jump where modes cross), the rigid-body
/// modes on a panel of their own beside every mode when the rotor bends, and the synchronous
/// line `f = speed` where the unbalance excites a mode ([`plot::campbell`]).
fn chart(path: &Path, name: &str, rows: &[ModeRow]) -> Result<(), plot::PlotError> {
    use plant_physics::flex::Whirl as W;
    // One set of points per (whirl, mode), the rigid rotor's four first (forward and backward
    // cylindrical, then conical), then each bending mode's.
    let mut modes: Vec<(W, ModeName)> = Vec::new();
    for r in rows {
        if !modes.contains(&(r.whirl, r.mode)) {
            modes.push((r.whirl, r.mode));
        }
    }
    let kind = |m: &ModeName| match m.0 {
        ModeKind::Cylindrical => 0,
        ModeKind::Conical => 1,
        ModeKind::Bending(n) => 1 + n as usize,
    };
    let whirl = |w: &W| match w {
        W::Forward => 0,
        W::Backward => 1,
        W::Mixed => 2,
    };
    modes.sort_by_key(|m| (kind(&m.1), whirl(&m.0)));
    let points: Vec<(Vec<f64>, Vec<f64>)> = modes
        .iter()
        .map(|(w, s)| {
            rows.iter().filter(|r| r.whirl == *w && r.mode == *s).map(|r| (r.speed_hz, r.frequency_hz)).unzip()
        })
        .collect();
    // A colour per mode shape, a marker per whirl (forward ● filled, backward △ and mixed □ as
    // outlines); past the palette's ten shapes the colours come round again with ◆ and □.
    let shape = |k: usize, w: &W| {
        use plot::Shape::*;
        match (k / 10 % 2, w) {
            (0, W::Forward) => Circle,
            (0, W::Backward) => Triangle,
            (1, W::Forward) => Diamond,
            _ => Square,
        }
    };
    let series: Vec<plot::ModePoints> = modes
        .iter()
        .zip(&points)
        .map(|((w, s), (x, y))| plot::ModePoints {
            label: format!("{} {}", crate::summary::snake_name(w), s.name().replace('_', " ")),
            colour: plot::colour(kind(s)),
            shape: shape(kind(s), w),
            open: *w != W::Forward,
            x,
            y,
            rigid: kind(s) < 2,
        })
        .collect();
    plot::campbell(path, &format!("{name} — Campbell diagram, continuous PD (linearised)"), &series)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Four damped exponentials, forward and backward, in two channels: the pencil finds their
    /// frequencies and damping ratios.
    #[test]
    fn matrix_pencil_recovers_damped_whirls() {
        let modes = [(47.0, 0.01), (-47.0, 0.01), (70.4, 0.02), (-56.3, 0.015)];
        let lambda = |f: f64, z: f64| {
            let w = f.abs() * TAU;
            C64::new(-z * w / (1.0 - z * z).sqrt(), f.signum() * w)
        };
        let dt = 1.5e-3;
        let sig = |amps: [f64; 4]| -> Vec<C64> {
            (0..240)
                .map(|k| {
                    let t = k as f64 * dt;
                    modes.iter().zip(amps).map(|((f, z), a)| (lambda(*f, *z) * t).exp() * a).sum()
                })
                .collect()
        };
        let fitted = matrix_pencil(&[sig([1.0, 0.8, 0.1, 0.05]), sig([0.02, 0.03, 0.6, 0.9])], dt, 1e-8, 8);
        assert_eq!(fitted.len(), 4, "{fitted:?}");
        for (f, z) in modes {
            let best = fitted
                .iter()
                .min_by(|a, b| (a.frequency_hz() - f).abs().total_cmp(&(b.frequency_hz() - f).abs()))
                .unwrap();
            assert!((best.frequency_hz() - f).abs() < 1e-6 * f.abs(), "{f} Hz: {best:?}");
            let zr = best.damping_ratio();
            assert!((zr - z).abs() < 1e-6, "{f} Hz: damping {zr} against {z}");
        }
    }
}
