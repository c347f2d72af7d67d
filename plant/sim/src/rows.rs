//! One output sample of a run, as the plant makes it: the columns of `trace.csv` in their order
//! (plane A's and the shared ones, plane B's and the tilt's, the coils', the magnets', the
//! mid-span's), with the column indices the machines and the hardware write and read. The
//! names of the columns and their storage are the CLI's (`plant::trace`).

use crate::model::{ix, Model, State};
use plant_physics::two_plane;

/// Number of mid-span columns.
pub const WIDTH_MID: usize = 2;

/// A flexible sample's rotor at mid-span: `TraceMid::COLUMNS`, in order.
pub type RowMid = [f64; WIDTH_MID];
/// Number of coil columns (both planes').
pub const WIDTH_HW: usize = 8;

/// A sample's coil currents and voltages: `TraceHw::COLUMNS`, in order.
pub type RowHw = [f64; WIDTH_HW];
/// Number of magnet columns (both planes').
pub const WIDTH_MAGNETS: usize = 16;

/// A sample's magnet currents and voltages: `TraceMagnets::COLUMNS`, in order.
pub type RowMagnets = [f64; WIDTH_MAGNETS];
/// Number of columns of a trace (the planar model's; plane A's and the shared ones).
pub const WIDTH: usize = 19;

/// One output sample of one plane: the values of `Trace::COLUMNS` (`plant::trace`), in order. A two-plane
/// sample's plane B is seen as such a row too ([`Record::plane`]).
pub type Row = [f64; WIDTH];

/// Number of plane B and tilt columns of a two-plane trace.
pub const WIDTH_B: usize = 18;

/// A two-plane sample's plane B and tilt values: `TraceB::COLUMNS`, in order.
pub type RowB = [f64; WIDTH_B];

/// One output sample: the planar columns (plane A's and the shared ones) and, for a two-plane
/// rotor, plane B's and the tilt's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Record {
    /// The planar columns.
    pub a: Row,
    /// Plane B and the tilt (two-plane runs).
    pub b: Option<RowB>,
    /// The coils' currents and voltages (runs with amplifiers).
    pub hw: Option<RowHw>,
    /// Each magnet's current and voltage (runs with unipolar amplifiers).
    pub magnets: Option<RowMagnets>,
    /// The rotor at mid-span (flexible runs).
    pub mid: Option<RowMid>,
}

impl Record {
    /// A planar sample.
    pub fn planar(a: Row) -> Self {
        Self { a, b: None, hw: None, magnets: None, mid: None }
    }

    /// Bearing planes in the sample: 1 (planar) or 2.
    pub fn planes(&self) -> usize {
        1 + usize::from(self.b.is_some())
    }

    /// Plane `i`'s sample as a planar row (0: plane A, the planar columns; 1: plane B's
    /// columns with the shared ones: time, spin, housing).
    pub fn plane(&self, i: usize) -> Row {
        match (i, &self.b) {
            (1, Some(b)) => {
                let a = &self.a;
                [
                    a[col::T_S],
                    b[colb::DX],
                    b[colb::DX + 1],
                    b[colb::DX + 2],
                    b[colb::DX + 3],
                    b[colb::RACE],
                    b[colb::RACE + 1],
                    b[colb::RACE + 2],
                    b[colb::RACE + 3],
                    a[col::ROTOR_ANGLE_RAD],
                    a[col::ROTOR_SPEED_RAD_S],
                    b[colb::RACE_SPEED],
                    b[colb::CONTACT],
                    b[colb::CONTACT + 1],
                    b[colb::CONTACT + 2],
                    b[colb::CURRENT],
                    b[colb::CURRENT + 1],
                    a[col::HOUSING_X_M],
                    a[col::HOUSING_Y_M],
                ]
            }
            _ => self.a,
        }
    }

    /// The slopes (a, b) of the rotor axis (rad), two-plane samples.
    pub fn slopes(&self) -> Option<[f64; 2]> {
        self.b.map(|b| [b[colb::SLOPE], b[colb::SLOPE + 1]])
    }
}

/// Column indices of a [`RowB`].
pub mod colb {
    /// `b_dx_m` (then `b_dy_m`, `b_vx_m_s`, `b_vy_m_s`).
    pub const DX: usize = 0;
    /// `b_xb_m` (then `b_yb_m`, `b_vxb_m_s`, `b_vyb_m_s`).
    pub const RACE: usize = 4;
    /// `b_race_speed_rad_s`.
    pub const RACE_SPEED: usize = 8;
    /// `b_contact_force_n` (then `b_friction_force_n`, `b_ball_force_n`).
    pub const CONTACT: usize = 9;
    /// `b_ix_a` (then `b_iy_a`).
    pub const CURRENT: usize = 12;
    /// `slope_x_rad` (then `slope_y_rad`, `slope_x_rate_rad_s`, `slope_y_rate_rad_s`).
    pub const SLOPE: usize = 14;
}

/// Column indices of a [`Row`], in the order of `Trace::COLUMNS` (`plant::trace`).
pub mod col {
    /// `t_s`.
    pub const T_S: usize = 0;
    /// `dx_m`.
    pub const DX_M: usize = 1;
    /// `dy_m`.
    pub const DY_M: usize = 2;
    /// `vx_m_s`.
    pub const VX_M_S: usize = 3;
    /// `vy_m_s`.
    pub const VY_M_S: usize = 4;
    /// `xb_m`.
    pub const XB_M: usize = 5;
    /// `yb_m`.
    pub const YB_M: usize = 6;
    /// `rotor_angle_rad`.
    pub const ROTOR_ANGLE_RAD: usize = 9;
    /// `rotor_speed_rad_s`.
    pub const ROTOR_SPEED_RAD_S: usize = 10;
    /// `race_speed_rad_s`.
    pub const RACE_SPEED_RAD_S: usize = 11;
    /// `contact_force_n`.
    pub const CONTACT_FORCE_N: usize = 12;
    /// `friction_force_n`.
    pub const FRICTION_FORCE_N: usize = 13;
    /// `ix_a`.
    pub const IX_A: usize = 15;
    /// `iy_a`.
    pub const IY_A: usize = 16;
    /// `housing_x_m`.
    pub const HOUSING_X_M: usize = 17;
    /// `housing_y_m`.
    pub const HOUSING_Y_M: usize = 18;
}

/// The planar model's sample of the state `y` at time `t`, with the forces the model gives there.
pub fn row(model: &Model, t: f64, y: &State) -> Row {
    let ev = model.evaluate(t, y);
    let housing = model.base.eval(t);
    [
        t,
        y[ix::XR],
        y[ix::YR],
        y[ix::VXR],
        y[ix::VYR],
        y[ix::XB],
        y[ix::YB],
        y[ix::VXB],
        y[ix::VYB],
        y[ix::TR],
        y[ix::WR],
        y[ix::WB],
        ev.contact.normal,
        ev.contact.tangential,
        ev.balls.on_race[0].hypot(ev.balls.on_race[1]),
        ev.current[0],
        ev.current[1],
        housing.disp[0],
        housing.disp[1],
    ]
}

/// The two-plane model's sample of the state `y` at time `t`: plane A in the planar columns
/// (the rotor at bearing A), plane B and the slopes in the others.
pub fn two_plane_record(model: &two_plane::Model, t: f64, y: &two_plane::State) -> Record {
    use two_plane::ix;
    let ev = model.evaluate(t, y);
    let housing = model.base.eval(t);
    let plane = |i: usize| {
        let (pos, vel) = two_plane::at_station(y, model.params.planes[i].station);
        let race = ix::RACE[i];
        let race = [y[race], y[race + 1], y[race + ix::V], y[race + 1 + ix::V], y[race + 2 + ix::V]];
        plane_values([pos.x, pos.y], [vel.x, vel.y], race, &ev.planes[i])
    };
    let slopes = [y[ix::SX], y[ix::SY], y[ix::VSX], y[ix::VSY]];
    two_bearing_record(t, [y[ix::TR], y[ix::WR]], housing.disp, [plane(0), plane(1)], slopes)
}

/// One bearing plane's values in a two-bearing record, in the order of plane B's columns: the
/// rotor at the plane (x, y, their rates), the race (x, y, their rates, its spin speed), the
/// contact's normal and tangential force, the balls' force on the race, the currents x, y.
pub type PlaneValues = [f64; 14];

/// One bearing plane's [`PlaneValues`]: the rotor's position and velocity at the plane, the
/// race's state `[x, y, ẋ, ẏ, ω]`, and what the model evaluated there.
pub fn plane_values(pos: [f64; 2], vel: [f64; 2], race: [f64; 5], p: &two_plane::PlaneEvaluation) -> PlaneValues {
    [
        pos[0],
        pos[1],
        vel[0],
        vel[1],
        race[0],
        race[1],
        race[2],
        race[3],
        race[4],
        p.contact.normal,
        p.contact.tangential,
        p.balls.on_race[0].hypot(p.balls.on_race[1]),
        p.current[0],
        p.current[1],
    ]
}

/// The record of a rotor on two bearing planes (the two-plane rotor, the flexible rotor):
/// plane A in the planar columns, plane B and the slopes `[a, b, ȧ, ḃ]` of the line through the
/// planes in the others; `spin` is the rotor's angle and speed, `housing` its displacement.
pub fn two_bearing_record(
    t: f64,
    spin: [f64; 2],
    housing: [f64; 2],
    planes: [PlaneValues; 2],
    slopes: [f64; 4],
) -> Record {
    let [dx, dy, vx, vy, xb, yb, vxb, vyb, race_speed, normal, tangential, balls, ix_a, iy_a] = planes[0];
    let a = [
        t, dx, dy, vx, vy, xb, yb, vxb, vyb, spin[0], spin[1], race_speed, normal, tangential, balls, ix_a, iy_a,
        housing[0], housing[1],
    ];
    let mut b = [0.0; WIDTH_B];
    b[..14].copy_from_slice(&planes[1]);
    b[colb::SLOPE..].copy_from_slice(&slopes);
    Record { a, b: Some(b), hw: None, magnets: None, mid: None }
}
