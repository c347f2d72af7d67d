//! End-to-end tests of the `shock-table` binary: output forms and exit
//! codes (0 success, 1 I/O failure, 2 bad input).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the binary to completion within a minute (far more than any of these calls needs,
/// even in a debug build on a loaded machine); past it the child is killed and the test fails,
/// so that a hang cannot stall the suite.
fn run(args: &[&str]) -> Output {
    use std::io::Read;
    use std::process::Stdio;
    use std::time::{Duration, Instant};
    let limit = Duration::from_secs(60);
    let mut child = Command::new(env!("CARGO_BIN_EXE_shock-table"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the shock-table binary runs");
    let drain = |mut pipe: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            let _ = pipe.read_to_end(&mut bytes);
            bytes
        })
    };
    let out = drain(Box::new(child.stdout.take().expect("piped stdout")));
    let err = drain(Box::new(child.stderr.take().expect("piped stderr")));
    let deadline = Instant::now() + limit;
    let status = loop {
        if let Some(status) = child.try_wait().expect("waiting for shock-table") {
            break status;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("shock-table {args:?} did not finish within {limit:?} (killed)");
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    Output { status, stdout: out.join().unwrap_or_default(), stderr: err.join().unwrap_or_default() }
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A scratch directory unique to this test and process.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("shock-table-cli-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).expect("scratch dir");
    d
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 temp path")
}

const EXPORT_HEADER: &str = "t_s,ax_m_s2,ay_m_s2,vx_m_s,vy_m_s,dx_m,dy_m";

#[test]
fn table_prints_three_rows() {
    let o = run(&["table"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = stdout(&o);
    let lines: Vec<&str> = text.lines().filter(|l| !l.starts_with('#')).collect();
    assert!(lines[0].contains("a_1 (G)") && lines[0].contains("h (mm)"), "{text}");
    let rows: Vec<Vec<&str>> = lines[1..].iter().map(|l| l.split_whitespace().collect()).collect();
    assert_eq!(rows.len(), 3, "{text}");
    // The study's Table 1, with a_2 of the 3 G row from the velocity
    // condition (−0.26, not the printed −0.44) and h of the 20 G row with
    // G = 9.80665 (13.50; the study, with G = 9.81, prints 13.51).
    let want = [
        ["3.00", "-0.26", "0.0042", "0.0519", "2.03"],
        ["10.00", "-0.87", "0.0042", "0.0519", "6.75"],
        ["20.00", "-1.75", "0.0042", "0.0519", "13.50"],
    ];
    for (row, w) in rows.iter().zip(want) {
        assert_eq!(&row[..5], &w[..], "{text}");
        assert_eq!(row.len(), 7, "V_0 and D_0 columns: {text}");
    }
}

#[test]
fn table_json_is_machine_readable() {
    let o = run(&["table", "--json", "--peaks-g", "10"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("valid JSON");
    let rows = v["rows"].as_array().expect("rows");
    assert_eq!(rows.len(), 1);
    let h = rows[0]["h_mm"].as_f64().expect("h_mm");
    assert!((h - 6.75).abs() < 0.005, "{h}");
    assert_eq!(v["f2_hz"].as_f64(), Some(80.0));
}

#[test]
fn export_writes_csv_with_header() {
    let dir = scratch("export");
    let out = dir.join("pulse.csv");
    let o = run(&["export", "--peak-g", "10", "--rate-hz", "10000", "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = std::fs::read_to_string(&out).expect("CSV written");
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(EXPORT_HEADER));
    let rows: Vec<Vec<f64>> = lines.map(|l| l.split(',').map(|x| x.parse().expect("number")).collect()).collect();
    // default duration: t_2 ≈ 0.0519 s + 10 % ≈ 0.0571 s at 10 kHz
    assert_eq!(rows.len(), 572);
    for r in &rows {
        assert_eq!(r.len(), 7);
        assert_eq!((r[1], r[3], r[5]), (0.0, 0.0, 0.0), "x columns are 0");
    }
    let last = rows.last().expect("rows");
    assert!(last[4].abs() < 1e-12, "at rest after the pulse");
    assert!((last[6] * 1e3 - 6.75).abs() < 0.005, "lifted by h");
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn export_programme_file() {
    let dir = scratch("programme");
    std::fs::write(dir.join("hit.csv"), "t_s,accel_m_s2\n0,1\n0.01,1\n").expect("write");
    std::fs::write(
        dir.join("prog.toml"),
        "[[shock]]\nkind = \"double_half_sine\"\ndesign_accel_g = 20.0\nf1_hz = 10.0\nf2_hz = 80.0\n\
         start_s = 0.01\n\n[[shock]]\nkind = \"recorded\"\nfile = \"hit.csv\"\ndirection_deg = 0.0\n",
    )
    .expect("write");
    let out = dir.join("p.csv");
    let o = run(&[
        "export",
        "--programme",
        s(&dir.join("prog.toml")),
        "--duration-s",
        "0.1",
        "--rate-hz",
        "1000",
        "--out",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = std::fs::read_to_string(&out).expect("CSV written");
    assert_eq!(text.lines().count(), 1 + 101);
    let last: Vec<f64> = text.lines().last().expect("rows").split(',').map(|x| x.parse().expect("number")).collect();
    // x: 1 m/s² for 10 ms, then coasting at 0.01 m/s
    assert!((last[3] - 0.01).abs() < 1e-15, "{last:?}");
    assert!((last[5] - (0.00005 + 0.01 * 0.09)).abs() < 1e-15, "{last:?}");
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn bad_flag_value_exits_2() {
    for args in [
        &["table", "--f2-hz", "-3"][..],
        &["table", "--f2-hz", "5"],
        &["table", "--peaks-g", "abc"],
        &["export", "--peak-g", "0", "--out", "unused.csv"],
        &["export", "--peak-g", "10", "--rate-hz", "0", "--out", "unused.csv"],
        &["export", "--out", "unused.csv"],
    ] {
        let o = run(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
    }
    let o = run(&["table", "--f2-hz", "-3"]);
    assert!(stderr(&o).contains("--f2-hz = -3 Hz: must be > 0"), "{}", stderr(&o));
    let o = run(&["table", "--f2-hz", "5"]);
    assert!(stderr(&o).contains("--f2-hz = 5 Hz: must be > --f1-hz = 10 Hz"), "{}", stderr(&o));
    assert!(!Path::new("unused.csv").exists());
}

#[test]
fn bad_programme_key_exits_2_and_names_it() {
    let dir = scratch("badkey");
    let prog = dir.join("prog.toml");
    std::fs::write(&prog, "[[shock]]\nkind = \"double_half_sine\"\npeak_g = 10.0\nf1_hz = 10.0\nf2_hz = -3.0\n")
        .expect("write");
    let out = dir.join("p.csv");
    let o = run(&["export", "--programme", s(&prog), "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("shock[0].f2_hz = -3 Hz: must be > 0"), "{}", stderr(&o));
    std::fs::write(&prog, "[[shock]]\nkind = \"half_sine\"\npeak_g = 5.0\nduration_s = 0.01\nstart = 1\n")
        .expect("write");
    let o = run(&["export", "--programme", s(&prog), "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("unknown field `start`"), "{}", stderr(&o));
    assert!(!out.exists());
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn io_errors_exit_1() {
    let o = run(&["export", "--programme", "/nonexistent/prog.toml", "--out", "unused.csv"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("/nonexistent/prog.toml"));
    let o = run(&["export", "--peak-g", "10", "--out", "/nonexistent/dir/p.csv"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("writing /nonexistent/dir/p.csv"));
}
