//! The output's columns come from the row types (issue 41 item 3): every header is derived
//! from a type's fields and is the header the files have always had; a row written and read
//! back is the same value; no header constant in `plant/src` is a hand-written list.
//!
//! The expected headers below are the files as shipped before the typed rows (the first line
//! of each kind of `trace.csv` of `scripts/identity/run.sh`'s baseline, the literal constants
//! of commit dc05da1): independent of the code that now derives them.

use plant::trace::{read_rows, Columns, Layout, Mid, Record, Row, RowB, RowHw, RowMagnets, Trace, TraceWriter};
use std::path::{Path, PathBuf};

const PLANAR: &str = "t_s,dx_m,dy_m,vx_m_s,vy_m_s,xb_m,yb_m,vxb_m_s,vyb_m_s,rotor_angle_rad,rotor_speed_rad_s,\
race_speed_rad_s,contact_force_n,friction_force_n,ball_force_n,ix_a,iy_a,housing_x_m,housing_y_m";
const PLANE_B: &str = "b_dx_m,b_dy_m,b_vx_m_s,b_vy_m_s,b_xb_m,b_yb_m,b_vxb_m_s,b_vyb_m_s,b_race_speed_rad_s,\
b_contact_force_n,b_friction_force_n,b_ball_force_n,b_ix_a,b_iy_a,slope_x_rad,slope_y_rad,slope_x_rate_rad_s,\
slope_y_rate_rad_s";
const COILS: &str = "ix_coil_a,iy_coil_a,vx_coil_v,vy_coil_v";
const COILS_B: &str = "b_ix_coil_a,b_iy_coil_a,b_vx_coil_v,b_vy_coil_v";
const MAGNETS: &str = "ix_plus_a,ix_minus_a,iy_plus_a,iy_minus_a,vx_plus_v,vx_minus_v,vy_plus_v,vy_minus_v";
const MAGNETS_B: &str = "b_ix_plus_a,b_ix_minus_a,b_iy_plus_a,b_iy_minus_a,b_vx_plus_v,b_vx_minus_v,b_vy_plus_v,\
b_vy_minus_v";
const MID: &str = "mid_dx_m,mid_dy_m";

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("plant-columns-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir.join("trace.csv")
}

fn header_of(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap().lines().next().unwrap().to_string()
}

#[test]
fn every_trace_layouts_header_is_the_one_shipped() {
    let layout = |planes, coils, magnets, mid| Layout { planes, coils, magnets, mid };
    let cases = [
        (layout(1, false, false, false), vec![PLANAR]),
        (layout(1, true, false, false), vec![PLANAR, COILS]),
        (layout(1, true, true, false), vec![PLANAR, COILS, MAGNETS]),
        (layout(2, false, false, false), vec![PLANAR, PLANE_B]),
        (layout(2, true, true, false), vec![PLANAR, PLANE_B, COILS, COILS_B, MAGNETS, MAGNETS_B]),
        (layout(2, false, false, true), vec![PLANAR, PLANE_B, MID]),
    ];
    for (i, (layout, parts)) in cases.iter().enumerate() {
        let expected = parts.join(",");
        assert_eq!(layout.names().join(","), expected, "{layout:?}");
        // The writer writes that header.
        let path = scratch(&format!("header-{i}"));
        let w = TraceWriter::with_layout(&path, *layout).unwrap();
        drop(w);
        assert_eq!(header_of(&path), expected, "{layout:?}");
        let _ = std::fs::remove_dir_all(path.parent().unwrap());
    }
    assert_eq!(Trace::COLUMNS.join(","), PLANAR);
}

/// A row whose every value differs (and is awkward to print: negative, tiny, huge, not a
/// round decimal), counted from `start`.
fn awkward<R: Columns>(start: usize) -> R {
    let mut k = start;
    R::take(&mut || {
        k += 1;
        (-1.0f64).powi(k as i32) * (k as f64) * std::f64::consts::PI * 10f64.powi(k as i32 % 17 - 8)
    })
}

/// Samples with every group of columns, written through the trace writer and read back through
/// the reader: the same values, bit for bit (the reader reads the planar, plane B, tilt and
/// mid-span columns; the coils and magnets are written for the charts and scripts only).
#[test]
fn a_record_written_and_read_back_is_the_same_value() {
    let path = scratch("roundtrip");
    let layout = Layout { planes: 2, coils: true, magnets: true, mid: true };
    let mut w = TraceWriter::with_layout(&path, layout).unwrap();
    let records: Vec<Record> = (0..4)
        .map(|i| {
            let mut a: Row = awkward(100 * i);
            a.t_s = i as f64 * 5e-5;
            if i == 2 {
                a.loads.contact_force_n = f64::NAN;
            }
            Record {
                a,
                b: Some(awkward::<RowB>(100 * i + 30)),
                hw: Some(RowHw { planes: [awkward(100 * i + 50), awkward(100 * i + 55)] }),
                magnets: Some(RowMagnets { planes: [awkward(100 * i + 60), awkward(100 * i + 70)] }),
                mid: Some(awkward::<Mid>(100 * i + 90)),
            }
        })
        .collect();
    for r in &records {
        w.write(r).unwrap();
    }
    w.flush().unwrap();
    drop(w);
    let mut back = Vec::new();
    assert!(read_rows(&path, |r| {
        back.push(*r);
        true
    })
    .unwrap());
    assert_eq!(back.len(), records.len());
    let bits = |r: &Record| {
        let mut v = r.a.values();
        v.extend(r.b.unwrap().values());
        v.extend(r.mid.unwrap().values());
        v.into_iter().map(f64::to_bits).collect::<Vec<_>>()
    };
    for (r, b) in records.iter().zip(&back) {
        assert_eq!(bits(r), bits(b));
    }
    // Each coil and magnet value is in the file under its own name.
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let first: Vec<f64> = lines.next().unwrap().split(',').map(|f| f.parse().unwrap()).collect();
    let at = |name: &str| first[header.iter().position(|h| *h == name).unwrap()];
    let hw = records[0].hw.unwrap();
    assert_eq!(at("iy_coil_a"), hw.planes[0].iy_coil_a);
    assert_eq!(at("b_vx_coil_v"), hw.planes[1].vx_coil_v);
    let m = records[0].magnets.unwrap();
    assert_eq!(at("vy_minus_v"), m.planes[0].vy_minus_v);
    assert_eq!(at("b_ix_plus_a"), m.planes[1].ix_plus_a);
    let _ = std::fs::remove_dir_all(path.parent().unwrap());
}

/// The tables' headers, derived from their row types, are the headers shipped.
#[test]
fn every_table_header_is_its_row_types_fields_as_shipped() {
    use plant::bench::rows::*;
    let cases: [(&str, &str); 18] = [
        (plant::campbell::CAMPBELL_HEADER, "speed_hz,mode,whirl,frequency_hz,damping_ratio"),
        (
            plant::campbell::DECAY_HEADER,
            "speed_hz,mode,whirl,linear_hz,decay_hz,error_rel,linear_damping_ratio,decay_damping_ratio",
        ),
        (plant::compare::MAP_HEADER, "map,rate_hz,value,damping_measured,class"),
        (
            plant::compare::COMPARE_HEADER,
            "rate_hz,mode,status,rms_dev_m,max_dev_m,damping_ratio,recover_s,post_shock_mode",
        ),
        (
            plant::compare::REALTIME_HEADER,
            "run,mode,status,deadline_misses,deadline_miss_fraction,longest_miss_burst,plant_overruns,tick_p999_us,\
tick_max_us,integration_p999_us,integration_max_us,latency_p999_us,post_shock_mode,recovery_s,max_contact_force_n,\
max_radius_m,steady_contact_fraction,rms_dev_m,max_dev_m,same_as_lockstep,load_1min",
        ),
        (
            plant::compare::LAWS_HEADER,
            "law,mode,status,recovery_s,post_shock_mode,max_contact_force_n,contact_time_s,steady_contact_fraction,\
whirl_hz",
        ),
        (
            plant::bench::tick::TICK_HEADER,
            "setting,run,status,ticks,contact_ticks,integration_p50_us,integration_p99_us,integration_p999_us,\
integration_max_us,contact_p50_us,contact_p99_us,contact_p999_us,contact_max_us,tick_p50_us,tick_p999_us,\
tick_max_us,max_rhs_evals_per_tick,wall_time_s,post_shock_mode,max_contact_force_n,max_radius_m,contact_fraction,\
scheduling,load_1min",
        ),
        (
            plant::bench::tick::REPEAT_HEADER,
            "setting,repeats,rhs_evals,p50_us,p99_us,p999_us,max_us,scheduling,load_1min",
        ),
        (
            plant::bench::host::HOST_HEADER,
            "pacing,rate_hz,ticks,late_p50_us,late_p99_us,late_p999_us,late_max_us,over_period,over_period_fraction,\
scheduling,load_1min",
        ),
        (
            ACCURACY_HEADER,
            "scene,implementation,method,setting,rtol,substeps,status,err_rms,err_max,wall_s_per_sim_s,rhs_evals,sim_s",
        ),
        (STABILITY_HEADER, "scene,method,largest_stable_step_s,substeps,estimated_step_s"),
        (REFERENCE_HEADER, "t_s,dx_m,dy_m"),
        (MODELS_HEADER, "scene,variant,err_rms,err_max,wall_s_per_sim_s,speedup"),
        (
            MACHINE_HEADER,
            "scene,model,plane,peak_contact_force_n,contact_time_s,contact_fraction,friction_energy_j,recovery_s,\
max_radius_m,first_contact_s,post_shock_mode,err_rms,err_max,wall_s_per_sim_s,speedup",
        ),
        (
            ENGINEERING_HEADER,
            "scene,setting,status,peak_contact_force_n,max_radius_m,contact_fraction,post_shock_mode,steady_class,\
wall_s_per_sim_s,peak_force_rel_diff,max_radius_rel_diff,contact_fraction_diff,same_mode",
        ),
        (plant::soak::ENVELOPE_CSV_HEADER, "t_s,max_radius_m,max_contact_force_n"),
        (
            plant::soak::SOAK_CSV_HEADER,
            "index,start_s,peak_g,direction_deg,duration_s,recovered,recovery_s,max_contact_force_n,contact_time_s,\
contact_episodes,max_radius_m,complete",
        ),
        (plant::soak::RSS_CSV_HEADER, "t_sim_s,wall_s,plant_rss_kib,controller_rss_kib"),
    ];
    for (derived, shipped) in cases {
        assert_eq!(derived, shipped);
    }
    // A sweep's `points.csv`: the single-run columns, then an ensemble's.
    let single = "value,post_shock_mode,steady_class,period_k,contact_fraction,whirl_hz,max_radius_m,\
max_contact_force_n,status,index";
    let ensemble = "members,recovered,dry_whirl,rebound,diverged,p_recovered,p_lo,p_hi,recovery_median_s,\
recovery_p90_s,worst_contact_force_n,verified,numerically_sensitive,sensitive,stopped_by";
    assert_eq!(plant::grid::outputs::SINGLE_COLUMNS.join(","), single);
    assert_eq!(plant::ensemble::merge::ENSEMBLE_COLUMNS.join(","), ensemble);
}

/// No header constant in `plant/src` or `plant/sim/src` is a string literal (`…_HEADER: &str = "…"`) or a
/// literal list of names (`…_COLUMNS: [&str; n] = [`): each is derived from its row type
/// (`table_row!`, `text_row!`, or the trace's typed rows).
#[test]
fn no_header_constant_is_a_hand_written_list() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = vec![root.join("src"), root.join("sim/src")];
    let mut literal = Vec::new();
    while let Some(path) = files.pop() {
        if path.is_dir() {
            files.extend(std::fs::read_dir(&path).unwrap().map(|e| e.unwrap().path()));
            continue;
        }
        if path.extension().is_none_or(|e| e != "rs") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        for (i, line) in lines.iter().enumerate() {
            let Some(rest) = line.split_once("_HEADER: &str =").map(|(name, rest)| (name, rest.trim())) else {
                continue;
            };
            let (_, value) = rest;
            // The value may start on the next line.
            let value = if value.is_empty() { lines.get(i + 1).map_or("", |l| l.trim()) } else { value };
            if value.starts_with('"') {
                literal.push(format!("{}:{}: {}", path.display(), i + 1, line.trim()));
            }
        }
        for (i, line) in lines.iter().enumerate() {
            if line.contains("_COLUMNS: [&str;") {
                literal.push(format!("{}:{}: {}", path.display(), i + 1, line.trim()));
            }
        }
    }
    assert!(literal.is_empty(), "hand-written header constants:\n{}", literal.join("\n"));
}
