//! `controller`: the AMB controller as its own process, serving one run of the
//! plant over iceoryx2 (`controller --run-id ID`) with every law of the
//! registry. The process is [`controller::serve`]: argument parsing,
//! handshake, wake protocol, signals, peer liveness and exit codes (0 the
//! plant ended the run; 1 an IPC failure; 2 bad input, a refused hello, a run
//! id in use; 4 the plant is gone; 130 SIGINT/SIGTERM) live in the library,
//! so that a crate outside this repository is a controller by the same call.

fn main() -> std::process::ExitCode {
    controller::serve(controller::ALL_LAWS)
}
