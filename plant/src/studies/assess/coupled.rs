//! The closed form of a rotor whose axes' loops couple through the rotor itself: the flexible
//! rotor ([`plant_physics::flex::linear`], through the rotor seam's
//! [`crate::config::Rotor::open_loop`]). Each axis' sensitivity is the diagonal entry of
//! `S = (I − L)⁻¹` with the loops of the four axes closed, at each speed the measurement runs:
//! the continuous PD on the continuous open loop, or the registry's law (its
//! [`controller::ControlLaw::linear`]: a PD behind an optional notch) sampled with its delay on
//! the open loop discretised under a zero-order hold. Stability from the closed loop's poles
//! (real parts, continuous; moduli, sampled), the peaks of `|S|` from a fine log grid refined by
//! golden-section search: the largest, and each local peak (a bending mode's among them).

use super::sensitivity::{self, Settings};
use crate::config::Scene;
use crate::linear::law::LinearLaw;
use nalgebra::{Complex, DMatrix};
use plant_physics::flex::linear::{AxisLaw, OpenLoop, PlanePd, Response, SampledLoop};
use serde::Serialize;
use std::f64::consts::TAU;

/// One axis' closed form at one speed.
#[derive(Clone, Debug, Serialize)]
pub struct AxisClosedForm {
    /// Axis name.
    pub axis: String,
    /// Rotor speed (Hz).
    pub speed_hz: f64,
    /// The closed loop (all axes) is stable.
    pub stable: bool,
    /// Its least stable pole: the largest real part (1/s) of the continuous loop's, the largest
    /// modulus of the sampled loop's.
    pub largest_pole: f64,
    /// Peak frequency (Hz), stable loops only.
    pub f_hz: Option<f64>,
    /// Peak `|S|`.
    pub s_abs: Option<f64>,
    /// In dB.
    pub s_db: Option<f64>,
    /// Zone (`unstable` for an unstable loop).
    pub zone: String,
    /// Every local peak of `|S|` above 0 dB: `(f_hz, dB)`, ascending in frequency.
    pub peaks: Vec<(f64, f64)>,
    /// The largest difference (dB) between the measured `|S|` of this axis at this speed and
    /// the closed form's at the measured frequencies, where both exist.
    pub measured_difference_db: Option<f64>,
    /// `|S|` (dB) on a log grid, for the chart.
    pub curve: Vec<(f64, f64)>,
}

/// The loop's law, continuous or sampled.
enum Law {
    Continuous([PlanePd; 2]),
    Sampled(SampledLoop),
}

/// The scene's law as a linear loop: the continuous PD, or the registry's law where it is a PD
/// behind an optional filter (a command is a black box: `None`), as [`crate::linear::law::of`]
/// reads it (one entry per axis, x then y of each plane), for the two-plane loop.
fn law_of(scene: &Scene) -> Option<Law> {
    if scene.plane_designs().len() != 2 {
        return None;
    }
    match crate::linear::law::of(scene)? {
        LinearLaw::Continuous(pds) => Some(Law::Continuous([*pds.first()?, *pds.get(2)?])),
        LinearLaw::Sampled { laws, period } => {
            let laws: [AxisLaw; 4] = laws.try_into().ok()?;
            Some(Law::Sampled(SampledLoop { laws, period, delay: scene.controller.delay_samples }))
        }
        LinearLaw::StateSpace { .. } => None,
    }
}

/// The closed form of every axis at each speed in `speeds_hz`, for a scene whose rotor gives
/// its whole open loop (the flexible rotor) and whose law is linear around levitation; `None`
/// otherwise.
pub fn closed_form_axes(scene: &Scene, settings: &Settings, speeds_hz: &[f64]) -> Option<Vec<AxisClosedForm>> {
    let open = scene.rotor.open_loop()?;
    let law = law_of(scene)?;
    every_axis(&super::axis_names(scene), speeds_hz, settings, |speed_hz| {
        let (response, largest_pole, stable, f_hi) = loop_at(&open, &law, speed_hz * TAU, settings);
        let law = &law;
        let s_at = move |f: f64| match law {
            Law::Continuous(pd) => response.sensitivity_continuous(pd, f),
            Law::Sampled(lp) => response.sensitivity(lp, f),
        };
        Some((stable, largest_pole, f_hi, s_at))
    })
}

/// The closed forms of every axis (`names`) at each distinct speed of `speeds_hz` (Hz), from
/// `at(speed_hz)`: the loop's stability, its largest pole, the band's top (Hz) and its `S` (all
/// axes) at a frequency (Hz); `S` once per frequency of the grid, every axis from it. `None`
/// where `at` has no loop at a speed.
pub(super) fn every_axis<S: Fn(f64) -> DMatrix<Complex<f64>>>(
    names: &[&str],
    speeds_hz: &[f64],
    settings: &Settings,
    mut at: impl FnMut(f64) -> Option<(bool, f64, f64, S)>,
) -> Option<Vec<AxisClosedForm>> {
    let mut out = Vec::new();
    let mut seen: Vec<f64> = Vec::new();
    for &speed_hz in speeds_hz {
        if seen.contains(&speed_hz) {
            continue;
        }
        seen.push(speed_hz);
        let (stable, largest_pole, f_hi, s_at) = at(speed_hz)?;
        let grid: Vec<f64> =
            if stable { sensitivity::log_grid(settings.f_min_hz, f_hi, GRID).into() } else { Vec::new() };
        let matrices: Vec<_> = grid.iter().map(|f| s_at(*f)).collect();
        for (k, name) in names.iter().enumerate() {
            let s_kk = |f: f64| s_at(f)[(k, k)].norm();
            let values: Vec<f64> = matrices.iter().map(|m| m[(k, k)].norm()).collect();
            out.push(axis_form(name, speed_hz, stable, largest_pole, &grid, &values, &s_kk));
        }
    }
    Some(out)
}

/// The closed form's `S` (all axes) at spin speed `speed_hz` (Hz) and frequency `f_hz` (Hz),
/// `None` where [`closed_form_axes`] has none: what `plant linear`'s export is checked against.
pub fn sensitivity_at(scene: &Scene, speed_hz: f64, f_hz: f64) -> Option<nalgebra::DMatrix<nalgebra::Complex<f64>>> {
    let open = scene.rotor.open_loop()?;
    Some(match law_of(scene)? {
        Law::Continuous(pd) => open.continuous(speed_hz * TAU).sensitivity_continuous(&pd, f_hz),
        Law::Sampled(lp) => open.discretise(speed_hz * TAU, lp.period).sensitivity(&lp, f_hz),
    })
}

/// The open loop at `speed` (rad/s) as the law needs it, the least stable pole, stability and
/// the highest frequency of the band.
fn loop_at(open: &OpenLoop, law: &Law, speed: f64, settings: &Settings) -> (Response, f64, bool, f64) {
    match law {
        Law::Continuous(pd) => {
            let abscissa = open.abscissa_continuous(pd, speed);
            (open.continuous(speed), abscissa, abscissa < 0.0, settings.f_max_hz)
        }
        Law::Sampled(lp) => {
            let d = open.discretise(speed, lp.period);
            let radius = d.spectral_radius(lp);
            (d, radius, radius < 1.0, settings.f_max_hz.min(0.45 / lp.period))
        }
    }
}

/// One axis' figures from its `|S|` as a function of frequency.
/// Frequencies of the closed form's log grid (its peaks are then refined).
pub(super) const GRID: usize = 1500;

pub(super) fn axis_form(
    name: &str,
    speed_hz: f64,
    stable: bool,
    largest_pole: f64,
    grid: &[f64],
    values: &[f64],
    s: &dyn Fn(f64) -> f64,
) -> AxisClosedForm {
    let db = |v: f64| 20.0 * v.log10();
    let curve: Vec<(f64, f64)> = grid.iter().zip(values).step_by(3).map(|(f, v)| (*f, db(*v))).collect();
    let mut form = AxisClosedForm {
        axis: name.to_string(),
        speed_hz,
        stable,
        largest_pole,
        f_hz: None,
        s_abs: None,
        s_db: None,
        zone: "unstable".into(),
        peaks: Vec::new(),
        measured_difference_db: None,
        curve,
    };
    if !stable {
        return form;
    }
    // Each local maximum of the grid, refined between its neighbours (golden section in ln f).
    for i in 1..grid.len().saturating_sub(1) {
        if values[i] > values[i - 1] && values[i] >= values[i + 1] && values[i] > 1.0 {
            let (mut lo, mut hi) = (grid[i - 1].ln(), grid[i + 1].ln());
            let g = (5f64.sqrt() - 1.0) / 2.0;
            for _ in 0..60 {
                let (c, d) = (hi - g * (hi - lo), lo + g * (hi - lo));
                if s(c.exp()) > s(d.exp()) {
                    hi = d;
                } else {
                    lo = c;
                }
            }
            let f = (0.5 * (lo + hi)).exp();
            form.peaks.push((f, db(s(f))));
        }
    }
    let top = form.peaks.iter().copied().max_by(|a, b| a.1.total_cmp(&b.1)).or_else(|| {
        let i = (0..values.len()).max_by(|&a, &b| values[a].total_cmp(&values[b]))?;
        Some((grid[i], db(values[i])))
    });
    if let Some((f, d)) = top {
        let abs = 10f64.powf(d / 20.0);
        form.f_hz = Some(f);
        form.s_abs = Some(abs);
        form.s_db = Some(d);
        form.zone = sensitivity::zone(abs).into();
    }
    form
}

/// Fills each closed form's `measured_difference_db` from the measured axes.
pub fn compare(forms: &mut [AxisClosedForm], measured: &[sensitivity::AxisResult], scene: &Scene) {
    let Some(open) = scene.rotor.open_loop() else { return };
    let Some(law) = law_of(scene) else { return };
    for form in forms.iter_mut() {
        let Some(axis) = measured.iter().find(|a| a.axis == form.axis && a.speed_hz == form.speed_hz) else {
            continue;
        };
        if axis.points.is_empty() || !form.stable {
            continue;
        }
        let k = super::axis_names(scene).iter().position(|n| *n == form.axis).unwrap_or(0);
        let (response, ..) = loop_at(&open, &law, form.speed_hz * TAU, &axis_settings(scene));
        let worst = axis
            .points
            .iter()
            .map(|p| {
                let s = match &law {
                    Law::Continuous(pd) => response.sensitivity_continuous(pd, p.f_hz)[(k, k)].norm(),
                    Law::Sampled(lp) => response.sensitivity(lp, p.f_hz)[(k, k)].norm(),
                };
                (p.s_db - 20.0 * s.log10()).abs()
            })
            .fold(0.0, f64::max);
        form.measured_difference_db = Some(worst);
    }
}

/// Settings only for [`loop_at`]'s band (not used by [`compare`]'s pointwise evaluation).
fn axis_settings(scene: &Scene) -> Settings {
    Settings::for_gap(scene.plane(0).contact.gap)
}
