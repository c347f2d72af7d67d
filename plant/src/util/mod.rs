//! The small shared rooms every layer uses: the one atomic write ([`atomic`]) and the one way of
//! creating an output file ([`outfile`]), the one reader of input files ([`input`]), one live
//! process per output folder ([`claim`]), the one SIGINT/SIGTERM handler ([`interrupt`]), the
//! endings the library raises ([`exit`]), CSV tables and row files ([`table`], [`row_file`]),
//! command-line values ([`argument`]), an in-process controller FMU that ends the process
//! ([`fmu_exit`]). They import nothing from the layers above.

pub mod argument;
pub mod atomic;
pub mod claim;
pub mod exit;
pub mod input;
pub mod interrupt;
pub mod outfile;
pub mod row_file;
pub mod table;

/// A fresh folder for a test: `plant-<name>-<process id>` in the system's temporary folder,
/// emptied and created.
#[cfg(test)]
pub(crate) fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("plant-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}
