//! The plant as an FMU (FMI 2.0 co-simulation, docs/guide/fmu-plant.md): the variables of a
//! scene's FMU ([`Model::of`]) and its `modelDescription.xml` ([`Model::xml`]); the FMU file
//! itself is the CLI's (`plant::fmu_export::package`, `plant fmu SCENE --out plant.fmu`).
//!
//! The binary inside the FMU is the `plant-fmu` crate (`plant/fmu`, `libplant_fmu.so`): at
//! `fmi2Instantiate` it loads the scene from the FMU's `resources/scene.toml` and builds the
//! same [`Model`] from it, so the value references, names, bounds and GUID it answers to are
//! those of the file's `modelDescription.xml` by construction (a GUID that differs is refused).
//!
//! Variable names are promises (the guide lists them): inputs `current_x_A`, `current_y_A`
//! (and `current_x_B`, `current_y_B` on a two-plane rotor); outputs `sensor_*`, `speed`,
//! `angle`, `rotor_*`, `radius_*`, `contact_force_*`, `race_speed_*`, `housing_x`,
//! `housing_y`; parameters named by their scene keys (`shock[0].peak_g`,
//! `touchdown.air_gap_mm`, …).

use crate::config::{load_scene, Scene};
use sha2::{Digest, Sha256};
use std::path::Path;

/// The most a file the scene reads may hold (bytes), when its bytes go into the GUID and when
/// `plant fmu` packs it into the FMU.
pub const MAX_FILE_BYTES: u64 = 1 << 30;

/// The FMI version of the FMU.
pub const FMI_VERSION: &str = "2.0";

/// What an output variable is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Output {
    /// Axis `i`'s sensor signal (V), as the controller reads it.
    Sensor(usize),
    /// The keyphasor's rotor speed (rad/s).
    Speed,
    /// The keyphasor's rotor angle (rad, in [0, 2π)).
    Angle,
    /// Plane `i`'s rotor x relative to the housing (m): `trace.csv`'s `dx_m` (`b_dx_m`).
    RotorX(usize),
    /// Plane `i`'s rotor y relative to the housing (m).
    RotorY(usize),
    /// Plane `i`'s rotor radius relative to the housing (m): `hypot(dx, dy)`.
    Radius(usize),
    /// Plane `i`'s rotor – race normal force (N).
    ContactForce(usize),
    /// Plane `i`'s race spin speed (rad/s).
    RaceSpeed(usize),
    /// The housing's displacement, x (m).
    HousingX,
    /// The housing's displacement, y (m).
    HousingY,
}

/// What a variable is.
#[derive(Clone, Debug, PartialEq)]
pub enum Role {
    /// Axis `i`'s coil current command (A), as the wire carries it.
    Input(usize),
    /// An output.
    Output(Output),
    /// A scene key, set before initialisation (`--set KEY=VALUE` of the FMU's scene).
    Parameter(String),
}

/// One scalar variable (all are `Real`); its value reference is its index in [`Model::variables`].
#[derive(Clone, Debug, PartialEq)]
pub struct Variable {
    /// The name (a promise).
    pub name: String,
    /// What it is.
    pub role: Role,
    /// Its unit (a name of `<UnitDefinitions>`), `None` for a pure number.
    pub unit: Option<&'static str>,
    /// Its description.
    pub description: String,
    /// Its start value (inputs and parameters).
    pub start: Option<f64>,
    /// Its bounds (parameters).
    pub min: Option<f64>,
    /// Its upper bound.
    pub max: Option<f64>,
}

/// The FMU of one scene: its names, rate and variables.
#[derive(Clone, Debug, PartialEq)]
pub struct Model {
    /// `modelName`: the scene's name.
    pub name: String,
    /// `modelIdentifier`: the binary's name in `binaries/linux64/` (a C identifier).
    pub identifier: String,
    /// The scene's description.
    pub description: String,
    /// The plant's controller tick (s): every communication step is a whole number of them.
    pub period: f64,
    /// The scene's duration (s): the default experiment's stop time.
    pub duration: f64,
    /// Bearing planes (1 or 2).
    pub planes: usize,
    /// The variables, by value reference.
    pub variables: Vec<Variable>,
    /// The GUID: a digest of the model description without it and of the whole resolved scene.
    pub guid: String,
}

/// A parameter kind: the last part of its scene key, its unit, bounds and what it is.
struct Kind {
    field: &'static str,
    unit: Option<&'static str>,
    min: f64,
    max: f64,
    what: &'static str,
}

const ROTOR_KEYS: &[Kind] = &[
    Kind { field: "eccentricity_um", unit: Some("um"), min: 0.0, max: 1000.0, what: "static unbalance: eccentricity" },
    Kind {
        field: "couple_unbalance_urad",
        unit: Some("urad"),
        min: -1e5,
        max: 1e5,
        what: "couple unbalance: the principal axis's tilt",
    },
    Kind {
        field: "unbalance_phase_deg",
        unit: Some("deg"),
        min: -360.0,
        max: 360.0,
        what: "unbalance phase from +x at t = 0",
    },
    Kind { field: "speed_hz", unit: Some("Hz"), min: 0.0, max: 1e4, what: "spin speed" },
];

const TOUCHDOWN_KEYS: &[Kind] = &[
    Kind {
        field: "air_gap_mm",
        unit: Some("mm"),
        min: 1e-3,
        max: 10.0,
        what: "radial air gap of the touchdown bearing",
    },
    Kind {
        field: "drag_torque_n_m",
        unit: Some("N.m"),
        min: 0.0,
        max: 100.0,
        what: "drag torque on the touchdown bearing's race",
    },
];

const CONTACT_KEYS: &[Kind] = &[
    Kind {
        field: "friction_static",
        unit: None,
        min: 0.0,
        max: 2.0,
        what: "rotor - race friction coefficient, static",
    },
    Kind {
        field: "friction_dynamic",
        unit: None,
        min: 0.0,
        max: 2.0,
        what: "rotor - race friction coefficient, dynamic",
    },
];

const SHOCK_KEYS: &[Kind] = &[
    Kind { field: "peak_g", unit: Some("g_n"), min: 1e-3, max: 1000.0, what: "peak acceleration" },
    Kind { field: "design_accel_g", unit: Some("g_n"), min: 1e-3, max: 2000.0, what: "design acceleration A_0" },
    Kind { field: "amplitude_g", unit: Some("g_n"), min: 1e-3, max: 1000.0, what: "acceleration amplitude" },
    Kind { field: "scale", unit: None, min: -1000.0, max: 1000.0, what: "factor on the recorded acceleration" },
    Kind { field: "direction_deg", unit: Some("deg"), min: -360.0, max: 360.0, what: "direction from +x" },
    Kind { field: "start_s", unit: Some("s"), min: 0.0, max: 1e6, what: "start time" },
];

/// The units the variables use: name, SI base exponents (kg, m, s, A), factor.
const UNITS: &[(&str, [i32; 4], f64)] = &[
    ("A", [0, 0, 0, 1], 1.0),
    ("V", [1, 2, -3, -1], 1.0),
    ("m", [0, 1, 0, 0], 1.0),
    ("N", [1, 1, -2, 0], 1.0),
    ("N.m", [1, 2, -2, 0], 1.0),
    ("rad", [0, 0, 0, 0], 1.0),
    ("rad/s", [0, 0, -1, 0], 1.0),
    ("s", [0, 0, 1, 0], 1.0),
    ("Hz", [0, 0, -1, 0], 1.0),
    ("um", [0, 1, 0, 0], 1e-6),
    ("mm", [0, 1, 0, 0], 1e-3),
    ("urad", [0, 0, 0, 0], 1e-6),
    ("deg", [0, 0, 0, 0], std::f64::consts::PI / 180.0),
    ("g_n", [0, 1, -2, 0], 9.80665),
];

/// A number of a TOML table at a dotted path.
fn number_at(table: &toml::Table, path: &[&str]) -> Option<f64> {
    let (last, head) = path.split_last()?;
    let mut t = table;
    for p in head {
        t = t.get(*p)?.as_table()?;
    }
    let v = t.get(*last)?;
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
}

/// The FMU's inputs (each axis' current command, starting at its bias `bias` A) and outputs,
/// in their value references' order, for a rotor of `planes` bearing planes.
fn signals(planes: usize, bias: &[f64]) -> Vec<Variable> {
    let mut variables = Vec::new();
    let axis_name = ["x", "y"];
    for axis in 0..2 * planes {
        let (plane, xy) = (PLANES[axis / 2], axis_name[axis % 2]);
        variables.push(Variable {
            name: format!("current_{xy}_{plane}"),
            role: Role::Input(axis),
            unit: Some("A"),
            description: format!(
                "coil current command of bearing {plane}, {xy} axis (as the wire carries it; held over the \
                 step, saturated at controller.current_limit_a)"
            ),
            start: Some(bias[axis]),
            min: None,
            max: None,
        });
    }
    let out = |name: String, o: Output, unit: &'static str, description: String| Variable {
        name,
        role: Role::Output(o),
        unit: Some(unit),
        description,
        start: None,
        min: None,
        max: None,
    };
    for axis in 0..2 * planes {
        let (plane, xy) = (PLANES[axis / 2], axis_name[axis % 2]);
        variables.push(out(
            format!("sensor_{xy}_{plane}"),
            Output::Sensor(axis),
            "V",
            format!("sensor signal of bearing {plane}, {xy} axis, as the controller reads it"),
        ));
    }
    variables.push(out("speed".into(), Output::Speed, "rad/s", "keyphasor: rotor spin speed".into()));
    variables.push(out(
        "angle".into(),
        Output::Angle,
        "rad",
        "keyphasor: rotor angle in [0, 2 pi), 0 when the unbalance points along +x".into(),
    ));
    for (i, plane) in PLANES.iter().enumerate().take(planes) {
        variables.push(out(
            format!("rotor_x_{plane}"),
            Output::RotorX(i),
            "m",
            format!("rotor x at bearing {plane} relative to the housing"),
        ));
        variables.push(out(
            format!("rotor_y_{plane}"),
            Output::RotorY(i),
            "m",
            format!("rotor y at bearing {plane} relative to the housing"),
        ));
        variables.push(out(
            format!("radius_{plane}"),
            Output::Radius(i),
            "m",
            format!("rotor radius at bearing {plane} relative to the housing"),
        ));
        variables.push(out(
            format!("contact_force_{plane}"),
            Output::ContactForce(i),
            "N",
            format!("rotor - race normal force at bearing {plane}"),
        ));
        variables.push(out(
            format!("race_speed_{plane}"),
            Output::RaceSpeed(i),
            "rad/s",
            format!("spin speed of touchdown bearing {plane}'s race"),
        ));
    }
    variables.push(out("housing_x".into(), Output::HousingX, "m", "housing displacement, x".into()));
    variables.push(out("housing_y".into(), Output::HousingY, "m", "housing displacement, y".into()));
    variables
}

/// The scene's numeric keys of [`Kind`]s in its resolved TOML `table`, appended to `variables`
/// as parameters (per plane on a rotor of two `planes`).
fn parameters(table: &toml::Table, planes: usize, variables: &mut Vec<Variable>) {
    let mut param = |key: String, start: f64, k: &Kind, context: &str| {
        variables.push(Variable {
            name: key.clone(),
            role: Role::Parameter(key),
            unit: k.unit,
            description: format!("{context}{} (scene key)", k.what),
            start: Some(start),
            min: Some(k.min.min(start)),
            max: Some(k.max.max(start)),
        });
    };
    for k in ROTOR_KEYS {
        if let Some(v) = number_at(table, &["rotor", k.field]) {
            param(format!("rotor.{}", k.field), v, k, "rotor: ");
        }
    }
    for (section, kinds) in [("touchdown", TOUCHDOWN_KEYS), ("contact", CONTACT_KEYS)] {
        for k in kinds {
            if planes == 1 {
                if let Some(v) = number_at(table, &[section, k.field]) {
                    param(format!("{section}.{}", k.field), v, k, "");
                }
                continue;
            }
            for plane in ["a", "b"] {
                let own = number_at(table, &[section, plane, k.field]);
                if let Some(v) = own.or_else(|| number_at(table, &[section, k.field])) {
                    param(format!("{section}.{plane}.{}", k.field), v, k, &format!("bearing {plane}: "));
                }
            }
        }
    }
    let shocks = table.get("shock").and_then(|s| s.as_array()).cloned().unwrap_or_default();
    for (i, shock) in shocks.iter().enumerate() {
        let Some(t) = shock.as_table() else { continue };
        for k in SHOCK_KEYS {
            if let Some(v) = number_at(t, &[k.field]) {
                param(format!("shock[{i}].{}", k.field), v, k, &format!("shock {i}: "));
            }
        }
    }
}

/// The plane words of a parameter key and the letters of the outputs.
const PLANES: [&str; 2] = ["A", "B"];

impl Model {
    /// The FMU of `scene` (its parameters those of [`Kind`]s the scene has).
    pub fn of(scene: &Scene) -> Result<Self, String> {
        let planes = scene.planes();
        let bias = crate::run::bias_of(scene, &crate::run::plane_gains(scene).map_err(|e| e.to_string())?);
        let mut variables = signals(planes, &bias);
        let text = scene.to_toml().map_err(|e| e.to_string())?;
        let table: toml::Table = toml::from_str(&text).map_err(|e| e.to_string())?;
        parameters(&table, planes, &mut variables);
        let identifier = identifier_of(&scene.name);
        let mut model = Model {
            name: scene.name.clone(),
            identifier,
            description: scene.description.clone(),
            period: scene.controller.period,
            duration: scene.duration,
            planes,
            variables,
            guid: String::new(),
        };
        // The whole resolved scene, not only the description's variables: an edited
        // resources/scene.toml (rotor.mass_kg, integrator.method: no FMU variable) made
        // another plant under the same GUID (issue 40 item 4).
        let digest = Sha256::digest(format!("{}\n{}", model.xml(), portable(&table)?).as_bytes());
        let h: String = digest.iter().take(16).map(|b| format!("{b:02x}")).collect();
        model.guid = format!("{{{}-{}-{}-{}-{}}}", &h[0..8], &h[8..12], &h[12..16], &h[16..20], &h[20..32]);
        Ok(model)
    }

    /// The variable of value reference `vr`.
    pub fn variable(&self, vr: u32) -> Option<&Variable> {
        self.variables.get(vr as usize)
    }

    /// `modelDescription.xml`.
    pub fn xml(&self) -> String {
        let mut x = String::new();
        x.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        x.push_str(&format!(
            "<fmiModelDescription fmiVersion=\"{FMI_VERSION}\" modelName=\"{}\" guid=\"{}\" description=\"{}\" \
             generationTool=\"plant {} (amb-touchdown-testbed)\" variableNamingConvention=\"flat\" \
             numberOfEventIndicators=\"0\">\n",
            esc(&self.name),
            esc(&self.guid),
            esc(&self.description),
            env!("CARGO_PKG_VERSION")
        ));
        x.push_str(&format!(
            "  <CoSimulation modelIdentifier=\"{}\" needsExecutionTool=\"false\" \
             canHandleVariableCommunicationStepSize=\"true\" canInterpolateInputs=\"false\" \
             maxOutputDerivativeOrder=\"0\" canRunAsynchronuously=\"false\" \
             canBeInstantiatedOnlyOncePerProcess=\"false\" canNotUseMemoryManagementFunctions=\"true\" \
             canGetAndSetFMUstate=\"true\" canSerializeFMUstate=\"true\" \
             providesDirectionalDerivative=\"false\"/>\n",
            self.identifier
        ));
        x.push_str(&self.units_and_categories());
        x.push_str("  <ModelVariables>\n");
        for (vr, v) in self.variables.iter().enumerate() {
            let (causality, variability, initial) = match v.role {
                Role::Input(_) => ("input", "continuous", None),
                Role::Output(_) => ("output", "continuous", Some("calculated")),
                Role::Parameter(_) => ("parameter", "fixed", Some("exact")),
            };
            x.push_str(&format!(
                "    <!-- index {} -->\n    <ScalarVariable name=\"{}\" valueReference=\"{vr}\" \
                 description=\"{}\" causality=\"{causality}\" variability=\"{variability}\"{}>\n      <Real",
                vr + 1,
                esc(&v.name),
                esc(&v.description),
                initial.map(|i| format!(" initial=\"{i}\"")).unwrap_or_default()
            ));
            if let Some(u) = v.unit {
                x.push_str(&format!(" unit=\"{}\"", esc(u)));
            }
            for (attr, value) in [("start", v.start), ("min", v.min), ("max", v.max)] {
                if let Some(value) = value {
                    x.push_str(&format!(" {attr}=\"{value:?}\""));
                }
            }
            x.push_str("/>\n    </ScalarVariable>\n");
        }
        x.push_str("  </ModelVariables>\n  <ModelStructure>\n    <Outputs>\n");
        let outputs: Vec<usize> =
            (0..self.variables.len()).filter(|&i| matches!(self.variables[i].role, Role::Output(_))).collect();
        // No output depends on an input at the same communication point (no direct feedthrough).
        for i in &outputs {
            x.push_str(&format!("      <Unknown index=\"{}\" dependencies=\"\"/>\n", i + 1));
        }
        x.push_str("    </Outputs>\n    <InitialUnknowns>\n");
        for i in &outputs {
            x.push_str(&format!("      <Unknown index=\"{}\"/>\n", i + 1));
        }
        x.push_str("    </InitialUnknowns>\n  </ModelStructure>\n</fmiModelDescription>\n");
        x
    }
}

impl Model {
    /// `modelDescription.xml` of the FMI 3.0 FMU: the same variables as `Float64`, the
    /// independent variable `time` after them, `fixedInternalStepSize` the plant's tick.
    pub fn xml3(&self) -> String {
        let mut x = String::new();
        x.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        x.push_str(&format!(
            "<fmiModelDescription fmiVersion=\"3.0\" modelName=\"{}\" instantiationToken=\"{}\" description=\"{}\" \
             generationTool=\"plant {} (amb-touchdown-testbed)\" variableNamingConvention=\"flat\">\n",
            esc(&self.name),
            esc(&self.guid),
            esc(&self.description),
            env!("CARGO_PKG_VERSION")
        ));
        x.push_str(&format!(
            "  <CoSimulation modelIdentifier=\"{}\" needsExecutionTool=\"false\" \
             canBeInstantiatedOnlyOncePerProcess=\"false\" canGetAndSetFMUState=\"true\" \
             canSerializeFMUState=\"true\" providesDirectionalDerivatives=\"false\" \
             providesAdjointDerivatives=\"false\" canHandleVariableCommunicationStepSize=\"true\" \
             fixedInternalStepSize=\"{:?}\" maxOutputDerivativeOrder=\"0\" providesIntermediateUpdate=\"false\" \
             canReturnEarlyAfterIntermediateUpdate=\"false\" hasEventMode=\"false\"/>\n",
            self.identifier, self.period
        ));
        x.push_str(&self.units_and_categories());
        x.push_str("  <ModelVariables>\n");
        for (vr, v) in self.variables.iter().enumerate() {
            let (causality, variability, initial) = match v.role {
                Role::Input(_) => ("input", "continuous", None),
                Role::Output(_) => ("output", "continuous", Some("calculated")),
                Role::Parameter(_) => ("parameter", "fixed", Some("exact")),
            };
            x.push_str(&format!(
                "    <Float64 name=\"{}\" valueReference=\"{vr}\" description=\"{}\" causality=\"{causality}\" \
                 variability=\"{variability}\"{}",
                esc(&v.name),
                esc(&v.description),
                initial.map(|i| format!(" initial=\"{i}\"")).unwrap_or_default()
            ));
            if let Some(u) = v.unit {
                x.push_str(&format!(" unit=\"{}\"", esc(u)));
            }
            for (attr, value) in [("start", v.start), ("min", v.min), ("max", v.max)] {
                if let Some(value) = value {
                    x.push_str(&format!(" {attr}=\"{value:?}\""));
                }
            }
            x.push_str("/>\n");
        }
        x.push_str(&format!(
            "    <Float64 name=\"time\" valueReference=\"{}\" description=\"simulated time\" \
             causality=\"independent\" variability=\"continuous\" unit=\"s\"/>\n",
            self.variables.len()
        ));
        x.push_str("  </ModelVariables>\n  <ModelStructure>\n");
        let outputs: Vec<usize> =
            (0..self.variables.len()).filter(|&i| matches!(self.variables[i].role, Role::Output(_))).collect();
        for i in &outputs {
            x.push_str(&format!("    <Output valueReference=\"{i}\" dependencies=\"\"/>\n"));
        }
        for i in &outputs {
            x.push_str(&format!("    <InitialUnknown valueReference=\"{i}\"/>\n"));
        }
        x.push_str("  </ModelStructure>\n</fmiModelDescription>\n");
        x
    }

    /// `<UnitDefinitions>`, `<LogCategories>` and `<DefaultExperiment>`, as both versions
    /// write them.
    fn units_and_categories(&self) -> String {
        let mut x = String::new();
        let mut units: Vec<&str> = self.variables.iter().filter_map(|v| v.unit).collect();
        units.push("s");
        x.push_str("  <UnitDefinitions>\n");
        for (name, [kg, m, s, a], factor) in UNITS.iter().filter(|u| units.contains(&u.0)) {
            let mut base = String::new();
            for (attr, e) in [("kg", kg), ("m", m), ("s", s), ("A", a)] {
                if *e != 0 {
                    base.push_str(&format!(" {attr}=\"{e}\""));
                }
            }
            if *name == "rad" || *name == "rad/s" || *name == "urad" || *name == "deg" {
                base.push_str(" rad=\"1\"");
            }
            if *factor != 1.0 {
                base.push_str(&format!(" factor=\"{factor:?}\""));
            }
            x.push_str(&format!("    <Unit name=\"{}\"><BaseUnit{base}/></Unit>\n", esc(name)));
        }
        x.push_str("  </UnitDefinitions>\n");
        x.push_str("  <LogCategories>\n");
        for (name, what) in LOG_CATEGORIES {
            x.push_str(&format!("    <Category name=\"{name}\" description=\"{}\"/>\n", esc(what)));
        }
        x.push_str("  </LogCategories>\n");
        x.push_str(&format!(
            "  <DefaultExperiment startTime=\"0.0\" stopTime=\"{:?}\" stepSize=\"{:?}\"/>\n",
            self.duration, self.period
        ));
        x
    }
}

/// Which FMI standard an FMU file follows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fmi {
    /// FMI 2.0 co-simulation (`binaries/linux64/`).
    V2,
    /// FMI 3.0 co-simulation (`binaries/x86_64-linux/`).
    V3,
}

impl Fmi {
    /// The version's number, as `fmiVersion` writes it.
    pub fn version(self) -> &'static str {
        match self {
            Fmi::V2 => "2.0",
            Fmi::V3 => "3.0",
        }
    }

    /// The folder of the binary inside the FMU.
    pub fn platform(self) -> &'static str {
        match self {
            Fmi::V2 => "linux64",
            Fmi::V3 => "x86_64-linux",
        }
    }
}

/// The log categories the FMU declares (`fmi2SetDebugLogging` takes them).
pub const LOG_CATEGORIES: [(&str, &str); 3] = [
    ("logStatusError", "calls refused and failures (always logged)"),
    ("logStatusWarning", "warnings"),
    ("logAll", "every call's outcome, when debug logging is on"),
];

/// A C identifier from a scene name: `plant_` and its letters, digits and underscores.
pub fn identifier_of(name: &str) -> String {
    let body: String = name.chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '_' }).collect();
    format!("plant_{body}")
}

/// XML attribute text.
fn esc(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&apos;"),
            '\n' => o.push_str("&#10;"),
            c if (c as u32) < 0x20 => o.push(' '),
            c => o.push(c),
        }
    }
    o
}

/// The scene of an FMU's `resources/` with its parameters set (`key=value` overrides): what
/// the binary steps. Errors name the key, value and unit ([`crate::config::ConfigError`]).
pub fn load_fmu_scene(resources: &Path, overrides: &[String]) -> Result<Scene, crate::config::ConfigError> {
    load_scene(&resources.join("scene.toml"), overrides)
}

/// The files a resolved scene reads: each one's place in the table (a recorded shock's `file`,
/// `rotor.ross_file`), as a path of keys, and the path written there.
pub fn files_read(table: &toml::Table) -> Vec<(Vec<String>, String)> {
    let mut files = Vec::new();
    let shocks = table.get("shock").and_then(|s| s.as_array()).map(Vec::as_slice).unwrap_or_default();
    for (i, shock) in shocks.iter().enumerate() {
        if let Some(file) = shock.get("file").and_then(|f| f.as_str()) {
            files.push((vec!["shock".into(), i.to_string(), "file".into()], file.to_owned()));
        }
    }
    if let Some(file) = table.get("rotor").and_then(|r| r.get("ross_file")).and_then(|f| f.as_str()) {
        files.push((vec!["rotor".into(), "ross_file".into()], file.to_owned()));
    }
    files
}

/// Sets the string at `keys` (a table key, or an array index) in `table`.
pub fn set_at(table: &mut toml::Table, keys: &[String], value: String) {
    let Some((last, walk)) = keys.split_last() else { return };
    let mut at: &mut toml::Value = match table.get_mut(&walk[0]) {
        Some(v) => v,
        None => return,
    };
    for k in &walk[1..] {
        let next = match at {
            toml::Value::Array(a) => k.parse::<usize>().ok().and_then(|i| a.get_mut(i)),
            toml::Value::Table(t) => t.get_mut(k),
            _ => None,
        };
        match next {
            Some(v) => at = v,
            None => return,
        }
    }
    if let toml::Value::Table(t) = at {
        t.insert(last.clone(), toml::Value::String(value));
    }
}

/// The resolved scene with each file it reads named by the SHA-256 of its bytes instead of its
/// path: what the GUID covers. The paths differ between where `plant fmu` stages the FMU and
/// where an importer unpacks it (a GUID over them refused every FMU with a recorded shock at
/// `fmi2Instantiate`); the bytes do not, and an edited file in `resources/` changes the GUID.
fn portable(table: &toml::Table) -> Result<String, String> {
    let mut t = table.clone();
    for (keys, file) in files_read(table) {
        let bytes = shock_table::input::read_bytes(Path::new(&file), MAX_FILE_BYTES)
            .map_err(|e| format!("{} = {file}: {e}", keys.join(".")))?;
        let hex: String = Sha256::digest(&bytes).iter().map(|b| format!("{b:02x}")).collect();
        set_at(&mut t, &keys, format!("sha256:{hex}"));
    }
    toml::to_string(&t).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The names of a planar and a two-plane scene's FMU, and its description's GUID from the
    /// description itself: a change of any variable changes it.
    #[test]
    fn the_variables_of_a_planar_and_a_two_plane_fmu() {
        let planar = Model::of(&crate::config::shipped("cosim-10g.toml", &[])).unwrap();
        let names: Vec<&str> = planar.variables.iter().map(|v| v.name.as_str()).collect();
        for n in [
            "current_x_A",
            "current_y_A",
            "sensor_x_A",
            "sensor_y_A",
            "speed",
            "angle",
            "radius_A",
            "contact_force_A",
            "race_speed_A",
            "housing_x",
            "housing_y",
            "rotor.eccentricity_um",
            "touchdown.air_gap_mm",
            "contact.friction_static",
            "shock[0].peak_g",
            "shock[0].direction_deg",
        ] {
            assert!(names.contains(&n), "{n} in {names:?}");
        }
        assert!(!names.iter().any(|n| n.ends_with("_B")), "{names:?}");
        let two = Model::of(&crate::config::shipped("two-plane-asymmetric-10g.toml", &[])).unwrap();
        let find = |n: &str| two.variables.iter().find(|v| v.name == n).unwrap_or_else(|| panic!("{n}"));
        assert_eq!(find("touchdown.b.air_gap_mm").start, Some(0.25));
        assert_eq!(find("touchdown.a.air_gap_mm").start, Some(0.15));
        assert_eq!(find("contact.a.friction_static").start, Some(0.3));
        assert_eq!(find("contact.b.friction_static").start, Some(0.1));
        find("sensor_y_B");
        find("radius_B");
        let other = Model::of(&crate::config::shipped("cosim-10g.toml", &["shock[0].peak_g=12.0"])).unwrap();
        assert_ne!(other.guid, planar.guid);
        assert_eq!(planar.guid, Model::of(&crate::config::shipped("cosim-10g.toml", &[])).unwrap().guid);
    }
}
