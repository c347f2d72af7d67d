//! The recorded time series of a run, columnar, written as `trace.csv`.

use crate::model::{ix, Model, State};
use std::io::Write;
use std::path::Path;

macro_rules! columns {
    ($($field:ident : $doc:literal),* $(,)?) => {
        /// Trace columns; each is one CSV column named like the field.
        #[derive(Clone, Debug, Default)]
        pub struct Trace { $(#[doc = $doc] pub $field: Vec<f64>,)* }

        impl Trace {
            /// CSV header names, in order.
            pub const COLUMNS: &'static [&'static str] = &[$(stringify!($field)),*];

            /// An empty trace with room for `n` rows.
            pub fn with_capacity(n: usize) -> Self {
                Self { $($field: Vec::with_capacity(n),)* }
            }

            fn columns(&self) -> Vec<&[f64]> {
                vec![$(&self.$field),*]
            }

            fn columns_mut(&mut self) -> Vec<&mut Vec<f64>> {
                vec![$(&mut self.$field),*]
            }
        }
    };
}

columns! {
    t_s: "Time (s).",
    dx_m: "Rotor x relative to the housing (m).",
    dy_m: "Rotor y relative to the housing (m).",
    vx_m_s: "Rotor x velocity relative to the housing (m/s).",
    vy_m_s: "Rotor y velocity relative to the housing (m/s).",
    xb_m: "Race x relative to the housing (m).",
    yb_m: "Race y relative to the housing (m).",
    vxb_m_s: "Race x velocity relative to the housing (m/s).",
    vyb_m_s: "Race y velocity relative to the housing (m/s).",
    rotor_angle_rad: "Rotor spin angle (rad).",
    rotor_speed_rad_s: "Rotor spin speed (rad/s).",
    race_speed_rad_s: "Race spin speed (rad/s).",
    contact_force_n: "Rotor – race normal force (N).",
    friction_force_n: "Rotor – race friction force (N), signed like the slip.",
    ball_force_n: "Resultant of the ball forces on the race (N).",
    ix_a: "Coil current, x (A).",
    iy_a: "Coil current, y (A).",
    housing_x_m: "Housing displacement, x (m).",
    housing_y_m: "Housing displacement, y (m).",
}

impl Trace {
    /// Number of rows.
    pub fn len(&self) -> usize {
        self.t_s.len()
    }

    /// True when no row was recorded.
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }

    /// Records the state at time `t`, with the forces the model gives there.
    pub fn push(&mut self, model: &Model, t: f64, y: &State) {
        let ev = model.evaluate(t, y);
        let housing = model.base.eval(t);
        self.t_s.push(t);
        self.dx_m.push(y[ix::XR]);
        self.dy_m.push(y[ix::YR]);
        self.vx_m_s.push(y[ix::VXR]);
        self.vy_m_s.push(y[ix::VYR]);
        self.xb_m.push(y[ix::XB]);
        self.yb_m.push(y[ix::YB]);
        self.vxb_m_s.push(y[ix::VXB]);
        self.vyb_m_s.push(y[ix::VYB]);
        self.rotor_angle_rad.push(y[ix::TR]);
        self.rotor_speed_rad_s.push(y[ix::WR]);
        self.race_speed_rad_s.push(y[ix::WB]);
        self.contact_force_n.push(ev.contact.normal);
        self.friction_force_n.push(ev.contact.tangential);
        self.ball_force_n.push(ev.balls.on_race[0].hypot(ev.balls.on_race[1]));
        self.ix_a.push(ev.current[0]);
        self.iy_a.push(ev.current[1]);
        self.housing_x_m.push(housing.disp[0]);
        self.housing_y_m.push(housing.disp[1]);
    }

    /// Rotor radius relative to the housing at each row (m).
    pub fn radius(&self) -> Vec<f64> {
        self.dx_m.iter().zip(&self.dy_m).map(|(x, y)| x.hypot(*y)).collect()
    }

    /// Writes the trace as CSV with a header row (full precision).
    pub fn write_csv(&self, path: &Path) -> std::io::Result<()> {
        let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
        writeln!(w, "{}", Self::COLUMNS.join(","))?;
        let cols = self.columns();
        let mut line = String::with_capacity(32 * cols.len());
        for row in 0..self.len() {
            line.clear();
            for (c, col) in cols.iter().enumerate() {
                if c > 0 {
                    line.push(',');
                }
                use std::fmt::Write as _;
                let _ = write!(line, "{:e}", col[row]);
            }
            line.push('\n');
            w.write_all(line.as_bytes())?;
        }
        w.flush()
    }

    /// Reads a trace written by [`Trace::write_csv`] (extra columns are ignored).
    pub fn read_csv(path: &Path) -> Result<Self, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().ok_or("empty trace file")?.split(',').collect();
        let mut trace = Trace::default();
        let index: Vec<Option<usize>> =
            Self::COLUMNS.iter().map(|name| header.iter().position(|h| h.trim() == *name)).collect();
        for (n, line) in lines.enumerate() {
            let values: Result<Vec<f64>, _> = line.split(',').map(|v| v.trim().parse::<f64>()).collect();
            let values = values.map_err(|e| format!("{} line {}: {e}", path.display(), n + 2))?;
            let mut cols = trace.columns_mut();
            for (col, idx) in cols.iter_mut().zip(&index) {
                let value = idx.and_then(|i| values.get(i).copied()).unwrap_or(f64::NAN);
                col.push(value);
            }
        }
        Ok(trace)
    }
}
