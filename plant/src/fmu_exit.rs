//! `exit` and `_exit` of the `plant` executable: an in-process controller FMU (sampled mode)
//! that ends the process says so, and the plant never ends with exit 0 without its outputs
//! (issue 40 item 5; docs/guide/fmu-controller.md).
//!
//! An FMU's library runs in the plant's process in sampled mode, and a call of `exit` or
//! `_exit` in it (pythonfmu's `os._exit`, a C FMU's `exit(0)` on an error of its own) ended
//! the plant with the FMU's code, 0 included, and no `summary.json`: nothing in the process
//! runs after `_exit`. These two functions are exported by the executable (`plant/build.rs`),
//! so the dynamic linker binds an FMU library's calls (and its Python's) to them rather than
//! to the C library's. Called from inside an FMU's code on the thread that runs it
//! ([`controller_fmu::in_fmu_code`]), they write one line naming the FMU and the call and end
//! the process with exit 4, the code of a lost controller; from anywhere else they are the
//! C library's. An `exit_group` system call made directly, or a thread of the FMU's own, is
//! not seen: run an FMU you do not trust in lockstep, where its process is its own.
//!
//! Written by hand: no crate interposes libc's process exits.

use std::ffi::c_int;

/// The exit code when an FMU ends the process: a lost controller's ([`crate::exit_code::Code`]).
const FMU_ENDED: c_int = crate::exit_code::Code::PeerLost as c_int;

/// Ends the process at once (what the C library's `_exit` does).
fn exit_group(code: c_int) -> ! {
    // SAFETY: the system call that ends every thread of the process; it does not return.
    unsafe { libc::syscall(libc::SYS_exit_group, code as libc::c_long) };
    #[allow(clippy::empty_loop)]
    loop {}
}

/// An FMU called `call(code)`: one line on stderr, then [`FMU_ENDED`].
fn fmu_ended(fmu: &str, call: &str, code: c_int) -> ! {
    let line = format!(
        "plant: error: the controller {fmu} called {call}({code}) inside the plant's process (sampled mode): \
         the plant ends with exit {FMU_ENDED}, as for a lost controller, and writes no summary.json; run the FMU \
         in lockstep, where it has a process of its own\n"
    );
    // SAFETY: a write of a buffer we own to stderr.
    unsafe { libc::write(2, line.as_ptr().cast(), line.len()) };
    exit_group(FMU_ENDED)
}

/// `_exit(2)`, as the C library's unless an in-process FMU calls it.
#[no_mangle]
pub extern "C" fn _exit(code: c_int) -> ! {
    if let Some(fmu) = controller_fmu::in_fmu_code() {
        fmu_ended(&fmu, "_exit", code);
    }
    exit_group(code)
}

/// `exit(3)`, the C library's unless an in-process FMU calls it.
#[no_mangle]
pub extern "C" fn exit(code: c_int) -> ! {
    if let Some(fmu) = controller_fmu::in_fmu_code() {
        fmu_ended(&fmu, "exit", code);
    }
    // SAFETY: the C library's `exit`, the next definition after this executable's.
    let real = unsafe { libc::dlsym(libc::RTLD_NEXT, c"exit".as_ptr()) };
    if real.is_null() {
        exit_group(code)
    }
    // SAFETY: `exit` has this signature.
    let real: extern "C" fn(c_int) -> ! = unsafe { std::mem::transmute(real) };
    real(code)
}

/// Keeps both functions in the executable (the linker drops what nothing refers to).
pub fn keep() {
    std::hint::black_box((_exit as extern "C" fn(c_int) -> !, exit as extern "C" fn(c_int) -> !));
}
