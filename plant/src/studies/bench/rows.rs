//! The tables the benches write and read, one row type each: its fields are
//! the columns, in order (docs/results/speed-accuracy.md lists them; scripts read them by name).
//! Written and read through [`crate::table`]; numbers in `{:e}` as they
//! always were.
//!
//! | file | row |
//! |---|---|
//! | `accuracy.csv` (and the scipy peer's `peer_<scene>.csv`) | [`AccuracyRow`] |
//! | `stability.csv` | [`StabilityRow`] |
//! | `reference_<scene>.csv` (read by the peer) | [`ReferenceRow`] |
//! | `models.csv` | [`ModelRow`] |
//! | `models_flexible.csv` | [`MachineRow`] |
//! | `engineering.csv` | [`EngineeringRow`] |

use super::IntegratorSetting;
use crate::table::{sci, sci_or_empty};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Header of `accuracy.csv`, shared with the scipy peer's `peer.csv` (`bench/peer/run_peer.py`).
pub const ACCURACY_HEADER: &str = AccuracyRow::HEADER;

/// One row of `accuracy.csv`: one implementation, method and setting on one scene.
///
/// How a run of the accuracy bench ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AccuracyStatus {
    /// Completed with a finite error.
    Ok,
    /// A Rust run that did not complete, or whose error is not finite.
    Diverged,
    /// A peer run that failed (solve_ivp's status, non-finite values, or its time limit).
    Failed,
}

impl std::fmt::Display for AccuracyStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(crate::summary::snake_name(self).as_str())
    }
}

crate::table::table_row! {
/// The peer's rows are read by column name; a peer run that failed leaves its error columns
/// (and possibly `rhs_evals`, `sim_s`) empty: `None` here, empty again when written.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AccuracyRow {
    /// Scene name (`levitation`, `impact`, `rub`).
    pub scene: String,
    /// `rust`, `rust parked` or a peer (`scipy`).
    pub implementation: String,
    /// Method name.
    pub method: String,
    /// The setting as text (`rtol=1e-6`, `substeps=4`; the peer adds its atol).
    pub setting: String,
    /// Relative tolerance (adaptive methods).
    #[serde(with = "sci_or_empty")]
    pub rtol: Option<f64>,
    /// Substeps per controller period (fixed-step methods).
    pub substeps: Option<u32>,
    /// `ok`, `diverged` (Rust) or `failed` (peer).
    pub status: AccuracyStatus,
    /// RMS scaled error (infinite for a run that did not complete).
    #[serde(with = "sci_or_empty")]
    pub err_rms: Option<f64>,
    /// Max scaled error.
    #[serde(with = "sci_or_empty")]
    pub err_max: Option<f64>,
    /// Wall seconds per simulated second.
    #[serde(with = "sci")]
    pub wall_s_per_sim_s: f64,
    /// Right-hand-side evaluations.
    pub rhs_evals: Option<u64>,
    /// Simulated seconds.
    #[serde(with = "sci_or_empty")]
    pub sim_s: Option<f64>,
}
}

impl AccuracyRow {
    /// The `setting`, `rtol` and `substeps` columns of an integrator setting.
    pub fn setting_columns(setting: IntegratorSetting) -> (String, Option<f64>, Option<u32>) {
        match setting {
            IntegratorSetting::Rtol(r) => (setting.to_string(), Some(r), None),
            IntegratorSetting::Substeps(n) => (setting.to_string(), None, Some(n)),
        }
    }

    /// The RMS error, infinite where there is none (a failed run).
    pub fn rms(&self) -> f64 {
        self.err_rms.unwrap_or(f64::INFINITY)
    }
}

/// Writes rows as `accuracy.csv`.
pub fn write_accuracy(path: &Path, rows: &[AccuracyRow]) -> anyhow::Result<()> {
    crate::table::write_with_header(path, ACCURACY_HEADER, rows)
}

/// Reads the rows of an `accuracy.csv` or of the peer's CSV, by column name.
pub fn read_accuracy(path: &Path) -> anyhow::Result<Vec<AccuracyRow>> {
    crate::table::read(path)
}

/// Header of `stability.csv`.
pub const STABILITY_HEADER: &str = StabilityRow::HEADER;

crate::table::table_row! {
/// One row of `stability.csv`: the stability of one fixed-step method on one scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StabilityRow {
    /// Scene.
    pub scene: String,
    /// Method.
    pub method: String,
    /// The largest stable step found (s); none up to 4096 substeps.
    #[serde(with = "sci_or_empty")]
    pub largest_stable_step_s: Option<f64>,
    /// Its substeps per controller period.
    pub substeps: Option<u32>,
    /// The step the stability estimate gives (s).
    #[serde(with = "sci")]
    pub estimated_step_s: f64,
}
}

crate::table::table_row! {
/// One row of `reference_<scene>.csv`: the reference rotor position over the error window,
/// on the tick grid (the scipy peer reads it by column name).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReferenceRow {
    /// Time (s).
    #[serde(with = "sci")]
    pub t_s: f64,
    /// Rotor x relative to the housing (m).
    #[serde(with = "sci")]
    pub dx_m: f64,
    /// Rotor y relative to the housing (m).
    #[serde(with = "sci")]
    pub dy_m: f64,
}
}

/// Header of `reference_<scene>.csv`.
pub const REFERENCE_HEADER: &str = ReferenceRow::HEADER;

/// Header of `models.csv`.
pub const MODELS_HEADER: &str = ModelRow::HEADER;

crate::table::table_row! {
/// One row of `models.csv`: one model variant on one scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelRow {
    /// Scene.
    pub scene: String,
    /// Variant name (`full` for the detailed model).
    pub variant: String,
    /// Scaled error against the full model over the window: RMS.
    #[serde(with = "sci")]
    pub err_rms: f64,
    /// Max.
    #[serde(with = "sci")]
    pub err_max: f64,
    /// Wall seconds per simulated second with the scene's integrator.
    #[serde(with = "sci")]
    pub wall_s_per_sim_s: f64,
    /// Speed-up over the full model (four decimals).
    #[serde(serialize_with = "four_decimals", deserialize_with = "sci::deserialize")]
    pub speedup: f64,
}
}

fn four_decimals<S: serde::Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
    s.collect_str(&format_args!("{v:.4}"))
}

/// Header of `models_flexible.csv`.
pub const MACHINE_HEADER: &str = MachineRow::HEADER;

crate::table::table_row! {
/// One row of `models_flexible.csv`: one touchdown bearing of one model of the shipped flexible
/// machine (the flexible rotor, or the rigid two-plane rotor of its rigid body), from its run
/// of the whole scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MachineRow {
    /// Scene.
    pub scene: String,
    /// `flexible` or `rigid two-plane`.
    pub model: String,
    /// `a` or `b`.
    pub plane: String,
    /// Peak rotor – race normal force (N).
    #[serde(with = "sci_or_empty")]
    pub peak_contact_force_n: Option<f64>,
    /// Time in contact over the run (s).
    #[serde(with = "sci")]
    pub contact_time_s: f64,
    /// Fraction of samples in contact over the steady window.
    #[serde(with = "sci")]
    pub contact_fraction: f64,
    /// Friction energy dissipated at the rotor – race contact over the run (J).
    #[serde(with = "sci")]
    pub friction_energy_j: f64,
    /// From the shock's start to the last sample in contact (s); empty if still touching.
    #[serde(with = "sci_or_empty")]
    pub recovery_s: Option<f64>,
    /// Largest rotor radius at the touchdown bearing (m).
    #[serde(with = "sci_or_empty")]
    pub max_radius_m: Option<f64>,
    /// First sample in contact (s); empty if the plane never touched.
    #[serde(with = "sci_or_empty")]
    pub first_contact_s: Option<f64>,
    /// Post-shock mode of the plane.
    pub post_shock_mode: crate::analysis::classify::MotionMode,
    /// Scaled error of the plane's motion against the flexible rotor's over the window: RMS.
    #[serde(with = "sci")]
    pub err_rms: f64,
    /// Max.
    #[serde(with = "sci")]
    pub err_max: f64,
    /// Wall seconds per simulated second with the scene's integrator (the whole machine).
    #[serde(with = "sci")]
    pub wall_s_per_sim_s: f64,
    /// Speed-up over the flexible rotor (four decimals).
    #[serde(serialize_with = "four_decimals", deserialize_with = "sci::deserialize")]
    pub speedup: f64,
}
}

/// Header of `engineering.csv`.
pub const ENGINEERING_HEADER: &str = EngineeringRow::HEADER;

crate::table::table_row! {
/// One row of `engineering.csv`: one run's figures and their differences from the scene's
/// reference run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EngineeringRow {
    /// Scene.
    pub scene: String,
    /// What ran (method, setting, model).
    pub setting: String,
    /// `completed` or `diverged`.
    pub status: crate::status::Status,
    /// Peak contact force (N).
    #[serde(with = "sci")]
    pub peak_contact_force_n: f64,
    /// Largest rotor radius (m).
    #[serde(with = "sci")]
    pub max_radius_m: f64,
    /// Contact fraction over the last 200 revolutions.
    #[serde(with = "sci")]
    pub contact_fraction: f64,
    /// Post-shock mode.
    pub post_shock_mode: crate::analysis::classify::MotionMode,
    /// Steady class of the end of the run.
    pub steady_class: crate::analysis::classify::SteadyClass,
    /// Wall seconds per simulated second (fastest of the repeats).
    #[serde(with = "sci")]
    pub wall_s_per_sim_s: f64,
    /// (peak force − reference's) / reference's.
    #[serde(with = "sci")]
    pub peak_force_rel_diff: f64,
    /// (max radius − reference's) / reference's.
    #[serde(with = "sci")]
    pub max_radius_rel_diff: f64,
    /// Contact fraction − reference's.
    #[serde(with = "sci")]
    pub contact_fraction_diff: f64,
    /// Same post-shock mode and steady class as the reference.
    pub same_mode: bool,
}
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each row type's columns are its header, in order (the header constants are what the
    /// guide, the peer and any script were promised).
    #[test]
    fn the_row_types_write_their_promised_headers() {
        let acc = AccuracyRow {
            scene: "s".into(),
            implementation: "rust".into(),
            method: "dp5".into(),
            setting: "rtol=1e-4".into(),
            rtol: Some(1e-4),
            substeps: None,
            status: AccuracyStatus::Ok,
            err_rms: Some(1.0),
            err_max: Some(f64::INFINITY),
            wall_s_per_sim_s: 0.5,
            rhs_evals: Some(12),
            sim_s: Some(0.07),
        };
        let text = |b: Vec<u8>| String::from_utf8(b).unwrap();
        assert_eq!(
            text(crate::table::to_bytes(&[acc]).unwrap()),
            format!("{ACCURACY_HEADER}\ns,rust,dp5,rtol=1e-4,1e-4,,ok,1e0,inf,5e-1,12,7e-2\n")
        );
        let st = StabilityRow {
            scene: "rub".into(),
            method: "rk4".into(),
            largest_stable_step_s: None,
            substeps: None,
            estimated_step_s: 2.5e-6,
        };
        assert_eq!(text(crate::table::to_bytes(&[st]).unwrap()), format!("{STABILITY_HEADER}\nrub,rk4,,,2.5e-6\n"));
        let m = ModelRow {
            scene: "rub".into(),
            variant: "full".into(),
            err_rms: 0.0,
            err_max: 0.0,
            wall_s_per_sim_s: 3.8e-2,
            speedup: 1.0,
        };
        assert_eq!(
            text(crate::table::to_bytes(&[m]).unwrap()),
            format!("{MODELS_HEADER}\nrub,full,0e0,0e0,3.8e-2,1.0000\n")
        );
        let fx = MachineRow {
            scene: "flexible-10g".into(),
            model: "rigid two-plane".into(),
            plane: "b".into(),
            peak_contact_force_n: Some(7514.0),
            contact_time_s: 0.24,
            contact_fraction: 0.8,
            friction_energy_j: 42.5,
            recovery_s: None,
            max_radius_m: Some(2.1e-4),
            first_contact_s: Some(0.0226),
            post_shock_mode: crate::analysis::classify::MotionMode::Rebound,
            err_rms: 1.7,
            err_max: 2.5,
            wall_s_per_sim_s: 0.5,
            speedup: 1.75,
        };
        assert_eq!(
            text(crate::table::to_bytes(&[fx]).unwrap()),
            format!(
                "{MACHINE_HEADER}\nflexible-10g,rigid two-plane,b,7.514e3,2.4e-1,8e-1,4.25e1,,2.1e-4,2.26e-2,rebound,1.7e0,2.5e0,5e-1,1.7500\n"
            )
        );
        let r = ReferenceRow { t_s: 0.02, dx_m: -1e-6, dy_m: 0.0 };
        assert_eq!(text(crate::table::to_bytes(&[r]).unwrap()), format!("{REFERENCE_HEADER}\n2e-2,-1e-6,0e0\n"));
        let e = EngineeringRow {
            scene: "impact".into(),
            setting: "rk4 substeps=4".into(),
            status: crate::status::Status::Completed,
            peak_contact_force_n: 1724.5,
            max_radius_m: 1.79e-4,
            contact_fraction: 0.0,
            post_shock_mode: crate::analysis::classify::MotionMode::Recovered,
            steady_class: crate::analysis::classify::SteadyClass::Periodic,
            wall_s_per_sim_s: 0.25,
            peak_force_rel_diff: -1e-3,
            max_radius_rel_diff: 0.0,
            contact_fraction_diff: 0.0,
            same_mode: true,
        };
        assert_eq!(
            text(crate::table::to_bytes(&[e]).unwrap()),
            format!(
                "{ENGINEERING_HEADER}\nimpact,rk4 substeps=4,completed,1.7245e3,1.79e-4,0e0,recovered,periodic,2.5e-1,-1e-3,0e0,0e0,true\n"
            )
        );
    }

    /// The scipy peer's rows as `run_peer.py` writes them (`csv.DictWriter`, Python's float
    /// text, a failed run with empty error columns), in another column order than ours: read by
    /// name, not position.
    #[test]
    fn peer_rows_are_read_by_column_name() {
        let dir = std::env::temp_dir().join(format!("bench-rows-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("peer.csv");
        std::fs::write(
            &path,
            "implementation,scene,method,setting,rtol,substeps,status,err_rms,err_max,wall_s_per_sim_s,rhs_evals,sim_s,note\n\
             scipy,rub,RK45,rtol=1e-6 atol=rtol*scale,1e-6,,ok,0.000123,0.0005,0.75,1892,0.07,x\n\
             scipy,rub,LSODA,rtol=1e-3 atol=1e-9,1e-3,,failed,,,600.0,,,\n",
        )
        .unwrap();
        let rows = read_accuracy(&path).unwrap();
        assert_eq!(rows.len(), 2);
        let (ok, failed) = (&rows[0], &rows[1]);
        assert_eq!((ok.scene.as_str(), ok.implementation.as_str(), ok.method.as_str()), ("rub", "scipy", "RK45"));
        assert_eq!(ok.setting, "rtol=1e-6 atol=rtol*scale");
        assert_eq!((ok.rtol, ok.substeps), (Some(1e-6), None));
        assert_eq!((ok.err_rms, ok.err_max, ok.wall_s_per_sim_s), (Some(1.23e-4), Some(5e-4), 0.75));
        assert_eq!((ok.rhs_evals, ok.sim_s), (Some(1892), Some(0.07)));
        assert_eq!(failed.status, AccuracyStatus::Failed);
        assert_eq!((failed.err_rms, failed.err_max, failed.rhs_evals, failed.sim_s), (None, None, None, None));
        assert_eq!(failed.rms(), f64::INFINITY);
        // Written back: our columns and order, the failed run's empty fields kept empty.
        let out = dir.join("accuracy.csv");
        write_accuracy(&out, &rows).unwrap();
        let text = std::fs::read_to_string(&out).unwrap();
        assert_eq!(
            text,
            format!(
                "{ACCURACY_HEADER}\nrub,scipy,RK45,rtol=1e-6 atol=rtol*scale,1e-6,,ok,1.23e-4,5e-4,7.5e-1,1892,7e-2\n\
                 rub,scipy,LSODA,rtol=1e-3 atol=1e-9,1e-3,,failed,,,6e2,,\n"
            )
        );
        assert_eq!(read_accuracy(&out).unwrap(), rows);
        // A column missing is named.
        std::fs::write(&path, "scene,implementation,method\nrub,scipy,RK45\n").unwrap();
        let err = format!("{:#}", read_accuracy(&path).unwrap_err());
        assert!(err.contains("peer.csv") && err.contains("missing field `setting`"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The shipped tables of `docs/charts/` (written by earlier full runs of the benches, with
    /// scipy rows in `accuracy.csv`) read, and write back byte for byte: the formats did not
    /// change.
    #[test]
    fn the_shipped_tables_read_and_write_back_unchanged() {
        fn round_trip<T: serde::de::DeserializeOwned + Serialize>(file: &str, header: &str) -> Vec<T> {
            let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/charts").join(file);
            let rows: Vec<T> = crate::table::read(&path).unwrap();
            assert!(!rows.is_empty(), "{file}");
            let bytes = crate::table::to_bytes_with_header(header, &rows).unwrap();
            assert!(bytes == std::fs::read(&path).unwrap(), "docs/charts/{file} does not round-trip");
            rows
        }
        let acc: Vec<AccuracyRow> = round_trip("accuracy.csv", ACCURACY_HEADER);
        assert!(acc.iter().any(|r| r.implementation == "scipy") && acc.iter().any(|r| r.implementation == "rust"));
        round_trip::<StabilityRow>("stability.csv", STABILITY_HEADER);
        round_trip::<ModelRow>("models.csv", MODELS_HEADER);
        let fx: Vec<MachineRow> = round_trip("models_flexible.csv", MACHINE_HEADER);
        assert_eq!(fx.len(), 4);
        round_trip::<EngineeringRow>("engineering.csv", ENGINEERING_HEADER);
    }
}
