//! One bearing plane's physics: `[touchdown]`, `[contact]` and `[amb]` into a planar model's
//! [`Params`], for the planar rotor or a plane's share of the two-plane rotor.

use super::*;
use crate::config::models::{BuildContext, Share};

impl BuildContext for Context<'_> {
    fn whole(&self) -> &Share {
        self.whole
    }

    fn base_dir(&self) -> &Path {
        self.base_dir
    }

    fn single_plane(&self, share: &Share) -> Result<Params, ConfigError> {
        let raw = self.raw;
        refuse_plane_tables(raw)?;
        bearing(&raw.touchdown, &raw.contact, &raw.amb, &raw.controller, &Keys { plane: None }, share)
    }

    fn plane(&self, i: usize, share: &Share) -> Result<Params, ConfigError> {
        let raw = self.raw;
        let letter = ["a", "b"][i];
        let pick = |a: &Option<toml::Table>, b: &Option<toml::Table>| if i == 0 { a.clone() } else { b.clone() };
        let own = [
            pick(&raw.touchdown.a, &raw.touchdown.b),
            pick(&raw.contact.a, &raw.contact.b),
            pick(&raw.amb.a, &raw.amb.b),
        ];
        let td = plane_table(&raw.touchdown, own[0].as_ref(), &format!("touchdown.{letter}"))?;
        let ct = plane_table(&raw.contact, own[1].as_ref(), &format!("contact.{letter}"))?;
        let amb = plane_table(&raw.amb, own[2].as_ref(), &format!("amb.{letter}"))?;
        let keys = Keys { plane: Some((letter, [own[0].as_ref(), own[1].as_ref(), own[2].as_ref()])) };
        bearing(&td, &ct, &amb, &raw.controller, &keys, share)
    }
}

/// A two-plane rotor's per-plane tables (`[touchdown.a]`, …) and initial slopes given in a planar
/// scene, refused by name: each would be silently ignored otherwise. (Its `[rotor]` keys are
/// refused by the planar model's key struct.)
fn refuse_plane_tables(raw: &RawScene) -> Result<(), ConfigError> {
    const WHY: &str = "is a key of the two-plane rotor and this scene is planar (rotor.model = \"planar\"): set \
                       rotor.model = \"two_plane\" or remove the key";
    let slopes =
        [("initial.slope_x_urad", raw.initial.slope_x_urad), ("initial.slope_y_urad", raw.initial.slope_y_urad)];
    if let Some((key, value)) = slopes.iter().find_map(|(k, v)| v.map(|v| (*k, v))) {
        return Err(range(key, value, "µrad", WHY));
    }
    let tables = [
        ("touchdown", &raw.touchdown.a, &raw.touchdown.b),
        ("contact", &raw.contact.a, &raw.contact.b),
        ("amb", &raw.amb.a, &raw.amb.b),
    ];
    for (table, a, b) in tables {
        for (plane, own) in [("a", a), ("b", b)] {
            if let Some(own) = own {
                return Err(ConfigError::Range {
                    key: format!("{table}.{plane}"),
                    value: format!("a table of {} key(s)", own.len()),
                    unit: String::new(),
                    why: format!(
                        "per-plane tables ([{table}.a], [{table}.b]) are for the two-plane rotor and this scene is \
                         planar (rotor.model = \"planar\"): set rotor.model = \"two_plane\" or write the keys in [{table}]"
                    ),
                });
            }
        }
    }
    Ok(())
}

/// A per-plane table: the shared table `shared` (`[touchdown]`) with plane `plane`'s own keys
/// (`[touchdown.b]`) set over it, read as the same table.
pub(super) fn plane_table<T: serde::Serialize + serde::de::DeserializeOwned>(
    shared: &T,
    own: Option<&toml::Table>,
    name: &str,
) -> Result<T, ConfigError> {
    let parse = |message: String| ConfigError::Parse { path: name.to_string(), message };
    let mut table = toml::Table::try_from(shared).map_err(|e| parse(e.to_string()))?;
    table.remove("a");
    table.remove("b");
    if let Some(own) = own {
        if let Some(nested) = ["a", "b"].into_iter().find(|k| own.contains_key(*k)) {
            return Err(parse(format!("a plane's table holds keys, not another plane's table (`{nested}`)")));
        }
        for (key, value) in own {
            table.insert(key.clone(), value.clone());
        }
    }
    toml::Value::Table(table).try_into::<T>().map_err(|e| parse(e.to_string()))
}

/// The full names of a bearing plane's keys: `touchdown.air_gap_mm`, or `touchdown.b.air_gap_mm`
/// where plane B's table sets it.
pub(in crate::config) struct Keys<'a> {
    /// The plane's letter and its own tables of `[touchdown]`, `[contact]`, `[amb]`.
    pub(in crate::config) plane: Option<(&'static str, [Option<&'a toml::Table>; 3])>,
}

impl Keys<'_> {
    fn key(&self, table: usize, field: &str) -> String {
        const TABLES: [&str; 3] = ["touchdown", "contact", "amb"];
        match self.plane {
            Some((plane, own)) if own[table].is_some_and(|t| t.contains_key(field)) => {
                format!("{}.{plane}.{field}", TABLES[table])
            }
            _ => format!("{}.{field}", TABLES[table]),
        }
    }

    fn td(&self, field: &str) -> String {
        self.key(0, field)
    }

    fn ct(&self, field: &str) -> String {
        self.key(1, field)
    }

    fn amb(&self, field: &str) -> String {
        self.key(2, field)
    }
}

/// One bearing plane's parameters, validated: its touchdown bearing (`[touchdown]`), contact
/// laws (`[contact]`) and AMB (`[amb]`, `controller.current_limit_a`), with the rotor's `share`.
pub(in crate::config) fn bearing(
    td: &RawTouchdown,
    ct: &RawContact,
    amb: &RawAmb,
    ctl: &RawController,
    k: &Keys,
    share: &Share,
) -> Result<Params, ConfigError> {
    let race = race(td, k)?;
    let gap = race.gap;
    let (contact, balls) = contact_laws(ct, k, td.ball_count, share.radius, gap, race.clearance)?;
    let (support, race_when_clear) = supports(td, k, &balls)?;
    let (amb_law, ki, ks) = amb_law(amb, k, gap, race.clearance)?;
    let loop_constants = LoopConstants {
        ki_n_per_a: ki,
        ks_n_per_m: ks,
        amp_gain_a_per_v: positive(&k.amb("amp_gain_a_per_v"), amb.amp_gain_a_per_v, "A/V")?,
        sensor_gain_v_per_m: positive(&k.amb("sensor_gain_v_per_m"), amb.sensor_gain_v_per_m, "V/m")?,
        rotor_mass_kg: share.mass,
        gravity_m_s2: share.gravity,
        air_gap_m: gap,
    };
    let current_limit = positive("controller.current_limit_a", ctl.current_limit_a, "A")?;
    let axes = axes(amb, ctl, k)?;
    Ok(Params {
        gravity: share.gravity,
        rotor_mass: share.mass,
        eccentricity: share.eccentricity,
        rotor_inertia: share.inertia,
        speed: share.speed,
        spin: share.spin,
        race_mass: race.mass,
        race_inertia: race.inertia,
        cage: td.cage,
        cage_phase: race.cage_phase,
        cage_ratio: race.cage_ratio,
        contact,
        balls,
        support,
        race_when_clear,
        drag: race.drag,
        amb: amb_law,
        loop_constants,
        current_limit,
        axes,
        touchdown: race.geometry,
    })
}

/// A plane's touchdown race as `[touchdown]` gives it (SI).
struct Race {
    gap: f64,
    mass: f64,
    inertia: f64,
    clearance: f64,
    cage_phase: f64,
    cage_ratio: f64,
    drag: RaceDrag,
    geometry: TouchdownGeometry,
}

/// `[touchdown]`'s race, balls' geometry and drag.
fn race(td: &RawTouchdown, k: &Keys) -> Result<Race, ConfigError> {
    let gap = positive(&k.td("air_gap_mm"), td.air_gap_mm, "mm")? * 1e-3;
    let race_mass = positive(&k.td("race_mass_kg"), td.race_mass_kg, "kg")?;
    let race_inertia = positive(&k.td("race_polar_inertia_kg_m2"), td.race_polar_inertia_kg_m2, "kg·m²")?;
    let ball_d = positive(&k.td("ball_diameter_mm"), td.ball_diameter_mm, "mm")?;
    let dm = positive(&k.td("pitch_diameter_mm"), td.pitch_diameter_mm, "mm")?;
    if ball_d >= dm {
        return Err(range(
            &k.td("ball_diameter_mm"),
            ball_d,
            "mm",
            &format!("must be smaller than {}", k.td("pitch_diameter_mm")),
        ));
    }
    positive(&k.td("outer_diameter_mm"), td.outer_diameter_mm, "mm")?;
    positive(&k.td("width_mm"), td.width_mm, "mm")?;
    if !(3..=64).contains(&td.ball_count) {
        return Err(range(&k.td("ball_count"), td.ball_count, "", "must be between 3 and 64"));
    }
    let clearance = non_negative(&k.td("ball_clearance_mm"), td.ball_clearance_mm, "mm")? * 1e-3;
    let cage_phase = finite(&k.td("cage_phase_deg"), td.cage_phase_deg, "deg")?.to_radians();
    let (r_in, r_out) = (dm / 2.0 - ball_d / 2.0, dm / 2.0 + ball_d / 2.0);
    let reg_speed = positive(&k.td("drag_smoothing_rad_s"), td.drag_smoothing_rad_s, "rad/s")?;
    let torque = non_negative(&k.td("drag_torque_n_m"), td.drag_torque_n_m, "N·m")?;
    let f0 = non_negative(&k.td("palmgren_f0"), td.palmgren_f0, "")?;
    let nu0_cst = positive(&k.td("palmgren_viscosity_cst"), td.palmgren_viscosity_cst, "cSt")?;
    let f1 = non_negative(&k.td("palmgren_f1"), td.palmgren_f1, "")?;
    let drag = match td.drag {
        DragChoice::Constant => RaceDrag::Constant { torque, reg_speed },
        DragChoice::Palmgren => RaceDrag::Palmgren { f0, nu0_cst, f1, pitch_diameter_mm: dm, reg_speed },
    };

    Ok(Race {
        gap,
        mass: race_mass,
        inertia: race_inertia,
        clearance,
        cage_phase,
        cage_ratio: r_in / (r_in + r_out),
        drag,
        geometry: TouchdownGeometry {
            ball_diameter: ball_d * 1e-3,
            pitch_diameter: dm * 1e-3,
            width: td.width_mm * 1e-3,
        },
    })
}

/// `[contact]`: the rotor – race contact (on the rotor of radius `radius` in a bore `gap` wider)
/// and the `balls`' (with their `clearance`).
fn contact_laws(
    ct: &RawContact,
    k: &Keys,
    balls: u32,
    radius: f64,
    gap: f64,
    clearance: f64,
) -> Result<(RotorRace, BallSet), ConfigError> {
    let damping_depth = positive(&k.ct("damping_depth_mm"), ct.damping_depth_mm, "mm")? * 1e-3;
    let v_static = positive(&k.ct("stribeck_static_m_s"), ct.stribeck_static_m_s, "m/s")?;
    let v_dynamic = positive(&k.ct("stribeck_dynamic_m_s"), ct.stribeck_dynamic_m_s, "m/s")?;
    if v_dynamic < v_static {
        return Err(range(
            &k.ct("stribeck_dynamic_m_s"),
            v_dynamic,
            "m/s",
            &format!("must be >= {}", k.ct("stribeck_static_m_s")),
        ));
    }
    let friction = Friction {
        mu_static: non_negative(&k.ct("friction_static"), ct.friction_static, "")?,
        mu_dynamic: non_negative(&k.ct("friction_dynamic"), ct.friction_dynamic, "")?,
        v_static,
        v_dynamic,
    };
    let contact = RotorRace {
        gap,
        rotor_radius: radius,
        bore_radius: radius + gap,
        stiffness: positive(
            &k.ct("rotor_race_stiffness_n_per_m10_9"),
            ct.rotor_race_stiffness_n_per_m10_9,
            "N/m^(10/9)",
        )?,
        damping_max: non_negative(&k.ct("rotor_race_damping_n_s_per_m"), ct.rotor_race_damping_n_s_per_m, "N·s/m")?,
        damping_depth,
        friction,
    };
    let balls = BallSet::new(
        balls as usize,
        clearance,
        positive(&k.ct("ball_stiffness_n_per_m1_5"), ct.ball_stiffness_n_per_m1_5, "N/m^(3/2)")?,
        non_negative(&k.ct("ball_damping_n_s_per_m"), ct.ball_damping_n_s_per_m, "N·s/m")?,
        damping_depth,
    );

    Ok((contact, balls))
}

/// `touchdown.support` (a lumped ring calibrated on `balls`), `touchdown.race_when_clear` and
/// `touchdown.race_release`.
fn supports(td: &RawTouchdown, k: &Keys, balls: &BallSet) -> Result<(Support, RaceWhenClear), ConfigError> {
    let lumped_reference = positive(&k.td("lumped_reference_mm"), td.lumped_reference_mm, "mm")? * 1e-3;
    let support = match td.support {
        SupportChoice::Balls => Support::Balls,
        SupportChoice::Lumped => Support::Lumped(LumpedSupport::calibrated(balls, lumped_reference)),
    };
    let release = match td.race_release {
        ReleaseChoice::Equilibrium => Release::Equilibrium,
        ReleaseChoice::Held => Release::Held,
    };
    let race_when_clear = match td.race_when_clear {
        RaceWhenClearChoice::Free => RaceWhenClear::Free,
        RaceWhenClearChoice::Parked => RaceWhenClear::Parked(release),
    };
    Ok((support, race_when_clear))
}

/// `[amb]`'s force law and its `k_i`, `k_s`; the nonlinear law's magnet gap must exceed the
/// touchdown `gap` plus the balls' `clearance`.
fn amb_law(amb: &RawAmb, k: &Keys, gap: f64, clearance: f64) -> Result<(AmbLaw, f64, f64), ConfigError> {
    let ki = positive(&k.amb("ki_n_per_a"), amb.ki_n_per_a, "N/A")?;
    let ks = non_negative(&k.amb("ks_n_per_m"), amb.ks_n_per_m, "N/m")?;
    let s0 = positive(&k.amb("nominal_gap_mm"), amb.nominal_gap_mm, "mm")? * 1e-3;
    let magnet_force_limit = positive(&k.amb("magnet_force_limit_n"), amb.magnet_force_limit_n, "N")?;
    let amb_law = match amb.force_law {
        ForceLaw::Linear => AmbLaw::Linear { ki, ks },
        ForceLaw::Nonlinear => {
            if ks == 0.0 {
                return Err(range(
                    &k.amb("ks_n_per_m"),
                    ks,
                    "N/m",
                    "must be > 0 for the nonlinear law (it sets the bias current)",
                ));
            }
            if s0 <= gap + clearance {
                return Err(range(
                    &k.amb("nominal_gap_mm"),
                    amb.nominal_gap_mm,
                    "mm",
                    "must exceed the touchdown gap plus ball clearance",
                ));
            }
            AmbLaw::nonlinear_matching(ki, ks, s0, magnet_force_limit)
        }
    };
    Ok((amb_law, ki, ks))
}

/// `amb.axis_angle_deg`: the plane's axes; refused turned with a sampled or co-simulated law's
/// gravity bias.
fn axes(amb: &RawAmb, ctl: &RawController, k: &Keys) -> Result<plant_physics::axes::Axes, ConfigError> {
    let axes = match amb.axis_angle_deg {
        None => Default::default(),
        Some(deg) if deg.is_finite() && (-90.0..=90.0).contains(&deg) => {
            plant_physics::axes::Axes::new(deg.to_radians())
        }
        Some(deg) => return Err(range(&k.amb("axis_angle_deg"), deg, "°", "must be an angle in [-90, 90] degrees")),
    };
    if axes.turned() && ctl.gravity_bias && ctl.mode != ControlMode::Continuous {
        // The laws of the registry add the gravity bias on their own y axis (v), and the hello
        // carries no angle to turn it with (docs/wire-protocol.md): refused, not guessed.
        return Err(range(
            &k.amb("axis_angle_deg"),
            amb.axis_angle_deg.unwrap_or_default(),
            "°",
            "turns the plane's axes, and with controller.gravity_bias = true a sampled or co-simulated law adds \
             the weight's current on its own y axis (v), which is then not vertical (the wire carries no angle): \
             set controller.gravity_bias = false and let an integral carry the weight (law pid, ross_pid), or \
             controller.mode = \"continuous\" (the plant's PD shares the bias between u and v)",
        ));
    }
    Ok(axes)
}
