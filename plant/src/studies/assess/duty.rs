//! The touchdown bearing's duty in one run, accumulated as the run goes (a [`Sink`] around
//! another): what one shock event costs the bearing. Every figure is taken at the run's output
//! samples (the scene's `output.rate_hz`): a peak between two samples is not seen.
//!
//! | figure | basis |
//! |---|---|
//! | time in contact | output samples with a rotor – race normal force > 0, each counted for one sample interval |
//! | peak rotor – race force | the contact law's normal force (MODEL.md §4) |
//! | peak rotor – race pressure | Hertz line contact at that force ([`super::hertz::rotor_race`]) |
//! | peak ball load, its pressure | the most loaded ball (MODEL.md §5) and Hertz's point contact at its inner raceway ([`super::hertz::ball_inner`]) |
//! | friction energy | `∫ |F_t v_slip| dt` at the rotor – race contact (trapezoid over the samples): the heat the contact's friction dissipates |
//! | race peak speed, acceleration | the inner race's spin `|ω_b|` and its angular acceleration `|ω̇_b|` from the model |
//! | ball-load cycles | rainflow count of each ball's load history ([`super::rainflow`]), cycles whose range is at least `capacity_fraction` of one ball's static capacity `Q₀` ([`super::hertz::ball_static_load`]), summed over the balls |
//!
//! None of these is a life: they are the loads a life model would take.

use super::hertz::{self, Materials};
use super::rainflow::Rainflow;
use crate::machine::PlaneState;
use crate::model::{cage_angle, Cage, Support};
use crate::run::{PlaneStates, Sink};
use nalgebra::Vector2;
use serde::Serialize;

/// The bearing's geometry and materials the duty needs beyond the model's parameters (SI).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Bearing {
    /// Materials and groove conformity.
    pub materials: Materials,
    /// Ball diameter D (m).
    pub ball_diameter_m: f64,
    /// Pitch diameter d_m (m).
    pub pitch_diameter_m: f64,
    /// Race width B, the rotor – race contact length (m).
    pub width_m: f64,
    /// One ball's static capacity Q₀ (N).
    pub ball_static_load_n: f64,
    /// Counted load cycles have a range of at least this share of Q₀.
    pub capacity_fraction: f64,
}

impl Bearing {
    /// The bearing of a scene's `[touchdown]` with these materials.
    pub fn new(materials: Materials, ball: f64, pitch: f64, width: f64, capacity_fraction: f64) -> Self {
        Self {
            materials,
            ball_diameter_m: ball,
            pitch_diameter_m: pitch,
            width_m: width,
            ball_static_load_n: hertz::ball_static_load(&materials, ball, pitch),
            capacity_fraction,
        }
    }

    /// The touchdown bearing of a scene, with these materials: plane A's geometry from the
    /// validated parameters (SI), the one bearing the duty grades (a two-plane scene's planes
    /// share it unless a plane's table gives its own).
    pub fn of_scene(scene: &crate::config::Scene, materials: Materials, capacity_fraction: f64) -> Self {
        let g = scene.rotor.plane(0).touchdown;
        Self::new(materials, g.ball_diameter, g.pitch_diameter, g.width, capacity_fraction)
    }
}

/// The duty of one run.
#[derive(Clone, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct Duty {
    /// Time in contact (s).
    pub contact_time_s: f64,
    /// Peak rotor – race normal force (N).
    pub peak_contact_force_n: f64,
    /// Peak rotor – race Hertz pressure (MPa).
    pub peak_race_pressure_mpa: f64,
    /// The line contact's half-width at that force (mm).
    pub race_contact_half_width_mm: f64,
    /// The most loaded ball's peak load and pressure; `None` with the lumped support (no balls).
    #[serde(flatten)]
    pub ball: BallPeak,
    /// Friction energy dissipated at the rotor – race contact (J).
    pub friction_energy_j: f64,
    /// Peak race spin speed (rpm).
    pub race_peak_speed_rpm: f64,
    /// Peak race angular acceleration (rad/s²).
    pub race_peak_accel_rad_s2: f64,
    /// Ball-load cycles with a range of at least the stated share of Q₀, all balls.
    pub ball_cycles: Option<f64>,
    /// The two-plane rotor: each touchdown bearing's duty, A then B (the figures above are
    /// each the larger of the two); empty for the planar model.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub planes: Vec<Duty>,
}

/// The peak of the most loaded ball; `None` with the lumped support (no balls).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct BallPeak {
    /// Peak load of the most loaded ball (N).
    pub peak_ball_load_n: Option<f64>,
    /// Its Hertz pressure at the inner raceway (MPa).
    pub peak_ball_pressure_mpa: Option<f64>,
}

/// One touchdown bearing's duty, accumulated sample by sample.
struct PlaneDuty {
    duty: Duty,
    last: Option<(f64, f64)>,
    loads: Vec<f64>,
    counters: Vec<Rainflow>,
    lumped: bool,
}

impl PlaneDuty {
    fn new(bearing: &Bearing, balls: usize) -> Self {
        let q0 = bearing.ball_static_load_n;
        Self {
            duty: Duty::default(),
            last: None,
            loads: vec![0.0; balls],
            counters: (0..balls).map(|_| Rainflow::new(0.01 * q0, bearing.capacity_fraction * q0)).collect(),
            lumped: false,
        }
    }

    fn push(&mut self, bearing: &Bearing, t: f64, s: &PlaneState) {
        let p = s.params;
        let d = &mut self.duty;
        let normal = s.normal;
        // Slip at the contact point (MODEL.md §4), for the friction power |F_t v_t|.
        let gap = s.rotor.0 - s.race.0;
        let power = if normal > 0.0 && gap.norm() > 0.0 {
            let n = gap / gap.norm();
            let tangent = Vector2::new(-n.y, n.x);
            let dv = s.rotor.1 - s.race.1;
            let slip = dv.dot(&tangent) + s.rotor_speed * p.contact.rotor_radius - s.race_speed * p.contact.bore_radius;
            (s.tangential * slip).abs()
        } else {
            0.0
        };
        if let Some((t0, p0)) = self.last {
            let dt = t - t0;
            d.friction_energy_j += 0.5 * (p0 + power) * dt;
            if normal > 0.0 {
                d.contact_time_s += dt;
            }
        }
        self.last = Some((t, power));
        if normal > d.peak_contact_force_n {
            d.peak_contact_force_n = normal;
            let r = hertz::rotor_race(
                &bearing.materials,
                normal,
                p.contact.rotor_radius,
                p.contact.bore_radius,
                bearing.width_m,
            );
            d.peak_race_pressure_mpa = r.p_max_pa * 1e-6;
            d.race_contact_half_width_mm = r.half_width_m * 1e3;
        }
        d.race_peak_speed_rpm = d.race_peak_speed_rpm.max(s.race_speed.abs() * 60.0 / std::f64::consts::TAU);
        d.race_peak_accel_rad_s2 = d.race_peak_accel_rad_s2.max(s.race_accel.abs());
        self.lumped = !matches!(p.support, Support::Balls);
        if let Support::Balls = p.support {
            let (cage, rate) = match p.cage {
                Cage::Rotating => (cage_angle(p, s.race_angle), p.cage_ratio * s.race_speed),
                Cage::Fixed => (cage_angle(p, s.race_angle), 0.0),
            };
            if self.loads.len() != p.balls.count() {
                // This bearing's own ball count (the sink was made with the scene's).
                let fresh = Self::new(bearing, p.balls.count());
                (self.loads, self.counters) = (fresh.loads, fresh.counters);
            }
            p.balls.loads(s.race.0, s.race.1, cage, rate, &mut self.loads);
            let d = &mut self.duty;
            let mut most = d.ball.peak_ball_load_n.unwrap_or(0.0);
            for (l, c) in self.loads.iter().zip(&mut self.counters) {
                c.push(*l);
                most = most.max(*l);
            }
            d.ball.peak_ball_load_n = Some(most);
        }
    }

    fn finish(self, bearing: &Bearing) -> Duty {
        let mut d = self.duty;
        let m = &bearing.materials;
        if self.lumped {
            d.ball = BallPeak::default();
            d.ball_cycles = None;
        } else {
            let q = d.ball.peak_ball_load_n.unwrap_or(0.0);
            let p = hertz::ball_inner(m, q, bearing.ball_diameter_m, bearing.pitch_diameter_m);
            d.ball.peak_ball_pressure_mpa = Some(p.p_max_pa * 1e-6);
            d.ball_cycles = Some(self.counters.into_iter().map(|c| c.finish().0).sum());
        }
        d
    }
}

/// Accumulates [`Duty`] from a run's samples and passes them on to `inner`: one touchdown
/// bearing's on the planar model, each of the two-plane rotor's two.
pub struct DutySink<'a> {
    inner: &'a mut dyn Sink,
    bearing: Bearing,
    balls: usize,
    planes: Vec<PlaneDuty>,
}

impl<'a> DutySink<'a> {
    /// A duty accumulator for `balls` balls per bearing in front of `inner`.
    pub fn new(inner: &'a mut dyn Sink, bearing: Bearing, balls: usize) -> Self {
        Self { inner, bearing, balls, planes: Vec::new() }
    }

    fn plane(&mut self, i: usize) -> &mut PlaneDuty {
        while self.planes.len() <= i {
            self.planes.push(PlaneDuty::new(&self.bearing, self.balls));
        }
        &mut self.planes[i]
    }

    /// The duty of the samples seen: the one bearing's; with two, each figure is the larger of
    /// the two bearings' (they may come from different bearings), each bearing's in `planes`.
    pub fn finish(self) -> Duty {
        let bearing = self.bearing;
        let mut planes: Vec<Duty> = self.planes.into_iter().map(|p| p.finish(&bearing)).collect();
        if planes.len() <= 1 {
            return planes.pop().unwrap_or_default();
        }
        let most = |f: fn(&Duty) -> f64| planes.iter().map(f).fold(0.0, f64::max);
        let most_opt = |f: fn(&Duty) -> Option<f64>| planes.iter().filter_map(f).reduce(f64::max);
        let governing = planes
            .iter()
            .max_by(|a, b| a.peak_contact_force_n.total_cmp(&b.peak_contact_force_n))
            .cloned()
            .unwrap_or_default();
        Duty {
            contact_time_s: most(|d| d.contact_time_s),
            peak_contact_force_n: governing.peak_contact_force_n,
            peak_race_pressure_mpa: governing.peak_race_pressure_mpa,
            race_contact_half_width_mm: governing.race_contact_half_width_mm,
            ball: BallPeak {
                peak_ball_load_n: most_opt(|d| d.ball.peak_ball_load_n),
                peak_ball_pressure_mpa: most_opt(|d| d.ball.peak_ball_pressure_mpa),
            },
            friction_energy_j: most(|d| d.friction_energy_j),
            race_peak_speed_rpm: most(|d| d.race_peak_speed_rpm),
            race_peak_accel_rad_s2: most(|d| d.race_peak_accel_rad_s2),
            ball_cycles: most_opt(|d| d.ball_cycles),
            planes,
        }
    }
}

impl Sink for DutySink<'_> {
    fn sample(&mut self, record: &crate::trace::Record) {
        self.inner.sample(record);
    }

    fn planes(&mut self, planes: &dyn PlaneStates) {
        self.inner.planes(planes);
        let (bearing, t) = (self.bearing, planes.time());
        planes.visit(&mut |i, sample| self.plane(i).push(&bearing, t, sample));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shipped;
    use crate::trace::Trace;

    /// Issue 41 item 4: the duty's bearing is the scene's `[touchdown]` geometry in metres (the
    /// figures of config/paper-10g.toml: D = 5.5 mm, d_m = 51 mm, B = 12 mm), read from the
    /// validated parameters; a two-plane scene's plane A table gives plane A's own.
    #[test]
    fn the_duty_bearing_is_the_scenes_touchdown_geometry_in_si() {
        // Millimetres to metres within an ulp or two (51 mm × 1e-3 is 0.051000000000000004).
        let same = |b: &Bearing, want: [f64; 3]| {
            let got = [b.ball_diameter_m, b.pitch_diameter_m, b.width_m];
            assert!(got.iter().zip(want).all(|(g, w)| (g - w).abs() <= 1e-15 * w), "{got:?} vs {want:?}");
        };
        same(&Bearing::of_scene(&shipped("paper-10g.toml", &[]), Materials::default(), 0.5), [5.5e-3, 51e-3, 12e-3]);
        let own = ["touchdown.a.ball_diameter_mm=6.0", "touchdown.a.width_mm=10.0"];
        let scene = shipped("two-plane-asymmetric-10g.toml", &own);
        same(&Bearing::of_scene(&scene, Materials::default(), 0.5), [6e-3, 51e-3, 10e-3]);
    }

    /// Every layout of the plant's state (bare, with amplifiers, with unipolar amplifiers; planar
    /// and two-plane) hands the duty each of its planes in contact: the duty reads the planes
    /// through the rotor model (`Machine::plane_states`), the hardware's wrapper included (before
    /// the rotor seam, a run with amplifiers handed the duty nothing and its duty was all zeros).
    #[test]
    fn every_layout_of_the_state_hands_the_duty_its_planes() {
        let hw = "amb.amplifier=true";
        let uni = ["amb.amplifier=true", "amb.amplifier_topology=\"unipolar\"", "amb.force_law=\"nonlinear\""];
        let cases: [(&str, &[&str]); 4] = [
            ("realistic-10g.toml", &[]),
            ("realistic-10g.toml", &uni),
            ("two-plane-asymmetric-10g.toml", &[]),
            ("two-plane-asymmetric-10g.toml", &[hw]),
        ];
        for (file, sets) in cases {
            let mut sets = sets.to_vec();
            sets.push("controller.mode=\"continuous\"");
            let scene = shipped(file, &sets);
            // Into contact: the shock's first 30 ms, at the fixed-step setting (fast).
            let mut more = scene.fixed_step_overrides();
            more.push(format!("scene.duration_s={:?}", scene.first_shock_start() + 0.03));
            let scene = scene.reload(&more).unwrap();
            let bearing = Bearing::new(Materials::default(), 6.35e-3, 50e-3, 10e-3, 0.1);
            let mut trace = Trace::with_capacity(1024);
            let mut sink = DutySink::new(&mut trace, bearing, scene.plane(0).balls.count());
            let run = crate::run::run_into(&scene, &Default::default(), &mut crate::hooks::Quiet, &mut sink)
                .unwrap_or_else(|e| panic!("{file} {sets:?}: {e}"));
            assert_eq!(run.outcome, crate::run::Outcome::Completed, "{file} {sets:?}");
            let duty = sink.finish();
            // One plane's duty is the duty; two planes' are each in `planes`.
            assert_eq!(duty.planes.len(), if scene.planes() == 1 { 0 } else { scene.planes() }, "{file} {sets:?}");
            assert!(
                duty.contact_time_s > 0.0 && duty.peak_contact_force_n > 0.0,
                "{file} {sets:?}: the shock puts the rotor into a race: {duty:?}"
            );
        }
    }
}
