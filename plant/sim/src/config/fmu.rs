//! `controller.fmu`: a controller FMU as the scene's controller (docs/guide/fmu-controller.md).
//!
//! The key is a path (`fmu = "ctl.fmu"`, from the scene file's folder) or a table (`path`,
//! `map`, `solver`, `substeps`, `step_timeout_ms`: [`controller_fmu::Spec`]). With it the law is
//! `fmu` (`controller.law` left at its default or written `"fmu"`); in lockstep and realtime the
//! plant starts `controller-fmu` (next to `plant`) as its controller command, in sampled mode
//! it runs the FMU in its own process. The FMU is checked when the scene loads (a zip, FMI 2.0
//! or 3.0, a Linux x86-64 binary, every signal's variable): bad input, exit 2.

use super::range;
use super::raw::RawController;
use super::{ConfigError, Scene};
use controller_fmu::Spec;
use std::path::{Path, PathBuf};

/// The FMU host's executable name.
pub const HOST_EXE: &str = "controller-fmu";

/// Reads `controller.fmu` of a raw scene: the path made absolute (so that the run folder's
/// `scene.toml` runs it from anywhere), `law` set to `fmu`. A scene with both `fmu` and
/// `command`, or another law, is refused.
pub fn resolve(ctl: &mut RawController, base_dir: &Path) -> Result<Option<Spec>, ConfigError> {
    let Some(value) = &ctl.fmu else { return Ok(None) };
    let spec =
        Spec::from_toml(value, base_dir).map_err(|message| ConfigError::Parse { path: "scene".into(), message })?;
    if ctl.command.is_some() {
        return Err(range(
            "controller.command",
            ctl.command.as_ref().map(|c| c.to_string()).unwrap_or_default(),
            "",
            "a scene names either a controller FMU (controller.fmu) or a controller command, not both",
        ));
    }
    if !matches!(ctl.law.as_str(), "pd" | controller_fmu::LAW_NAME) {
        return Err(range(
            "controller.law",
            format!("\"{}\"", ctl.law),
            "",
            "with controller.fmu the law is the FMU: leave controller.law out or write \"fmu\"",
        ));
    }
    ctl.law = controller_fmu::LAW_NAME.into();
    let mut table = match value {
        toml::Value::Table(t) => t.clone(),
        _ => toml::Table::new(),
    };
    table.insert("path".into(), toml::Value::String(spec.path.display().to_string()));
    ctl.fmu = Some(if table.len() == 1 { table["path"].clone() } else { toml::Value::Table(table) });
    Ok(Some(spec))
}

/// The controller command that serves `spec`: `controller-fmu` next to the running executable
/// (else looked up in `PATH`) with the spec's arguments.
pub fn host_argv(spec: &Spec) -> Vec<String> {
    let next_to = std::env::current_exe()
        .ok()
        .and_then(|p| p.parent().map(|d| d.join(HOST_EXE)))
        .filter(|p| p.is_file())
        .unwrap_or_else(|| PathBuf::from(HOST_EXE));
    let mut argv = vec![next_to.display().to_string()];
    argv.extend(spec.to_args());
    argv
}

/// The controller command of a resolved `controller.fmu` ([`host_argv`]), if the scene names one.
pub fn command(ctl: &RawController) -> Result<Option<Vec<String>>, ConfigError> {
    let Some(value) = &ctl.fmu else { return Ok(None) };
    let spec = Spec::from_toml(value, Path::new("/"))
        .map_err(|message| ConfigError::Parse { path: "scene".into(), message })?;
    Ok(Some(host_argv(&spec)))
}

/// Checks the FMU for the scene's rotor without loading it ([`controller_fmu::inspect`]).
pub fn check(spec: &Spec, axes: usize) -> Result<(), ConfigError> {
    let inspected = controller_fmu::inspect(spec, axes);
    inspected.map(|_| ()).map_err(|e| range("controller.fmu", format!("\"{}\"", e.path.display()), "", &e.why))
}

/// The FMU of a validated scene, if it names one.
pub fn spec_of(scene: &Scene) -> Option<Spec> {
    let value = scene.source.raw.controller.fmu.as_ref()?;
    Spec::from_toml(value, &scene.source.base_dir).ok()
}
