//! Resident memory of a process, from `/proc/<pid>/status` (Linux).

/// `VmRSS` of process `pid` (`None`: this process) in KiB, or `None` where
/// there is no `/proc` or the process is gone.
pub fn rss_kib(pid: Option<u32>) -> Option<u64> {
    let path = match pid {
        Some(pid) => format!("/proc/{pid}/status"),
        None => "/proc/self/status".to_string(),
    };
    parse_vm_rss(&std::fs::read_to_string(path).ok()?) // "/proc/…": the system's own file
}

/// The `VmRSS:` line of a `status` file, in KiB.
///
/// ```
/// let status = "Name:\tplant\nVmPeak:\t  20000 kB\nVmRSS:\t    5120 kB\nThreads:\t1\n";
/// assert_eq!(plant::soak::rss::parse_vm_rss(status), Some(5120));
/// ```
pub fn parse_vm_rss(status: &str) -> Option<u64> {
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    line["VmRSS:".len()..].split_whitespace().next()?.parse().ok()
}

#[cfg(test)]
mod tests {
    #[test]
    #[cfg(target_os = "linux")]
    fn this_process_has_a_resident_size() {
        let kib = super::rss_kib(None).expect("VmRSS of this process");
        assert!(kib > 100, "{kib} KiB");
        assert_eq!(super::rss_kib(Some(u32::MAX)), None);
    }
}
