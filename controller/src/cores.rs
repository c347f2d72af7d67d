//! The machine's CPU cores: what `controller.pin_cores` is checked against, in the laws' crate
//! so that a scene is checked without the link (feature `ipc`).

/// Number of CPU cores online.
pub fn cores_online() -> usize {
    // SAFETY: sysconf has no preconditions.
    let n = unsafe { libc::sysconf(libc::_SC_NPROCESSORS_ONLN) };
    usize::try_from(n).unwrap_or(1).max(1)
}
