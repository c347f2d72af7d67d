//! `controller-fmu`: a controller FMU served over the wire, one `doStep` per controller tick
//! (docs/guide/fmu-controller.md). The plant starts it for a scene with `controller.fmu` in
//! lockstep and realtime modes:
//!
//! ```text
//! controller-fmu --fmu ctl.fmu [--map SIGNAL=VARIABLE]… [--solver euler|rk4] [--substeps N]
//!                [--step-timeout-ms MS] --run-id ID [the controller's other options]
//! ```
//!
//! Everything but the FMU's own options is `controller::serve`'s (handshake, wake protocol,
//! liveness, signals, exit codes 0, 1, 2, 4, 130). Its own endings: 2 when the FMU cannot be
//! opened (not a zip, FMI 1.0, no Linux x86-64 binary, a signal without its variable), and 3
//! when the FMU fails during the run (a step's Discard, Error or Fatal; a tick's calls longer
//! than `--step-timeout-ms`; a crash inside the FMU ends the process by its signal, after a
//! line that says so). The FMU's log and these lines go to stderr: `controller.log`.

use controller::{LawError, Params, RotorDesign, RotorLaw, RotorLawEntry};
use controller_fmu::{Fmu, OnFailure, Spec};
use std::process::ExitCode;
use std::sync::{Arc, OnceLock};
use std::time::Duration;

/// Exit code: the FMU failed during the run.
const FMU_FAILED: i32 = 3;

static FMU: OnceLock<Arc<Fmu>> = OnceLock::new();

fn build(design: &RotorDesign, params: &Params) -> Result<Box<dyn RotorLaw>, LawError> {
    let fmu = FMU.get().expect("opened before serving");
    eprintln!(
        "controller-fmu: {} for {} axes at {} Hz",
        fmu.describe(),
        design.axes(),
        1.0 / design.plane_a().period_s
    );
    Ok(Box::new(fmu.law(design, params)?.on_failure(OnFailure::Exit(FMU_FAILED))))
}

const LAW: RotorLawEntry =
    RotorLawEntry { name: controller_fmu::LAW_NAME, summary: "a controller FMU (controller.fmu)", build };

/// A line on stderr and the process ended by the signal, for a crash inside the FMU.
extern "C" fn crashed(signal: libc::c_int) {
    let name: &[u8] = match signal {
        libc::SIGSEGV => b"SIGSEGV",
        libc::SIGBUS => b"SIGBUS",
        libc::SIGFPE => b"SIGFPE",
        libc::SIGILL => b"SIGILL",
        _ => b"SIGABRT",
    };
    let head: &[u8] = b"controller-fmu: error: the FMU crashed (";
    let tail: &[u8] = b") inside an FMI call; the plant's lost-controller handling takes over\n";
    // SAFETY: write(2) and raise(3) are async-signal-safe; the handler was reset to the default
    // (SA_RESETHAND), so the raise ends the process by this signal.
    unsafe {
        libc::write(2, head.as_ptr().cast(), head.len());
        libc::write(2, name.as_ptr().cast(), name.len());
        libc::write(2, tail.as_ptr().cast(), tail.len());
        libc::raise(signal);
    }
}

fn on_crash() {
    for signal in [libc::SIGSEGV, libc::SIGBUS, libc::SIGFPE, libc::SIGILL, libc::SIGABRT] {
        // SAFETY: a zeroed sigaction with a handler that only writes and re-raises.
        unsafe {
            let mut action: libc::sigaction = std::mem::zeroed();
            action.sa_sigaction = crashed as *const () as usize;
            action.sa_flags = libc::SA_RESETHAND | libc::SA_NODEFER;
            libc::sigemptyset(&mut action.sa_mask);
            libc::sigaction(signal, &action, std::ptr::null_mut());
        }
    }
}

/// Ends the process when one tick's FMI calls take longer than `limit`.
fn watchdog(limit: Duration, folder: std::path::PathBuf) {
    std::thread::spawn(move || loop {
        std::thread::sleep(Duration::from_millis(10).min(limit / 4));
        if let Some((since, tick)) = controller_fmu::inside_since_ns() {
            let elapsed = controller_fmu::monotonic_ns().saturating_sub(since);
            if elapsed > limit.as_nanos() as u64 && controller_fmu::inside_since_ns() == Some((since, tick)) {
                eprintln!(
                    "controller-fmu: error: the FMU's calls of tick {tick} have not returned within {} ms \
                     (controller.fmu.step_timeout_ms): it hangs; exiting (the plant's lost-controller handling takes over)",
                    limit.as_secs_f64() * 1e3
                );
                let _ = std::fs::remove_dir_all(&folder);
                // SAFETY: ends the process at once (the FMU's thread is stuck inside it).
                unsafe { libc::_exit(FMU_FAILED) };
            }
        }
    });
}

fn main() -> ExitCode {
    let argv: Vec<String> = std::env::args().collect();
    let program = "controller-fmu";
    let (spec, rest) = match Spec::take_args(argv) {
        Ok((Some(spec), rest)) => (spec, rest),
        Ok((None, rest)) if rest.iter().any(|a| a == "--help" || a == "-h" || a == "--version" || a == "-V") => {
            if rest.iter().any(|a| a == "--help" || a == "-h") {
                println!(
                    "{program} --fmu FILE.fmu [--map SIGNAL=VARIABLE]... [--solver euler|rk4] [--substeps N] \
                     [--step-timeout-ms MS] <the controller's options below>\n"
                );
            }
            return controller::serve::serve_from(rest.into_iter().map(Into::into).collect(), &[LAW]);
        }
        Ok((None, _)) => {
            eprintln!("{program}: error: --fmu FILE.fmu is missing (the FMU to serve)");
            return ExitCode::from(2);
        }
        Err(e) => {
            eprintln!("{program}: error: {e}");
            return ExitCode::from(2);
        }
    };
    // The signals are bound at the hello, for the rotor it describes.
    let fmu = match Fmu::open(&spec) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("{program}: error: {e}");
            return ExitCode::from(2);
        }
    };
    let folder = fmu.folder().to_path_buf();
    let _ = FMU.set(fmu);
    on_crash();
    watchdog(Duration::from_secs_f64(spec.step_timeout_ms / 1e3), folder.clone());
    let code = controller::serve::serve_from(rest.into_iter().map(Into::into).collect(), &[LAW]);
    // The law (the instance) is gone; the unpacked FMU in the static is never dropped.
    let _ = std::fs::remove_dir_all(&folder);
    code
}
