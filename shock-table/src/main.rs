//! `shock-table`: print the BV043/85 double half-sine table (the study's
//! Table 1) and export base-motion time histories to CSV.
//!
//! Exit codes: 0 success, 1 I/O failure, 2 bad input (flag or programme
//! file value, with the flag/key, value and unit named).

use std::f64::consts::FRAC_PI_2;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::anyhow;
use clap::{Parser, Subcommand};
use serde::Serialize;
use shock_table::{load_programme, DoubleHalfSine, Programme, Shock, ShockError, G0_M_S2};

/// Largest number of CSV rows `export` writes.
const MAX_EXPORT_ROWS: f64 = 1e8;

#[derive(Parser, Debug)]
#[command(name = "shock-table", version, about)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand, Debug)]
enum Cmd {
    /// Print the double half-sine table (the study's Table 1 form).
    Table(TableArgs),
    /// Write a base-motion time history to CSV
    /// (t_s,ax_m_s2,ay_m_s2,vx_m_s,vy_m_s,dx_m,dy_m).
    Export(ExportArgs),
}

#[derive(clap::Args, Debug)]
struct TableArgs {
    /// Peak accelerations a_1 of the pulses, G (comma-separated).
    #[arg(
        long = "peaks-g",
        value_delimiter = ',',
        default_values_t = [3.0, 10.0, 20.0],
        allow_hyphen_values = true
    )]
    peaks_g: Vec<f64>,
    /// Lower SRS corner frequency f_1, Hz.
    #[arg(long = "f1-hz", default_value_t = 10.0, allow_negative_numbers = true)]
    f1_hz: f64,
    /// Upper SRS corner frequency f_2, Hz.
    #[arg(long = "f2-hz", default_value_t = 80.0, allow_negative_numbers = true)]
    f2_hz: f64,
    /// Print JSON instead of a text table.
    #[arg(long)]
    json: bool,
}

#[derive(clap::Args, Debug)]
struct ExportArgs {
    /// Peak acceleration a_1 of a double half-sine along +y, G.
    #[arg(
        long = "peak-g",
        required_unless_present = "programme",
        conflicts_with = "programme",
        allow_negative_numbers = true
    )]
    peak_g: Option<f64>,
    /// Lower SRS corner frequency f_1, Hz [default: 10] (with --peak-g).
    #[arg(long = "f1-hz", conflicts_with = "programme", allow_negative_numbers = true)]
    f1_hz: Option<f64>,
    /// Upper SRS corner frequency f_2, Hz [default: 80] (with --peak-g).
    #[arg(long = "f2-hz", conflicts_with = "programme", allow_negative_numbers = true)]
    f2_hz: Option<f64>,
    /// Programme file (TOML, `[[shock]]` tables).
    #[arg(long)]
    programme: Option<PathBuf>,
    /// Sample rate, Hz.
    #[arg(long = "rate-hz", default_value_t = 20000.0, allow_negative_numbers = true)]
    rate_hz: f64,
    /// Length of the history, s [default: end of the programme + 10 %].
    #[arg(long = "duration-s", allow_negative_numbers = true)]
    duration_s: Option<f64>,
    /// Output CSV file.
    #[arg(long)]
    out: PathBuf,
}

/// Failure of a command, mapped to an exit code.
enum Failure {
    /// Bad input (exit 2).
    Input(anyhow::Error),
    /// I/O failure (exit 1).
    Io(anyhow::Error),
}

impl Failure {
    /// Classify a library error: I/O errors exit 1, the rest is bad input.
    fn from_shock(e: ShockError, context: String) -> Self {
        if e.is_io() {
            Failure::Io(anyhow::Error::new(e).context(context))
        } else {
            Failure::Input(anyhow::Error::new(e).context(context))
        }
    }
}

fn io_failure(e: io::Error, context: String) -> Failure {
    Failure::Io(anyhow::Error::new(e).context(context))
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.cmd {
        Cmd::Table(a) => table(&a),
        Cmd::Export(a) => export(&a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Input(e)) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
        Err(Failure::Io(e)) if is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(Failure::Io(e)) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}

/// Output cut short by the reader (`shock-table table | head`): not an error.
fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.downcast_ref::<io::Error>().is_some_and(|e| e.kind() == io::ErrorKind::BrokenPipe)
}

/// `flag = value unit: reason` for a bad flag value.
fn bad_flag(flag: &str, value: f64, unit: &str, reason: &str) -> Failure {
    let unit = if unit.is_empty() { String::new() } else { format!(" {unit}") };
    Failure::Input(anyhow!("{flag} = {value}{unit}: {reason}"))
}

fn require_positive(flag: &str, value: f64, unit: &str) -> Result<(), Failure> {
    if !value.is_finite() {
        Err(bad_flag(flag, value, unit, "must be finite"))
    } else if value <= 0.0 {
        Err(bad_flag(flag, value, unit, "must be > 0"))
    } else {
        Ok(())
    }
}

/// Double half-sine from flags; library keys (`f2_hz`) are reported as the
/// flags (`--f2-hz`).
fn pulse_from_flags(peak_flag: &str, peak_g: f64, f1_hz: f64, f2_hz: f64) -> Result<DoubleHalfSine, Failure> {
    require_positive(peak_flag, peak_g, "G")?;
    DoubleHalfSine::from_peak(peak_g * G0_M_S2, f1_hz, f2_hz).map_err(|e| match e {
        ShockError::InvalidParameter { key, value, unit, reason } => {
            bad_flag(&format!("--{}", key.replace('_', "-")), value, unit, &reason.replace("f1_hz", "--f1-hz"))
        }
        other => Failure::Input(other.into()),
    })
}

/// One row of the table, in the table's units.
#[derive(Serialize)]
struct PulseRow {
    a1_g: f64,
    a2_g: f64,
    t1_s: f64,
    t2_s: f64,
    h_mm: f64,
    v0_m_s: f64,
    d0_mm: f64,
}

#[derive(Serialize)]
struct TableJson<'a> {
    f1_hz: f64,
    f2_hz: f64,
    g_m_s2: f64,
    rows: &'a [PulseRow],
}

fn table(args: &TableArgs) -> Result<(), Failure> {
    if args.peaks_g.is_empty() {
        return Err(Failure::Input(anyhow!("--peaks-g: give at least one peak, G")));
    }
    let rows = args
        .peaks_g
        .iter()
        .map(|&g| {
            let p = pulse_from_flags("--peaks-g", g, args.f1_hz, args.f2_hz)?;
            Ok(PulseRow {
                a1_g: p.a1 / G0_M_S2,
                a2_g: p.a2 / G0_M_S2,
                t1_s: p.t1,
                t2_s: p.t2,
                h_mm: p.lift() * 1e3,
                v0_m_s: p.design_velocity(),
                d0_mm: p.design_displacement() * 1e3,
            })
        })
        .collect::<Result<Vec<_>, Failure>>()?;
    let stdout = io::stdout();
    let mut out = stdout.lock();
    let written = if args.json {
        let doc = TableJson { f1_hz: args.f1_hz, f2_hz: args.f2_hz, g_m_s2: G0_M_S2, rows: &rows };
        serde_json::to_writer_pretty(&mut out, &doc).map_err(io::Error::from).and_then(|()| writeln!(out))
    } else {
        write_table(&mut out, args, &rows)
    };
    written.map_err(|e| io_failure(e, "writing to stdout".into()))
}

fn write_table(out: &mut impl Write, args: &TableArgs, rows: &[PulseRow]) -> io::Result<()> {
    writeln!(
        out,
        "# BV043/85 double half-sine: f1 = {} Hz, f2 = {} Hz, G = {G0_M_S2} m/s², \
         a_2 from v(t_2) = 0",
        args.f1_hz, args.f2_hz
    )?;
    writeln!(
        out,
        "{:>9} {:>9} {:>9} {:>9} {:>9} {:>10} {:>9}",
        "a_1 (G)", "a_2 (G)", "t_1 (s)", "t_2 (s)", "h (mm)", "V_0 (m/s)", "D_0 (mm)"
    )?;
    for r in rows {
        writeln!(
            out,
            "{:>9.2} {:>9.2} {:>9.4} {:>9.4} {:>9.2} {:>10.3} {:>9.2}",
            r.a1_g, r.a2_g, r.t1_s, r.t2_s, r.h_mm, r.v0_m_s, r.d0_mm
        )?;
    }
    Ok(())
}

fn export(args: &ExportArgs) -> Result<(), Failure> {
    let programme = match (&args.programme, args.peak_g) {
        (Some(path), _) => {
            let p =
                load_programme(path).map_err(|e| Failure::from_shock(e, format!("programme {}", path.display())))?;
            if p.is_empty() {
                return Err(Failure::Input(anyhow!("programme {}: no [[shock]] tables", path.display())));
            }
            p
        }
        (None, Some(peak_g)) => {
            let pulse = pulse_from_flags("--peak-g", peak_g, args.f1_hz.unwrap_or(10.0), args.f2_hz.unwrap_or(80.0))?;
            let shock = Shock::new(pulse.into(), 0.0, FRAC_PI_2).map_err(|e| Failure::Input(e.into()))?;
            Programme::single(shock)
        }
        // clap enforces one of the two
        (None, None) => return Err(Failure::Input(anyhow!("give --peak-g or --programme"))),
    };
    require_positive("--rate-hz", args.rate_hz, "Hz")?;
    let duration = match args.duration_s {
        Some(d) => {
            require_positive("--duration-s", d, "s")?;
            d
        }
        None => 1.1 * programme.end_time(),
    };
    let intervals = (duration * args.rate_hz + 1e-9).floor();
    if intervals + 1.0 > MAX_EXPORT_ROWS {
        return Err(Failure::Input(anyhow!(
            "--duration-s = {duration} s at --rate-hz = {} Hz gives {} rows: more than {MAX_EXPORT_ROWS}",
            args.rate_hz,
            intervals + 1.0
        )));
    }
    let n = intervals as u64 + 1;
    let ctx = || format!("writing {}", args.out.display());
    let file = File::create(&args.out).map_err(|e| io_failure(e, ctx()))?;
    let mut w = BufWriter::new(file);
    write_history(&mut w, &programme, args.rate_hz, n).and_then(|()| w.flush()).map_err(|e| io_failure(e, ctx()))
}

/// Header of the exported CSV.
const EXPORT_HEADER: &str = "t_s,ax_m_s2,ay_m_s2,vx_m_s,vy_m_s,dx_m,dy_m";

fn write_history(w: &mut impl Write, p: &Programme, rate_hz: f64, n: u64) -> io::Result<()> {
    writeln!(w, "{EXPORT_HEADER}")?;
    for i in 0..n {
        let t = i as f64 / rate_hz;
        let k = p.eval(t);
        writeln!(
            w,
            "{t},{:e},{:e},{:e},{:e},{:e},{:e}",
            k.accel[0], k.accel[1], k.vel[0], k.vel[1], k.disp[0], k.disp[1]
        )?;
    }
    Ok(())
}
