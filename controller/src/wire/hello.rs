//! The handshake: the plant's hello (the design, the law, its parameters), the controller's
//! acknowledgement or refusal, and the checks of a hello.

use super::*;

/// The plant's side of the handshake: what it runs, each bearing plane's loop design
/// ([`Design`]: plane A in the fields of protocol 3, plane B's in the `b_` fields), the
/// rotor's geometry for 4 axes ([`Geometry`]), and the law's own parameters. 4448 bytes.
/// The fields of a planar hello past `params` are 0.
///
/// | offset | size | field                  | type       |
/// |-------:|-----:|------------------------|------------|
/// | 0      | 4    | `protocol_version`     | u32        |
/// | 4      | 4    | `axes`                 | u32        |
/// | 8      | 4    | `units`                | u32        |
/// | 12     | 4    | `session`              | u32        |
/// | 16     | 8    | `token`                | u64        |
/// | 24     | 8    | `rate_hz`              | f64        |
/// | 32     | 8    | `period_s`             | f64        |
/// | 40     | 32   | `run_id`               | [u8; 32]   |
/// | 72     | 32   | `law`                  | [u8; 32]   |
/// | 104    | 8    | `stiffness_n_per_m`    | f64        |
/// | 112    | 8    | `damping_ratio`        | f64        |
/// | 120    | 8    | `ki_n_per_a`           | f64        |
/// | 128    | 8    | `ks_n_per_m`           | f64        |
/// | 136    | 8    | `amp_gain_a_per_v`     | f64        |
/// | 144    | 8    | `sensor_gain_v_per_m`  | f64        |
/// | 152    | 8    | `rotor_mass_kg`        | f64        |
/// | 160    | 8    | `gravity_m_s2`         | f64        |
/// | 168    | 8    | `current_limit_a`      | f64        |
/// | 176    | 8    | `air_gap_m`            | f64        |
/// | 184    | 4    | `delay_samples`        | u32        |
/// | 188    | 4    | `gravity_bias`         | u32        |
/// | 192    | 8    | `spin_ns`              | u64        |
/// | 200    | 4    | `mode`                 | u32        |
/// | 204    | 4    | `plant_pid`            | u32        |
/// | 208    | 4    | `params_len`           | u32        |
/// | 212    | 4    | `reserved`             | u32        |
/// | 216    | 4096 | `params`               | [u8; 4096] |
/// | 4312   | 8    | `b_stiffness_n_per_m`  | f64        |
/// | 4320   | 8    | `b_damping_ratio`      | f64        |
/// | 4328   | 8    | `b_ki_n_per_a`         | f64        |
/// | 4336   | 8    | `b_ks_n_per_m`         | f64        |
/// | 4344   | 8    | `b_amp_gain_a_per_v`   | f64        |
/// | 4352   | 8    | `b_sensor_gain_v_per_m`| f64        |
/// | 4360   | 8    | `b_rotor_mass_kg`      | f64        |
/// | 4368   | 8    | `b_current_limit_a`    | f64        |
/// | 4376   | 8    | `b_air_gap_m`          | f64        |
/// | 4384   | 8    | `total_mass_kg`        | f64        |
/// | 4392   | 8    | `transverse_inertia_kg_m2` | f64    |
/// | 4400   | 8    | `polar_inertia_kg_m2`  | f64        |
/// | 4408   | 8    | `rated_speed_rad_s`    | f64        |
/// | 4416   | 8    | `bearing_a_z_m`        | f64        |
/// | 4424   | 8    | `bearing_b_z_m`        | f64        |
/// | 4432   | 8    | `sensor_a_z_m`         | f64        |
/// | 4440   | 8    | `sensor_b_z_m`         | f64        |
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[type_name("amb_testbed.v4.Hello")]
#[repr(C)]
pub struct Hello {
    /// [`PROTOCOL_VERSION`] of the plant.
    pub protocol_version: u32,
    /// Number of axes: [`AXES`] (planar) or [`TWO_PLANE_AXES`].
    pub axes: u32,
    /// Units code, [`UNITS_SI`].
    pub units: u32,
    /// Handshake number: 1 for the first controller, +1 per reconnection.
    pub session: u32,
    /// The run's token: random per run, never 0. Every frame of the run carries it; a frame
    /// with another token (another run, a stale process) is never applied.
    pub token: u64,
    /// Controller rate (Hz).
    pub rate_hz: f64,
    /// Controller period `T` (s), as the plant computed it from the rate.
    pub period_s: f64,
    /// The run id, UTF-8, NUL-padded.
    pub run_id: [u8; RUN_ID_LEN],
    /// Law name (`controller.law`), UTF-8, NUL-padded.
    pub law: [u8; LAW_NAME_LEN],
    /// Design stiffness k_e (N/m) (plane A's).
    pub stiffness_n_per_m: f64,
    /// Design damping ratio ξ_e (plane A's).
    pub damping_ratio: f64,
    /// Force-current coefficient k_i (N/A) (plane A's).
    pub ki_n_per_a: f64,
    /// Force-displacement coefficient k_s (N/m) (plane A's).
    pub ks_n_per_m: f64,
    /// Amplifier gain A_a (A/V) (plane A's).
    pub amp_gain_a_per_v: f64,
    /// Sensor gain A_s (V/m) (plane A's).
    pub sensor_gain_v_per_m: f64,
    /// Rotor mass m_r (kg) carried by the bearing: the planar model's mass, plane A's share on
    /// a two-plane rotor.
    pub rotor_mass_kg: f64,
    /// Gravity g (m/s²) (both planes).
    pub gravity_m_s2: f64,
    /// Amplifier limit i_max (A) (plane A's): the controller saturates at it.
    pub current_limit_a: f64,
    /// Radial air gap r_0 of the touchdown bearing (m) (plane A's).
    pub air_gap_m: f64,
    /// Samples between a sample and the tick its command is applied from.
    pub delay_samples: u32,
    /// 1: add the gravity bias current on y.
    pub gravity_bias: u32,
    /// How long a waiting side busy-polls before it blocks (ns).
    pub spin_ns: u64,
    /// [`mode`] code.
    pub mode: u32,
    /// Process id of the plant (informative).
    pub plant_pid: u32,
    /// Bytes of `params` in use.
    pub params_len: u32,
    /// 0.
    pub reserved: u32,
    /// The scene's `[controller.params]` table as TOML text, UTF-8 (the first `params_len`
    /// bytes; the rest 0).
    pub params: [u8; PARAMS_LEN],
    /// Plane B's design stiffness k_e (N/m); 0 on a planar hello (as every field below).
    pub b_stiffness_n_per_m: f64,
    /// Plane B's design damping ratio ξ_e.
    pub b_damping_ratio: f64,
    /// Plane B's k_i (N/A).
    pub b_ki_n_per_a: f64,
    /// Plane B's k_s (N/m).
    pub b_ks_n_per_m: f64,
    /// Plane B's amplifier gain A_a (A/V).
    pub b_amp_gain_a_per_v: f64,
    /// Plane B's sensor gain A_s (V/m).
    pub b_sensor_gain_v_per_m: f64,
    /// The rotor mass plane B carries (kg).
    pub b_rotor_mass_kg: f64,
    /// Plane B's amplifier limit (A).
    pub b_current_limit_a: f64,
    /// Plane B's touchdown air gap (m).
    pub b_air_gap_m: f64,
    /// The whole rotor's mass M (kg).
    pub total_mass_kg: f64,
    /// Transverse moment of inertia I_t about the centre of mass (kg m²).
    pub transverse_inertia_kg_m2: f64,
    /// Polar moment of inertia I_p (kg m²).
    pub polar_inertia_kg_m2: f64,
    /// Rated spin speed (rad/s).
    pub rated_speed_rad_s: f64,
    /// Bearing plane A's station z_A from the centre of mass (m, negative: A is on −z).
    pub bearing_a_z_m: f64,
    /// Bearing plane B's station z_B (m), > z_A.
    pub bearing_b_z_m: f64,
    /// Sensor plane A's station (m).
    pub sensor_a_z_m: f64,
    /// Sensor plane B's station (m).
    pub sensor_b_z_m: f64,
}

/// The controller's side of the handshake. 4416 bytes.
///
/// | offset | size | field              | type       |
/// |-------:|-----:|--------------------|------------|
/// | 0      | 4    | `protocol_version` | u32        |
/// | 4      | 4    | `session`          | u32        |
/// | 8      | 4    | `status`           | u32        |
/// | 12     | 4    | `controller_pid`   | u32        |
/// | 16     | 8    | `token`            | u64        |
/// | 24     | 32   | `law`              | [u8; 32]   |
/// | 56     | 256  | `message`          | [u8; 256]  |
/// | 312    | 4    | `overrides_len`    | u32        |
/// | 316    | 4    | `reserved`         | u32        |
/// | 320    | 4096 | `overrides`        | [u8; 4096] |
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[type_name("amb_testbed.v4.Ack")]
#[repr(C)]
pub struct Ack {
    /// [`PROTOCOL_VERSION`] of the controller.
    pub protocol_version: u32,
    /// The [`Hello::session`] this answers.
    pub session: u32,
    /// 0: accepted; otherwise a [`Refusal`] code.
    pub status: u32,
    /// Process id of the controller.
    pub controller_pid: u32,
    /// Echo of [`Hello::token`].
    pub token: u64,
    /// The law the controller runs (it may override the plant's choice).
    pub law: [u8; LAW_NAME_LEN],
    /// What the controller runs, or why it refuses; UTF-8, NUL-padded.
    pub message: [u8; MESSAGE_LEN],
    /// Bytes of `overrides` in use.
    pub overrides_len: u32,
    /// 0.
    pub reserved: u32,
    /// What the controller runs differently from the hello, as TOML text: a `[controller]`
    /// table (with `[controller.params]`), empty if nothing. The plant writes it into the run
    /// folder's `scene.toml` and `summary.json`, so that the folder reproduces the run.
    pub overrides: [u8; OVERRIDES_LEN],
}

/// Why a controller refuses a [`Hello`] ([`Ack::status`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum Refusal {
    /// Different [`PROTOCOL_VERSION`].
    Version = 1,
    /// The controller is configured for another rate.
    Rate = 2,
    /// Different number of axes.
    Axes = 3,
    /// Different units code.
    Units = 4,
    /// Unknown law or invalid design.
    Law = 5,
    /// The hello carries another run id.
    RunId = 6,
    /// The law refuses its parameters (or the parameter document is malformed).
    Params = 7,
}

impl Refusal {
    /// Every refusal, in code order.
    pub const ALL: [Refusal; 7] =
        [Refusal::Version, Refusal::Rate, Refusal::Axes, Refusal::Units, Refusal::Law, Refusal::RunId, Refusal::Params];

    /// Its name in the C header (`AMB_TESTBED_ACK_<name>`) and [`constants`].
    pub fn constant_name(self) -> &'static str {
        match self {
            Refusal::Version => "VERSION",
            Refusal::Rate => "RATE",
            Refusal::Axes => "AXES",
            Refusal::Units => "UNITS",
            Refusal::Law => "LAW",
            Refusal::RunId => "RUN_ID",
            Refusal::Params => "PARAMS",
        }
    }

    /// The code as sent.
    pub fn code(self) -> u32 {
        self as u32
    }

    /// A short name for a code (`"unknown reason"` for codes this version does not know).
    pub fn describe(code: u32) -> &'static str {
        match code {
            1 => "protocol version mismatch",
            2 => "rate mismatch",
            3 => "axis count mismatch",
            4 => "units mismatch",
            5 => "law rejected",
            6 => "run id mismatch",
            7 => "parameters rejected",
            _ => "unknown reason",
        }
    }
}

// The layouts above are the protocol: a change must fail to compile here.
/// What a controller is configured for, to check a [`Hello`] against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Expect<'a> {
    /// The run id it was started with.
    pub run_id: &'a str,
    /// The rate it is configured for (Hz), if any; `None` accepts the plant's.
    pub rate_hz: Option<f64>,
}

/// The axis counts a hello may carry: planar and two-plane.
pub const SUPPORTED_AXES: [u32; 2] = [AXES, TWO_PLANE_AXES];

/// Checks a [`Hello`] against this controller: protocol version, axes (2 or 4),
/// units, run id and rate. The message names both values.
///
/// ```
/// use controller::wire::{check_hello, Expect, Hello, Refusal};
/// let mut h = Hello::example("run1");
/// assert!(check_hello(&h, &Expect { run_id: "run1", rate_hz: Some(20_000.0) }).is_ok());
/// h.rate_hz = 10_000.0;
/// let (why, msg) = check_hello(&h, &Expect { run_id: "run1", rate_hz: Some(20_000.0) }).unwrap_err();
/// assert_eq!(why, Refusal::Rate);
/// assert!(msg.contains("10000") && msg.contains("20000"), "{msg}");
/// ```
pub fn check_hello(h: &Hello, expect: &Expect) -> Result<(), (Refusal, String)> {
    check_hello_for(h, expect, &SUPPORTED_AXES)
}

/// [`check_hello`] for a controller that drives only the axis counts `axes` (a controller
/// written for the planar model passes `&[AXES]` and so refuses a two-plane hello with
/// [`Refusal::Axes`], code 3).
///
/// ```
/// use controller::wire::{check_hello_for, Expect, Hello, Refusal, AXES};
/// let h = Hello::example_two_plane("r");
/// let (why, msg) = check_hello_for(&h, &Expect { run_id: "r", rate_hz: None }, &[AXES]).unwrap_err();
/// assert_eq!((why, why.code()), (Refusal::Axes, 3));
/// assert_eq!(msg, "the plant has 4 axes, this controller drives 2");
/// ```
pub fn check_hello_for(h: &Hello, expect: &Expect, axes: &[u32]) -> Result<(), (Refusal, String)> {
    if h.protocol_version != PROTOCOL_VERSION {
        return Err((
            Refusal::Version,
            format!(
                "protocol version {} from the plant, this controller speaks {PROTOCOL_VERSION}",
                h.protocol_version
            ),
        ));
    }
    if !axes.contains(&h.axes) {
        let drives: Vec<String> = axes.iter().map(u32::to_string).collect();
        return Err((
            Refusal::Axes,
            format!("the plant has {} axes, this controller drives {}", h.axes, drives.join(" or ")),
        ));
    }
    if h.units != UNITS_SI {
        return Err((
            Refusal::Units,
            format!("units code {} from the plant, this controller uses {UNITS_SI} (SI)", h.units),
        ));
    }
    let id = str_of(&h.run_id);
    if id != expect.run_id {
        return Err((Refusal::RunId, format!("hello for run id {id:?}, this controller serves {:?}", expect.run_id)));
    }
    if let Some(rate) = expect.rate_hz {
        if !(h.rate_hz.is_finite() && (h.rate_hz - rate).abs() <= 1e-9 * rate) {
            return Err((
                Refusal::Rate,
                format!(
                    "the plant runs at controller.rate_hz = {} Hz, this controller is configured for {rate} Hz",
                    h.rate_hz
                ),
            ));
        }
    }
    Ok(())
}

impl Hello {
    /// The hello of a planar run: law `law` built from `design` at `rate_hz`, with the law's
    /// parameter document `params` (TOML text, at most [`PARAMS_LEN`] bytes). Session 0 (the
    /// plant counts handshakes from 1), token 0 (the plant sets the run's), lockstep, no spin,
    /// this process as the plant.
    pub fn new(run_id: &str, law: &str, design: &Design, rate_hz: f64, params: &str) -> Result<Self, ParamsError> {
        Self::for_rotor(run_id, law, &RotorDesign::Planar(*design), rate_hz, params)
    }

    /// [`Hello::new`] for any rotor: a planar design gives `axes` = 2 and zeros past
    /// `params`; a two-plane design `axes` = 4, plane B's design in the `b_` fields and the
    /// geometry. The planes' shared fields (period, delay, gravity bias, gravity) are plane
    /// A's ([`RotorDesign::check`]).
    pub fn for_rotor(
        run_id: &str,
        law: &str,
        design: &RotorDesign,
        rate_hz: f64,
        params: &str,
    ) -> Result<Self, ParamsError> {
        if params.len() > PARAMS_LEN {
            return Err(ParamsError::TooLong { len: params.len() });
        }
        let a = design.plane_a();
        let c = &a.constants;
        let mut hello = Hello {
            protocol_version: PROTOCOL_VERSION,
            axes: design.axes(),
            units: UNITS_SI,
            session: 0,
            token: 0,
            rate_hz,
            period_s: a.period_s,
            run_id: fixed_str(run_id),
            law: fixed_str(law),
            stiffness_n_per_m: a.stiffness_n_per_m,
            damping_ratio: a.damping_ratio,
            ki_n_per_a: c.ki_n_per_a,
            ks_n_per_m: c.ks_n_per_m,
            amp_gain_a_per_v: c.amp_gain_a_per_v,
            sensor_gain_v_per_m: c.sensor_gain_v_per_m,
            rotor_mass_kg: c.rotor_mass_kg,
            gravity_m_s2: c.gravity_m_s2,
            current_limit_a: a.current_limit_a,
            air_gap_m: c.air_gap_m,
            delay_samples: a.delay_samples,
            gravity_bias: u32::from(a.gravity_bias),
            spin_ns: 0,
            mode: mode::LOCKSTEP,
            plant_pid: std::process::id(),
            params_len: params.len() as u32,
            reserved: 0,
            params: [0; PARAMS_LEN],
            b_stiffness_n_per_m: 0.0,
            b_damping_ratio: 0.0,
            b_ki_n_per_a: 0.0,
            b_ks_n_per_m: 0.0,
            b_amp_gain_a_per_v: 0.0,
            b_sensor_gain_v_per_m: 0.0,
            b_rotor_mass_kg: 0.0,
            b_current_limit_a: 0.0,
            b_air_gap_m: 0.0,
            total_mass_kg: 0.0,
            transverse_inertia_kg_m2: 0.0,
            polar_inertia_kg_m2: 0.0,
            rated_speed_rad_s: 0.0,
            bearing_a_z_m: 0.0,
            bearing_b_z_m: 0.0,
            sensor_a_z_m: 0.0,
            sensor_b_z_m: 0.0,
        };
        hello.params[..params.len()].copy_from_slice(params.as_bytes());
        if let RotorDesign::TwoPlane { planes: [_, b], geometry: g } = design {
            let c = &b.constants;
            hello.b_stiffness_n_per_m = b.stiffness_n_per_m;
            hello.b_damping_ratio = b.damping_ratio;
            hello.b_ki_n_per_a = c.ki_n_per_a;
            hello.b_ks_n_per_m = c.ks_n_per_m;
            hello.b_amp_gain_a_per_v = c.amp_gain_a_per_v;
            hello.b_sensor_gain_v_per_m = c.sensor_gain_v_per_m;
            hello.b_rotor_mass_kg = c.rotor_mass_kg;
            hello.b_current_limit_a = b.current_limit_a;
            hello.b_air_gap_m = c.air_gap_m;
            hello.total_mass_kg = g.mass_kg;
            hello.transverse_inertia_kg_m2 = g.transverse_inertia_kg_m2;
            hello.polar_inertia_kg_m2 = g.polar_inertia_kg_m2;
            hello.rated_speed_rad_s = g.rated_speed_rad_s;
            [hello.bearing_a_z_m, hello.bearing_b_z_m] = g.bearing_z_m;
            [hello.sensor_a_z_m, hello.sensor_b_z_m] = g.sensor_z_m;
        }
        Ok(hello)
    }

    /// A planar hello with the study's design ([`Design::study`], law `pd`, 20 kHz; for
    /// examples and tests).
    ///
    /// ```
    /// let h = controller::wire::Hello::example("run1");
    /// assert_eq!((h.axes, h.design().stiffness_n_per_m), (2, 1e6));
    /// assert_eq!(h.params_text().unwrap(), "");
    /// ```
    pub fn example(run_id: &str) -> Self {
        Self::example_of(run_id, &RotorDesign::Planar(Design::study()))
    }

    /// A two-plane hello of the study's symmetric machine ([`RotorDesign::symmetric_study`],
    /// law `pd`, 20 kHz; for examples and tests).
    ///
    /// ```
    /// let h = controller::wire::Hello::example_two_plane("run1");
    /// assert_eq!((h.axes, h.total_mass_kg, h.b_rotor_mass_kg), (4, 23.0, 11.5));
    /// assert_eq!(h.rotor_design(), Some(controller::RotorDesign::symmetric_study()));
    /// ```
    pub fn example_two_plane(run_id: &str) -> Self {
        Self::example_of(run_id, &RotorDesign::symmetric_study())
    }

    fn example_of(run_id: &str, design: &RotorDesign) -> Self {
        let mut h = Self::for_rotor(run_id, "pd", design, 20_000.0, "").expect("an empty document fits");
        h.session = 1;
        h.token = 1;
        h.spin_ns = 200_000;
        h.plant_pid = 0;
        h
    }

    /// Plane A's loop design (the planar design of a planar hello; the inverse of
    /// [`Hello::new`]).
    pub fn design(&self) -> Design {
        Design {
            stiffness_n_per_m: self.stiffness_n_per_m,
            damping_ratio: self.damping_ratio,
            period_s: self.period_s,
            gravity_bias: self.gravity_bias != 0,
            current_limit_a: self.current_limit_a,
            delay_samples: self.delay_samples,
            constants: LoopConstants {
                ki_n_per_a: self.ki_n_per_a,
                ks_n_per_m: self.ks_n_per_m,
                amp_gain_a_per_v: self.amp_gain_a_per_v,
                sensor_gain_v_per_m: self.sensor_gain_v_per_m,
                rotor_mass_kg: self.rotor_mass_kg,
                gravity_m_s2: self.gravity_m_s2,
                air_gap_m: self.air_gap_m,
            },
        }
    }

    /// The whole rotor's design the hello carries (the inverse of [`Hello::for_rotor`]);
    /// `None` for an axis count other than 2 and 4.
    pub fn rotor_design(&self) -> Option<RotorDesign> {
        let a = self.design();
        match self.axes {
            AXES => Some(RotorDesign::Planar(a)),
            TWO_PLANE_AXES => {
                let b = Design {
                    stiffness_n_per_m: self.b_stiffness_n_per_m,
                    damping_ratio: self.b_damping_ratio,
                    current_limit_a: self.b_current_limit_a,
                    constants: LoopConstants {
                        ki_n_per_a: self.b_ki_n_per_a,
                        ks_n_per_m: self.b_ks_n_per_m,
                        amp_gain_a_per_v: self.b_amp_gain_a_per_v,
                        sensor_gain_v_per_m: self.b_sensor_gain_v_per_m,
                        rotor_mass_kg: self.b_rotor_mass_kg,
                        air_gap_m: self.b_air_gap_m,
                        ..a.constants
                    },
                    ..a
                };
                let geometry = Geometry {
                    mass_kg: self.total_mass_kg,
                    transverse_inertia_kg_m2: self.transverse_inertia_kg_m2,
                    polar_inertia_kg_m2: self.polar_inertia_kg_m2,
                    rated_speed_rad_s: self.rated_speed_rad_s,
                    bearing_z_m: [self.bearing_a_z_m, self.bearing_b_z_m],
                    sensor_z_m: [self.sensor_a_z_m, self.sensor_b_z_m],
                };
                Some(RotorDesign::TwoPlane { planes: [a, b], geometry })
            }
            _ => None,
        }
    }

    /// The law's parameter document (TOML text).
    pub fn params_text(&self) -> Result<&str, ParamsError> {
        let len = self.params_len as usize;
        if len > PARAMS_LEN {
            return Err(ParamsError::TooLong { len });
        }
        std::str::from_utf8(&self.params[..len]).map_err(|e| ParamsError::Syntax(format!("not UTF-8: {e}")))
    }
}

impl Ack {
    /// An acceptance (`status` 0) or refusal (a [`Refusal`] code) of the hello of `session`
    /// with token `token`, without overrides.
    pub fn new(session: u32, token: u64, status: u32, law: &str, message: &str) -> Self {
        Ack {
            protocol_version: PROTOCOL_VERSION,
            session,
            status,
            controller_pid: std::process::id(),
            token,
            law: fixed_str(law),
            message: fixed_str(message),
            overrides_len: 0,
            reserved: 0,
            overrides: [0; OVERRIDES_LEN],
        }
    }

    /// The same with an overrides document (TOML text); `Err(len)` if it is longer than
    /// [`OVERRIDES_LEN`].
    pub fn with_overrides(mut self, text: &str) -> Result<Self, usize> {
        if text.len() > OVERRIDES_LEN {
            return Err(text.len());
        }
        self.overrides = [0; OVERRIDES_LEN];
        self.overrides[..text.len()].copy_from_slice(text.as_bytes());
        self.overrides_len = text.len() as u32;
        Ok(self)
    }

    /// The overrides document (TOML text; empty if none).
    pub fn overrides_text(&self) -> Result<&str, String> {
        let len = self.overrides_len as usize;
        if len > OVERRIDES_LEN {
            return Err(format!("overrides_len = {len} bytes: the field holds {OVERRIDES_LEN}"));
        }
        std::str::from_utf8(&self.overrides[..len]).map_err(|e| format!("overrides are not UTF-8: {e}"))
    }
}
