//! `[controller]`: the co-simulation settings, the controller command, the stiffness bound and
//! the deprecated `relev_*` keys.

use super::*;

/// `controller.stiffness_n_per_m`: > 0 and at most [`MAX_STIFFNESS_N_PER_M`].
pub(super) fn stiffness(k_e: f64) -> Result<f64, ConfigError> {
    let k_e = positive("controller.stiffness_n_per_m", k_e, "N/m")?;
    if k_e > MAX_STIFFNESS_N_PER_M {
        return Err(range(
            "controller.stiffness_n_per_m",
            k_e,
            "N/m",
            &format!("must be <= {MAX_STIFFNESS_N_PER_M:e} N/m (the loop would chatter and the run not end)"),
        ));
    }
    Ok(k_e)
}

/// Validates the co-simulation keys of `[controller]`.
pub(super) fn cosim_settings(ctl: &RawController) -> Result<CosimSettings, ConfigError> {
    let fallback = ctl.fallback;
    let ms = |key: &str, v: f64, zero_ok: bool| -> Result<f64, ConfigError> {
        let ok = v.is_finite() && (if zero_ok { v >= 0.0 } else { v > 0.0 }) && v <= 3.6e6;
        if ok {
            Ok(v * 1e-3)
        } else {
            Err(range(key, v, "ms", if zero_ok { "must be between 0 and 3.6e6" } else { "must be > 0 and <= 3.6e6" }))
        }
    };
    let reconnect_timeout = ms("controller.reconnect_timeout_ms", ctl.reconnect_timeout_ms, true)?;
    if fallback == Fallback::Stop && reconnect_timeout > 0.0 {
        return Err(range(
            "controller.reconnect_timeout_ms",
            ctl.reconnect_timeout_ms,
            "ms",
            "must be 0 with controller.fallback = \"stop\" (the run stops at the loss)",
        ));
    }
    if !(ctl.spin_us.is_finite() && (0.0..=1e6).contains(&ctl.spin_us)) {
        return Err(range("controller.spin_us", ctl.spin_us, "µs", "must be between 0 and 1e6"));
    }
    let pin_cores = match ctl.pin_cores.as_slice() {
        [] => None,
        &[plant, controller] => {
            let cores = controller::cores::cores_online();
            for core in [plant, controller] {
                if core >= cores {
                    return Err(range(
                        "controller.pin_cores",
                        format!("{:?}", ctl.pin_cores),
                        "",
                        &format!("core {core} does not exist (this machine has cores 0 to {})", cores - 1),
                    ));
                }
            }
            Some([plant, controller])
        }
        _ => {
            return Err(range(
                "controller.pin_cores",
                format!("{:?}", ctl.pin_cores),
                "",
                "must be empty or two cores [plant, controller]",
            ))
        }
    };
    if ctl.realtime_priority > 99 {
        return Err(range("controller.realtime_priority", ctl.realtime_priority, "", "must be 0 (off) to 99"));
    }
    if ctl.realtime_priority > 97 && pin_cores.is_some_and(|[p, c]| p == c) {
        return Err(range(
            "controller.realtime_priority",
            ctl.realtime_priority,
            "",
            "must be 0 (off) to 97 with plant and controller on one core (controller.pin_cores): the controller \
             runs one level above the plant there, and the plant's watchdog one above that",
        ));
    }
    if !(ctl.max_miss_fraction.is_finite() && (0.0..=1.0).contains(&ctl.max_miss_fraction)) {
        return Err(range("controller.max_miss_fraction", ctl.max_miss_fraction, "", "must be between 0 and 1"));
    }
    if !(ctl.max_overrun_fraction.is_finite() && (0.0..=1.0).contains(&ctl.max_overrun_fraction)) {
        return Err(range("controller.max_overrun_fraction", ctl.max_overrun_fraction, "", "must be between 0 and 1"));
    }
    Ok(CosimSettings {
        fallback,
        reply_timeout: ms("controller.reply_timeout_ms", ctl.reply_timeout_ms, false)?,
        reconnect_timeout,
        connect_timeout: ms("controller.connect_timeout_ms", ctl.connect_timeout_ms, false)?,
        spin: ctl.spin_us * 1e-6,
        pin_cores,
        lockstep_timeout: ms("controller.lockstep_timeout_ms", ctl.lockstep_timeout_ms, false)?,
        command: crate::config::fmu::command(ctl)?
            .map_or_else(|| ctl.command.as_ref().map(command_argv).transpose(), |c| Ok(Some(c)))?,
        realtime_priority: ctl.realtime_priority,
        max_miss_fraction: ctl.max_miss_fraction,
        max_overrun_fraction: ctl.max_overrun_fraction,
        pacing: ctl.pacing,
    })
}

/// `controller.command` as an argv: one string is a one-element command; a list must hold
/// strings, the first not empty.
pub(super) fn command_argv(value: &toml::Value) -> Result<Vec<String>, ConfigError> {
    let bad = |why: &str| range("controller.command", value, "", why);
    let argv: Vec<String> = match value {
        toml::Value::String(s) => vec![s.clone()],
        toml::Value::Array(items) => items
            .iter()
            .map(|v| v.as_str().map(str::to_string))
            .collect::<Option<_>>()
            .ok_or_else(|| bad("must be a path (a string) or a list of strings"))?,
        _ => return Err(bad("must be a path (a string) or a list of strings")),
    };
    if argv.first().is_none_or(|a| a.is_empty()) {
        return Err(bad("must name a program (the first element is empty or missing)"));
    }
    Ok(argv)
}

/// Resolves `controller.command` against the scene's folder: an element that is a relative
/// path naming something that exists there becomes that absolute path; the others are kept.
/// The resolved list replaces the key, so that the resolved scene (`scene.toml` of a run
/// folder) runs the same command from anywhere.
pub(super) fn resolve_command(ctl: &mut RawController, base_dir: &Path) -> Result<(), ConfigError> {
    let Some(value) = &ctl.command else { return Ok(()) };
    let argv = command_argv(value)?;
    let resolved: Vec<toml::Value> = argv
        .into_iter()
        .map(|arg| {
            let here = base_dir.join(&arg);
            let local = !arg.is_empty() && Path::new(&arg).is_relative() && here.exists();
            let arg = if local { std::path::absolute(&here).unwrap_or(here).display().to_string() } else { arg };
            toml::Value::String(arg)
        })
        .collect();
    ctl.command = Some(toml::Value::Array(resolved));
    Ok(())
}

/// Moves the deprecated `relev_*` keys into `params` (law `relev`) or drops them (another
/// law), with a warning each; both an alias and its parameter given is an error.
pub(super) fn migrate_relev_aliases(ctl: &mut RawController, warnings: &mut Vec<String>) -> Result<(), ConfigError> {
    let given = [
        ctl.relev_enter_um.take(),
        ctl.relev_exit_um.take(),
        ctl.relev_damping_ratio.take(),
        ctl.relev_hold_ms.take(),
        ctl.relev_arm_ms.take(),
    ];
    let relev = controller::relev::LAW.name;
    for ((old, new), value) in controller::relev::ALIASES.iter().zip(given) {
        let Some(value) = value else { continue };
        if ctl.params.contains_key(*new) {
            return Err(ConfigError::Alias {
                old: format!("controller.{old}"),
                new: format!("controller.params.{new}"),
            });
        }
        if ctl.law == relev {
            warnings.push(format!(
                "controller.{old} is deprecated: write controller.params.{new} (a parameter of law relev)"
            ));
            ctl.params.insert(new.to_string(), toml::Value::Float(value));
        } else {
            warnings.push(format!(
                "controller.{old} is deprecated and ignored: it is controller.params.{new} of law relev, and this scene runs law {}",
                ctl.law
            ));
        }
    }
    Ok(())
}
