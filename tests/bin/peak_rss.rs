//! `peak-rss PROGRAM [ARGS…]`: runs the command (its standard output discarded, its errors
//! passed through) and prints
//! `CODE KIB`: its exit code (`signal` if a signal ended it) and its peak resident memory
//! (`ru_maxrss` from `wait4`), for the memory tests (not shipped).
//!
//! Why a process of its own: a child that a test process starts shares that process's
//! memory map until it calls exec (std spawns with `posix_spawn`), and Linux carries the
//! map's high-water mark into the child's `ru_maxrss`. A test binary that has read a large
//! trace, or runs other tests on other threads, would add its own peak to the figure. This
//! small process starts the command instead: its own mark, a few MiB, is all it can add.

#[cfg(target_os = "linux")]
fn main() -> std::process::ExitCode {
    use std::os::unix::process::CommandExt;
    let args: Vec<std::ffi::OsString> = std::env::args_os().skip(1).collect();
    let Some((program, rest)) = args.split_first() else {
        eprintln!("usage: peak-rss PROGRAM [ARGS...]");
        return std::process::ExitCode::from(2);
    };
    let mut cmd = std::process::Command::new(program);
    cmd.args(rest).stdin(std::process::Stdio::null()).stdout(std::process::Stdio::null());
    // SAFETY: prctl is async-signal-safe; the command dies with this process (a test that
    // kills this process at its time limit leaves nothing running).
    unsafe {
        cmd.pre_exec(|| {
            libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL);
            Ok(())
        });
    }
    let child = match cmd.spawn() {
        Ok(c) => c,
        Err(e) => {
            eprintln!("peak-rss: cannot start {program:?}: {e}");
            return std::process::ExitCode::from(2);
        }
    };
    let pid = child.id() as libc::pid_t;
    let mut status = 0;
    // SAFETY: plain syscall on our own child; `usage` is a valid out-parameter.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    if unsafe { libc::wait4(pid, &mut status, 0, &mut usage) } != pid {
        eprintln!("peak-rss: wait4: {}", std::io::Error::last_os_error());
        return std::process::ExitCode::from(1);
    }
    std::mem::forget(child); // reaped by wait4 above
    let code = if libc::WIFEXITED(status) { libc::WEXITSTATUS(status).to_string() } else { "signal".into() };
    println!("{code} {}", usage.ru_maxrss);
    std::process::ExitCode::SUCCESS
}

#[cfg(not(target_os = "linux"))]
fn main() {
    eprintln!("peak-rss: Linux only");
    std::process::exit(2);
}
