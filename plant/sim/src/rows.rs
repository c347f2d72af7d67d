//! The typed rows of a run's output: one output sample ([`Record`]) is a struct of typed rows —
//! the time, the rotor's spin, the housing, each bearing plane's motion and loads, the tilt, the
//! coils, the magnets, the rotor at mid-span — and this module is the one place that names each
//! column (the field's name is the column's name, its unit the name's suffix and the field's
//! doc), and gives the columns' order ([`Layout`]: `trace.csv`'s header and values). The CSV
//! writer and reader (`plant::trace`), the recording's topics, the analysis and the FMU's
//! outputs read and write rows through these types, never through a column's number.
//!
//! Pure: std, `plant_physics` and the model only; no I/O.

use crate::model::{ix, Model, State};
use plant_physics::two_plane;

/// A row type whose values are columns of the output: their names, in order, and the values in
/// the same order.
pub trait Columns: Copy {
    /// The columns' names, in order (plane A's; [`Columns::B_NAMES`] for plane B's).
    const NAMES: &'static [&'static str];
    /// The same columns of bearing plane B: the names with the prefix `b_` (the tilt and the
    /// mid-span, which are not a plane's, have no B names: their own names).
    const B_NAMES: &'static [&'static str];
    /// Number of columns.
    const WIDTH: usize = Self::NAMES.len();
    /// Every value `NaN`: what a row does not hold is written as `NaN` in `trace.csv`.
    const NAN: Self;

    /// Passes each value to `out`, in the order of [`Columns::NAMES`].
    fn put(&self, out: &mut dyn FnMut(f64));

    /// The row whose values `next` gives, in the order of [`Columns::NAMES`].
    fn take(next: &mut dyn FnMut() -> f64) -> Self;

    /// The row of `values`, in the order of [`Columns::NAMES`] (`values` holds at least
    /// [`Columns::WIDTH`]).
    fn from_values(values: &[f64]) -> Self {
        let mut it = values.iter();
        Self::take(&mut || it.next().copied().unwrap_or(f64::NAN))
    }

    /// The values, in the order of [`Columns::NAMES`].
    fn values(&self) -> Vec<f64> {
        let mut v = Vec::with_capacity(Self::WIDTH);
        self.put(&mut |x| v.push(x));
        v
    }
}

/// A leaf row type: a struct of `f64` fields, each one column named like the field; and the
/// same row kept columnar (`Vec<f64>` per field, `…Columns`) for a trace in memory. A
/// declarative macro rather than a derive crate: the names must be `&'static str` constants
/// (the header, the plane B prefix through `concat!`) and the struct, its columnar twin and its
/// [`Columns`] impl must come from the one list of fields; a proc-macro crate for four lines of
/// expansion per type would be a crate to build and keep.
macro_rules! row_type {
    ($(#[$meta:meta])* $name:ident, $columnar:ident, $prefix:literal { $($field:ident : $doc:literal),* $(,)? }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, Default, PartialEq)]
        pub struct $name { $(#[doc = $doc] pub $field: f64,)* }

        impl Columns for $name {
            const NAMES: &'static [&'static str] = &[$(stringify!($field)),*];
            const B_NAMES: &'static [&'static str] = &[$(concat!($prefix, stringify!($field))),*];
            const NAN: Self = Self { $($field: f64::NAN),* };

            fn put(&self, out: &mut dyn FnMut(f64)) {
                $(out(self.$field);)*
            }

            fn take(next: &mut dyn FnMut() -> f64) -> Self {
                Self { $($field: next()),* }
            }
        }

        #[doc = concat!("[`", stringify!($name), "`] kept columnar: one `Vec` per column, named like the column.")]
        #[derive(Clone, Debug, Default, PartialEq)]
        pub struct $columnar { $(#[doc = $doc] pub $field: Vec<f64>,)* }

        impl $columnar {
            /// Empty columns with room for `n` rows.
            pub fn with_capacity(n: usize) -> Self {
                Self { $($field: Vec::with_capacity(n),)* }
            }

            /// Appends a row.
            pub fn push(&mut self, r: &$name) {
                $(self.$field.push(r.$field);)*
            }

            /// Row `i`.
            pub fn get(&self, i: usize) -> $name {
                $name { $($field: self.$field[i]),* }
            }
        }
    };
}

row_type! {
    /// The rotor's and the race's motion at one bearing plane, relative to the housing.
    Motion, MotionColumns, "b_" {
        dx_m: "Rotor x relative to the housing (m); two-plane: at the bearing.",
        dy_m: "Rotor y relative to the housing (m); two-plane: at the bearing.",
        vx_m_s: "Rotor x velocity relative to the housing (m/s); two-plane: at the bearing.",
        vy_m_s: "Rotor y velocity relative to the housing (m/s); two-plane: at the bearing.",
        xb_m: "Race x relative to the housing (m).",
        yb_m: "Race y relative to the housing (m).",
        vxb_m_s: "Race x velocity relative to the housing (m/s).",
        vyb_m_s: "Race y velocity relative to the housing (m/s).",
    }
}

row_type! {
    /// The rotor's spin, shared by the planes.
    Spin, SpinColumns, "" {
        rotor_angle_rad: "Rotor spin angle (rad).",
        rotor_speed_rad_s: "Rotor spin speed (rad/s).",
    }
}

row_type! {
    /// The race's spin and the loads at one bearing plane: the contact, the balls, the coil
    /// currents (the commanded currents in a run with amplifiers).
    Loads, LoadsColumns, "b_" {
        race_speed_rad_s: "Race spin speed (rad/s).",
        contact_force_n: "Rotor – race normal force (N).",
        friction_force_n: "Rotor – race friction force (N), signed like the slip.",
        ball_force_n: "Resultant of the ball forces on the race (N).",
        ix_a: "Coil current, x (A).",
        iy_a: "Coil current, y (A).",
    }
}

row_type! {
    /// The housing's displacement, shared by the planes.
    Housing, HousingColumns, "" {
        housing_x_m: "Housing displacement, x (m).",
        housing_y_m: "Housing displacement, y (m).",
    }
}

row_type! {
    /// The tilt of the rotor's axis (a two-plane run).
    Tilt, TiltColumns, "" {
        slope_x_rad: "Slope a = dx/dz of the rotor axis (rad): the tilt about y.",
        slope_y_rad: "Slope b = dy/dz of the rotor axis (rad): minus the tilt about x.",
        slope_x_rate_rad_s: "Rate of the slope a (rad/s).",
        slope_y_rate_rad_s: "Rate of the slope b (rad/s).",
    }
}

row_type! {
    /// One bearing's coils in a run with amplifiers (`amb.amplifier`): the real currents and
    /// the amplifier's voltages. The current columns `ix_a`, `iy_a` ([`Loads`]) are then the
    /// commanded currents, the references of the current loops.
    Coils, CoilsColumns, "b_" {
        ix_coil_a: "Coil current, x (A): the real current the force follows.",
        iy_coil_a: "Coil current, y (A).",
        vx_coil_v: "Coil voltage, x (V): the amplifier's output.",
        vy_coil_v: "Coil voltage, y (V).",
    }
}

row_type! {
    /// One bearing's magnets in a run with unipolar amplifiers (`amb.amplifier_topology =
    /// "unipolar"`, docs/MODEL.md §12.3): `plus` is the magnet on the + side of the axis (it
    /// pulls the rotor toward +x, +y), `minus` the one on the − side. The coil columns
    /// ([`Coils`]) are then the differential current `(i₊ − i₋)/2` and voltage `(v₊ − v₋)/2`.
    Magnets, MagnetsColumns, "b_" {
        ix_plus_a: "Current of the +x magnet's coil (A).",
        ix_minus_a: "Current of the −x magnet's coil (A).",
        iy_plus_a: "Current of the +y (upper) magnet's coil (A).",
        iy_minus_a: "Current of the −y (lower) magnet's coil (A).",
        vx_plus_v: "Voltage on the +x magnet's coil (V).",
        vx_minus_v: "Voltage on the −x magnet's coil (V).",
        vy_plus_v: "Voltage on the +y magnet's coil (V).",
        vy_minus_v: "Voltage on the −y magnet's coil (V).",
    }
}

row_type! {
    /// A flexible run's rotor at mid-span: the shaft's node nearest the middle between its two
    /// touchdown-bearing nodes (MODEL.md §13.6), where the first bending mode's deflection is
    /// largest; the rigid rotors have no such columns.
    Mid, MidColumns, "" {
        mid_dx_m: "Rotor x at mid-span relative to the housing (m), flexible rotor.",
        mid_dy_m: "Rotor y at mid-span relative to the housing (m), flexible rotor.",
    }
}

impl Coils {
    /// Sets axis `axis`'s (0: x, 1: y) current (A) and voltage (V).
    pub fn set_axis(&mut self, axis: usize, current: f64, voltage: f64) {
        if axis == 0 {
            (self.ix_coil_a, self.vx_coil_v) = (current, voltage);
        } else {
            (self.iy_coil_a, self.vy_coil_v) = (current, voltage);
        }
    }
}

impl Magnets {
    /// Sets axis `axis`'s (0: x, 1: y) magnets' currents (A) and voltages (V), each `[+, −]`.
    pub fn set_axis(&mut self, axis: usize, current: [f64; 2], voltage: [f64; 2]) {
        if axis == 0 {
            [self.ix_plus_a, self.ix_minus_a] = current;
            [self.vx_plus_v, self.vx_minus_v] = voltage;
        } else {
            [self.iy_plus_a, self.iy_minus_a] = current;
            [self.vy_plus_v, self.vy_minus_v] = voltage;
        }
    }
}

/// The names of `parts`, one after the other, as an array of `N` (a compile error when `N` is
/// not their count): the composite rows' headers are built from their parts' names at compile
/// time, so that no list of names is written twice.
const fn concat<const N: usize>(parts: &[&[&'static str]]) -> [&'static str; N] {
    let mut out = [""; N];
    let (mut k, mut i) = (0, 0);
    while i < parts.len() {
        let mut j = 0;
        while j < parts[i].len() {
            out[k] = parts[i][j];
            k += 1;
            j += 1;
        }
        i += 1;
    }
    assert!(k == N, "a composite row's width is not the sum of its parts'");
    out
}

/// The time column's name.
pub const TIME: &str = "t_s";

/// One output sample of one bearing plane (the planar model's whole sample): the time, the
/// plane's motion, the spin, the plane's loads and the housing, in this order in `trace.csv`.
/// A two-plane sample's plane B is seen as such a row too ([`Record::plane`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Row {
    /// Time (s): `t_s`.
    pub t_s: f64,
    /// The rotor's and the race's motion at the plane.
    pub motion: Motion,
    /// The rotor's spin.
    pub spin: Spin,
    /// The race's spin and the loads at the plane.
    pub loads: Loads,
    /// The housing.
    pub housing: Housing,
}

const ROW_NAMES: [&str; 19] = concat(&[&[TIME], Motion::NAMES, Spin::NAMES, Loads::NAMES, Housing::NAMES]);

impl Columns for Row {
    const NAMES: &'static [&'static str] = &ROW_NAMES;
    /// A plane's row has no B names: plane B's own columns are [`RowB`]'s.
    const B_NAMES: &'static [&'static str] = &ROW_NAMES;
    const NAN: Self =
        Self { t_s: f64::NAN, motion: Motion::NAN, spin: Spin::NAN, loads: Loads::NAN, housing: Housing::NAN };

    fn put(&self, out: &mut dyn FnMut(f64)) {
        out(self.t_s);
        self.motion.put(out);
        self.spin.put(out);
        self.loads.put(out);
        self.housing.put(out);
    }

    fn take(next: &mut dyn FnMut() -> f64) -> Self {
        let t_s = next();
        let motion = Motion::take(next);
        let spin = Spin::take(next);
        let loads = Loads::take(next);
        let housing = Housing::take(next);
        Self { t_s, motion, spin, loads, housing }
    }
}

impl Row {
    /// The rotor's radius relative to the housing (m): hypot(`dx_m`, `dy_m`).
    pub fn radius(&self) -> f64 {
        self.motion.dx_m.hypot(self.motion.dy_m)
    }
}

/// A two-plane sample's plane B and tilt, after the planar columns in `trace.csv`: plane B's
/// motion and loads (plane A's names with the prefix `b_`), then the tilt.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RowB {
    /// The motion at plane B.
    pub motion: Motion,
    /// The loads at plane B.
    pub loads: Loads,
    /// The tilt of the rotor's axis.
    pub tilt: Tilt,
}

const ROW_B_NAMES: [&str; 18] = concat(&[Motion::B_NAMES, Loads::B_NAMES, Tilt::NAMES]);

impl Columns for RowB {
    const NAMES: &'static [&'static str] = &ROW_B_NAMES;
    const B_NAMES: &'static [&'static str] = &ROW_B_NAMES;
    const NAN: Self = Self { motion: Motion::NAN, loads: Loads::NAN, tilt: Tilt::NAN };

    fn put(&self, out: &mut dyn FnMut(f64)) {
        self.motion.put(out);
        self.loads.put(out);
        self.tilt.put(out);
    }

    fn take(next: &mut dyn FnMut() -> f64) -> Self {
        let motion = Motion::take(next);
        let loads = Loads::take(next);
        let tilt = Tilt::take(next);
        Self { motion, loads, tilt }
    }
}

/// One bearing plane's row of a two-bearing sample: its motion and its loads.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PlaneValues {
    /// The rotor's and the race's motion at the plane.
    pub motion: Motion,
    /// The race's spin and the loads at the plane.
    pub loads: Loads,
}

/// Each plane's row of a per-plane group (coils, magnets): plane A's, then plane B's (its
/// names with the prefix `b_`); a planar run writes plane A's only.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PerPlane<R> {
    /// Plane A's (then plane B's).
    pub planes: [R; 2],
}

impl<R: Columns> PerPlane<R> {
    /// Every value `NaN`.
    pub const NAN: Self = Self { planes: [R::NAN; 2] };

    /// The names of the first `planes` planes' columns.
    pub fn names(planes: usize) -> impl Iterator<Item = &'static str> {
        [R::NAMES, R::B_NAMES].into_iter().take(planes).flatten().copied()
    }
}

/// A sample's coils (runs with amplifiers): [`Coils`] per plane.
pub type RowHw = PerPlane<Coils>;

/// A sample's magnets (runs with unipolar amplifiers): [`Magnets`] per plane.
pub type RowMagnets = PerPlane<Magnets>;

/// A flexible sample's rotor at mid-span.
pub type RowMid = Mid;

/// Number of columns of a [`Row`] (the planar model's; plane A's and the shared ones).
pub const WIDTH: usize = Row::WIDTH;
/// Number of plane B and tilt columns of a two-plane trace.
pub const WIDTH_B: usize = RowB::WIDTH;
/// Number of coil columns (both planes').
pub const WIDTH_HW: usize = 2 * Coils::WIDTH;
/// Number of magnet columns (both planes').
pub const WIDTH_MAGNETS: usize = 2 * Magnets::WIDTH;
/// Number of mid-span columns.
pub const WIDTH_MID: usize = Mid::WIDTH;

/// One output sample: the planar columns (plane A's and the shared ones) and, for a two-plane
/// rotor, plane B's and the tilt's; the coils, magnets and mid-span where the run has them.
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

    /// The sample's time (s).
    pub fn t_s(&self) -> f64 {
        self.a.t_s
    }

    /// Bearing planes in the sample: 1 (planar) or 2.
    pub fn planes(&self) -> usize {
        1 + usize::from(self.b.is_some())
    }

    /// Plane `i`'s sample as a planar row (0: plane A, the planar columns; 1: plane B's
    /// motion and loads with the shared ones: time, spin, housing).
    pub fn plane(&self, i: usize) -> Row {
        match (i, &self.b) {
            (1, Some(b)) => Row { motion: b.motion, loads: b.loads, ..self.a },
            _ => self.a,
        }
    }

    /// The slopes (a, b) of the rotor axis (rad), two-plane samples.
    pub fn slopes(&self) -> Option<[f64; 2]> {
        self.b.map(|b| [b.tilt.slope_x_rad, b.tilt.slope_y_rad])
    }
}

/// Which columns a run's `trace.csv` has, and their order: the planar ones, plane B's and the
/// tilt's (two planes), the coils' (amplifiers, per plane), the magnets' (unipolar amplifiers,
/// per plane), the mid-span's (a bending rotor).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Bearing planes: 1 or 2.
    pub planes: usize,
    /// The coils' columns (a run with amplifiers).
    pub coils: bool,
    /// The magnets' columns (a run with unipolar amplifiers).
    pub magnets: bool,
    /// The mid-span's columns (a flexible run).
    pub mid: bool,
}

impl Layout {
    /// The columns' names, in order.
    pub fn names(&self) -> Vec<&'static str> {
        let mut names: Vec<&'static str> = Row::NAMES.to_vec();
        if self.planes == 2 {
            names.extend(RowB::NAMES);
        }
        if self.coils {
            names.extend(RowHw::names(self.planes));
        }
        if self.magnets {
            names.extend(RowMagnets::names(self.planes));
        }
        if self.mid {
            names.extend(Mid::NAMES);
        }
        names
    }

    /// A sample's values of these columns, in order, to `out`; what the sample does not hold is
    /// `NaN`.
    pub fn put(&self, r: &Record, out: &mut dyn FnMut(f64)) {
        r.a.put(out);
        if self.planes == 2 {
            r.b.unwrap_or(RowB::NAN).put(out);
        }
        if self.coils {
            let hw = r.hw.unwrap_or(RowHw::NAN);
            hw.planes[..self.planes].iter().for_each(|c| c.put(out));
        }
        if self.magnets {
            let m = r.magnets.unwrap_or(RowMagnets::NAN);
            m.planes[..self.planes].iter().for_each(|c| c.put(out));
        }
        if self.mid {
            r.mid.unwrap_or(Mid::NAN).put(out);
        }
    }
}

/// The planar model's sample of the state `y` at time `t`, with the forces the model gives there.
pub fn row(model: &Model, t: f64, y: &State) -> Row {
    let ev = model.evaluate(t, y);
    let housing = model.base.eval(t);
    Row {
        t_s: t,
        motion: Motion {
            dx_m: y[ix::XR],
            dy_m: y[ix::YR],
            vx_m_s: y[ix::VXR],
            vy_m_s: y[ix::VYR],
            xb_m: y[ix::XB],
            yb_m: y[ix::YB],
            vxb_m_s: y[ix::VXB],
            vyb_m_s: y[ix::VYB],
        },
        spin: Spin { rotor_angle_rad: y[ix::TR], rotor_speed_rad_s: y[ix::WR] },
        loads: Loads {
            race_speed_rad_s: y[ix::WB],
            contact_force_n: ev.contact.normal,
            friction_force_n: ev.contact.tangential,
            ball_force_n: ev.balls.on_race[0].hypot(ev.balls.on_race[1]),
            ix_a: ev.current[0],
            iy_a: ev.current[1],
        },
        housing: Housing { housing_x_m: housing.disp[0], housing_y_m: housing.disp[1] },
    }
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

/// One bearing plane's [`PlaneValues`]: the rotor's position and velocity at the plane, the
/// race's state `[x, y, ẋ, ẏ, ω]`, and what the model evaluated there.
pub fn plane_values(pos: [f64; 2], vel: [f64; 2], race: [f64; 5], p: &two_plane::PlaneEvaluation) -> PlaneValues {
    PlaneValues {
        motion: Motion {
            dx_m: pos[0],
            dy_m: pos[1],
            vx_m_s: vel[0],
            vy_m_s: vel[1],
            xb_m: race[0],
            yb_m: race[1],
            vxb_m_s: race[2],
            vyb_m_s: race[3],
        },
        loads: Loads {
            race_speed_rad_s: race[4],
            contact_force_n: p.contact.normal,
            friction_force_n: p.contact.tangential,
            ball_force_n: p.balls.on_race[0].hypot(p.balls.on_race[1]),
            ix_a: p.current[0],
            iy_a: p.current[1],
        },
    }
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
    let [a, b] = planes;
    let row = Row {
        t_s: t,
        motion: a.motion,
        spin: Spin { rotor_angle_rad: spin[0], rotor_speed_rad_s: spin[1] },
        loads: a.loads,
        housing: Housing { housing_x_m: housing[0], housing_y_m: housing[1] },
    };
    let [slope_x_rad, slope_y_rad, slope_x_rate_rad_s, slope_y_rate_rad_s] = slopes;
    let tilt = Tilt { slope_x_rad, slope_y_rad, slope_x_rate_rad_s, slope_y_rate_rad_s };
    Record { a: row, b: Some(RowB { motion: b.motion, loads: b.loads, tilt }), hw: None, magnets: None, mid: None }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The row whose k-th value (in `put` order) is k.
    fn counted<R: Columns>() -> R {
        let mut k = 0.0;
        R::take(&mut || {
            k += 1.0;
            k - 1.0
        })
    }

    /// `take` and `put` agree on the order, and each part's values sit under its own names in
    /// the composite's names (the composite's names are in the order its values are written).
    fn check_parts<R: Columns>(parts: &[(&[&str], Vec<f64>)]) {
        let values = counted::<R>().values();
        assert_eq!(values, (0..R::WIDTH).map(|k| k as f64).collect::<Vec<_>>());
        assert_eq!(R::NAMES.len(), R::WIDTH);
        let mut seen = 0;
        for (names, part) in parts {
            assert_eq!(names.len(), part.len());
            for (name, v) in names.iter().zip(part) {
                assert_eq!(R::NAMES[*v as usize], *name);
                seen += 1;
            }
        }
        assert_eq!(seen, R::WIDTH, "every column is some part's");
    }

    #[test]
    fn a_composite_rows_names_are_its_parts_names_in_the_order_its_values_are_written() {
        let r = counted::<Row>();
        assert_eq!(Row::NAMES[r.t_s as usize], "t_s");
        check_parts::<Row>(&[
            (&["t_s"], vec![r.t_s]),
            (Motion::NAMES, r.motion.values()),
            (Spin::NAMES, r.spin.values()),
            (Loads::NAMES, r.loads.values()),
            (Housing::NAMES, r.housing.values()),
        ]);
        let b = counted::<RowB>();
        check_parts::<RowB>(&[
            (Motion::B_NAMES, b.motion.values()),
            (Loads::B_NAMES, b.loads.values()),
            (Tilt::NAMES, b.tilt.values()),
        ]);
    }

    #[test]
    fn plane_b_is_plane_a_with_the_prefix_and_a_plane_b_row_reads_as_a_planar_row() {
        for (a, b) in Motion::NAMES.iter().zip(Motion::B_NAMES).chain(Loads::NAMES.iter().zip(Loads::B_NAMES)) {
            assert_eq!(format!("b_{a}"), *b);
        }
        let a = counted::<Row>();
        let mut b = counted::<RowB>();
        b.motion.dx_m = -1.0;
        b.loads.iy_a = -2.0;
        let r = Record { a, b: Some(b), hw: None, magnets: None, mid: None };
        let p = r.plane(1);
        assert_eq!((p.t_s, p.spin, p.housing), (a.t_s, a.spin, a.housing));
        assert_eq!((p.motion, p.loads), (b.motion, b.loads));
        assert_eq!(r.plane(0), a);
        assert_eq!(r.slopes(), Some([b.tilt.slope_x_rad, b.tilt.slope_y_rad]));
    }

    /// The layout's names and values line up: each value written is the one under its name,
    /// for every combination of the optional groups; what the sample lacks is NaN.
    #[test]
    fn a_layouts_values_sit_under_their_names() {
        let a = Row { t_s: 0.5, ..counted::<Row>() };
        let mut hw = RowHw::NAN;
        hw.planes[1].vy_coil_v = 7.0;
        hw.planes[0].ix_coil_a = 3.0;
        let record =
            Record { a, b: None, hw: Some(hw), magnets: None, mid: Some(Mid { mid_dx_m: 1.0, mid_dy_m: 2.0 }) };
        for planes in [1, 2] {
            for bits in 0..8 {
                let layout = Layout { planes, coils: bits & 1 != 0, magnets: bits & 2 != 0, mid: bits & 4 != 0 };
                let names = layout.names();
                let mut values = Vec::new();
                layout.put(&record, &mut |v| values.push(v));
                assert_eq!(names.len(), values.len(), "{layout:?}");
                let at = |n: &str| names.iter().position(|x| *x == n).map(|i| values[i]);
                assert_eq!(at("t_s"), Some(0.5));
                assert_eq!(at("rotor_speed_rad_s"), Some(a.spin.rotor_speed_rad_s));
                assert_eq!(at("housing_y_m"), Some(a.housing.housing_y_m));
                assert_eq!(at("ix_coil_a"), layout.coils.then_some(3.0));
                assert_eq!(at("b_vy_coil_v"), (layout.coils && planes == 2).then_some(7.0));
                assert_eq!(at("mid_dy_m"), layout.mid.then_some(2.0));
                assert!(at("b_dx_m").map_or(planes == 1, f64::is_nan), "{layout:?}");
                assert!(at("ix_minus_a").map_or(!layout.magnets, f64::is_nan), "{layout:?}");
                let unique: std::collections::BTreeSet<_> = names.iter().collect();
                assert_eq!(unique.len(), names.len(), "{layout:?}: a column named twice");
            }
        }
    }
}
