//! `pd-notch-controller`: a complete controller process for the testbed's
//! plant, serving one law of this crate (`pd_notch`) and, for comparison,
//! the registry's `pd`. Everything else (arguments, `AMB_TESTBED_RUN_ID`,
//! handshake, wake protocol, signals, liveness, exit codes) is
//! `controller::serve`.

fn main() -> std::process::ExitCode {
    controller::serve(&[amb_pd_notch::LAW, controller::pd::LAW])
}
