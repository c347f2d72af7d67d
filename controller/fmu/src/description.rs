//! `modelDescription.xml`: what the host needs of it (FMI 2.0 and 3.0): the version, the
//! instantiation token, the model identifiers of the interfaces the FMU offers, its scalar
//! variables (name, value reference, causality, type) and, for model exchange, the number of
//! continuous states.

/// The FMI version of an FMU.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FmiVersion {
    /// FMI 2.0.
    Two,
    /// FMI 3.0.
    Three,
}

impl FmiVersion {
    /// `2.0` or `3.0`.
    pub fn label(self) -> &'static str {
        match self {
            FmiVersion::Two => "2.0",
            FmiVersion::Three => "3.0",
        }
    }

    /// The folder under `binaries/` of Linux x86-64 shared libraries.
    pub fn platform(self) -> &'static str {
        match self {
            FmiVersion::Two => "linux64",
            FmiVersion::Three => "x86_64-linux",
        }
    }
}

/// A variable's causality (what the host may do with it).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Causality {
    /// An input: set by the host.
    Input,
    /// An output: read by the host.
    Output,
    /// A parameter: settable before initialisation (`[controller.params]`).
    Parameter,
    /// Any other (local, independent, calculatedParameter, structuralParameter).
    Other(String),
}

/// A variable's type (FMI 2.0 `Real` is `Float64`, `Integer` is `Int32`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum VarType {
    /// A 64-bit float (FMI 2.0 `Real`, FMI 3.0 `Float64`).
    Float64,
    /// A 32-bit integer (FMI 2.0 `Integer` and `Enumeration`, FMI 3.0 `Int32`).
    Int32,
    /// A boolean.
    Boolean,
    /// A string.
    String,
    /// Another type (set and read by no signal here).
    Other(String),
}

impl VarType {
    /// The type's name as the modelDescription writes it.
    pub fn label(&self, version: FmiVersion) -> &str {
        match (self, version) {
            (VarType::Float64, FmiVersion::Two) => "Real",
            (VarType::Float64, FmiVersion::Three) => "Float64",
            (VarType::Int32, FmiVersion::Two) => "Integer",
            (VarType::Int32, FmiVersion::Three) => "Int32",
            (VarType::Boolean, _) => "Boolean",
            (VarType::String, _) => "String",
            (VarType::Other(s), _) => s,
        }
    }
}

/// One scalar variable.
#[derive(Clone, Debug, PartialEq)]
pub struct Variable {
    /// Its name.
    pub name: String,
    /// Its value reference.
    pub vr: u32,
    /// Its causality.
    pub causality: Causality,
    /// Its type.
    pub ty: VarType,
    /// An array (FMI 3.0 `Dimension`): never a signal here.
    pub array: bool,
}

/// What the host reads from `modelDescription.xml`.
#[derive(Clone, Debug, PartialEq)]
pub struct Description {
    /// FMI version.
    pub version: FmiVersion,
    /// `modelName`.
    pub model_name: String,
    /// `guid` (2.0) or `instantiationToken` (3.0).
    pub token: String,
    /// The co-simulation interface's `modelIdentifier`, if offered.
    pub co_simulation: Option<String>,
    /// The model-exchange interface's `modelIdentifier`, if offered.
    pub model_exchange: Option<String>,
    /// The variables, in document order.
    pub variables: Vec<Variable>,
    /// Continuous states (model exchange: `ModelStructure/Derivatives`).
    pub states: usize,
}

impl Description {
    /// Parses a modelDescription document; refuses FMI 1.0 and other versions.
    pub fn parse(xml: &str) -> Result<Self, String> {
        let doc = roxmltree::Document::parse(xml).map_err(|e| format!("modelDescription.xml is not valid XML: {e}"))?;
        let root = doc.root_element();
        if root.tag_name().name() != "fmiModelDescription" {
            return Err(format!(
                "modelDescription.xml: the root element is <{}>, not <fmiModelDescription>",
                root.tag_name().name()
            ));
        }
        let version_text = root.attribute("fmiVersion").unwrap_or("");
        let version = if version_text.starts_with("2.") {
            FmiVersion::Two
        } else if version_text.starts_with("3.") {
            FmiVersion::Three
        } else if version_text.starts_with("1.") {
            return Err(format!(
                "fmiVersion = \"{version_text}\": FMI 1.0 is not supported (export the FMU as FMI 2.0 or 3.0)"
            ));
        } else {
            return Err(format!("fmiVersion = \"{version_text}\": not an FMI version this host runs (2.0, 3.0)"));
        };
        let token_key = if version == FmiVersion::Two { "guid" } else { "instantiationToken" };
        let token = root.attribute(token_key).unwrap_or("").to_string();
        let interface = |name: &str| {
            root.children()
                .find(|n| n.has_tag_name(name))
                .map(|n| n.attribute("modelIdentifier").unwrap_or("").to_string())
        };
        let co_simulation = interface("CoSimulation");
        let model_exchange = interface("ModelExchange");
        let mut variables = Vec::new();
        if let Some(list) = root.children().find(|n| n.has_tag_name("ModelVariables")) {
            for node in list.children().filter(roxmltree::Node::is_element) {
                let (ty, array) = match version {
                    FmiVersion::Two => {
                        let Some(t) = node.children().find(roxmltree::Node::is_element) else { continue };
                        let ty = match t.tag_name().name() {
                            "Real" => VarType::Float64,
                            "Integer" | "Enumeration" => VarType::Int32,
                            "Boolean" => VarType::Boolean,
                            "String" => VarType::String,
                            other => VarType::Other(other.to_string()),
                        };
                        (ty, false)
                    }
                    FmiVersion::Three => {
                        let ty = match node.tag_name().name() {
                            "Float64" => VarType::Float64,
                            "Int32" | "Enumeration" => VarType::Int32,
                            "Boolean" => VarType::Boolean,
                            "String" => VarType::String,
                            other => VarType::Other(other.to_string()),
                        };
                        (ty, node.children().any(|c| c.has_tag_name("Dimension")))
                    }
                };
                let name = node.attribute("name").unwrap_or("").to_string();
                let vr = node
                    .attribute("valueReference")
                    .and_then(|v| v.trim().parse::<u32>().ok())
                    .ok_or_else(|| format!("modelDescription.xml: variable `{name}` has no valid valueReference"))?;
                let causality = match node.attribute("causality").unwrap_or("local") {
                    "input" => Causality::Input,
                    "output" => Causality::Output,
                    "parameter" => Causality::Parameter,
                    other => Causality::Other(other.to_string()),
                };
                variables.push(Variable { name, vr, causality, ty, array });
            }
        }
        let structure = root.children().find(|n| n.has_tag_name("ModelStructure"));
        let states = match (version, structure) {
            (FmiVersion::Two, Some(s)) => s
                .children()
                .find(|n| n.has_tag_name("Derivatives"))
                .map_or(0, |d| d.children().filter(|n| n.has_tag_name("Unknown")).count()),
            (FmiVersion::Three, Some(s)) => {
                s.children().filter(|n| n.has_tag_name("ContinuousStateDerivative")).count()
            }
            (_, None) => 0,
        };
        Ok(Self {
            version,
            model_name: root.attribute("modelName").unwrap_or("").to_string(),
            token,
            co_simulation,
            model_exchange,
            variables,
            states,
        })
    }

    /// The variable named `name`.
    pub fn variable(&self, name: &str) -> Option<&Variable> {
        self.variables.iter().find(|v| v.name == name)
    }

    /// The names of the variables of a causality, for messages ("none" when empty).
    pub fn names_of(&self, causality: &Causality) -> String {
        let names: Vec<&str> =
            self.variables.iter().filter(|v| &v.causality == causality).map(|v| v.name.as_str()).collect();
        if names.is_empty() {
            "none".into()
        } else {
            names.join(", ")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fmi2_and_fmi3_documents_are_read_and_fmi1_refused() {
        let two = r#"<?xml version="1.0"?>
<fmiModelDescription fmiVersion="2.0" modelName="pd" guid="{abc}">
  <CoSimulation modelIdentifier="pd_cs"/>
  <ModelExchange modelIdentifier="pd_me"/>
  <ModelVariables>
    <ScalarVariable name="sensor_x" valueReference="1" causality="input"><Real start="0"/></ScalarVariable>
    <ScalarVariable name="current_x" valueReference="2" causality="output"><Real/></ScalarVariable>
    <ScalarVariable name="fault" valueReference="3" causality="parameter" variability="fixed"><Integer start="0"/></ScalarVariable>
    <ScalarVariable name="x" valueReference="4"><Real/></ScalarVariable>
    <ScalarVariable name="der(x)" valueReference="5"><Real derivative="4"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="2"/></Outputs><Derivatives><Unknown index="5"/></Derivatives></ModelStructure>
</fmiModelDescription>"#;
        let d = Description::parse(two).unwrap();
        assert_eq!((d.version, d.token.as_str(), d.states), (FmiVersion::Two, "{abc}", 1));
        assert_eq!((d.co_simulation.as_deref(), d.model_exchange.as_deref()), (Some("pd_cs"), Some("pd_me")));
        let f = d.variable("fault").unwrap();
        assert_eq!((f.vr, &f.causality, &f.ty), (3, &Causality::Parameter, &VarType::Int32));
        assert_eq!(d.names_of(&Causality::Input), "sensor_x");
        let three = r#"<fmiModelDescription fmiVersion="3.0" modelName="pd" instantiationToken="tok">
  <CoSimulation modelIdentifier="pd3"/>
  <ModelVariables>
    <Float64 name="time" valueReference="0" causality="independent"/>
    <Float64 name="sensor_x" valueReference="1" causality="input" start="0"/>
    <Float64 name="v" valueReference="9" causality="output"><Dimension start="2"/></Float64>
    <Boolean name="on" valueReference="2" causality="parameter" variability="fixed" start="true"/>
  </ModelVariables>
</fmiModelDescription>"#;
        let d = Description::parse(three).unwrap();
        assert_eq!((d.version, d.token.as_str(), d.model_exchange.is_none()), (FmiVersion::Three, "tok", true));
        assert_eq!(d.variable("on").unwrap().ty, VarType::Boolean);
        assert!(d.variable("v").unwrap().array);
        let one = r#"<fmiModelDescription fmiVersion="1.0" modelName="old" guid="x"/>"#;
        assert!(Description::parse(one).unwrap_err().contains("FMI 1.0 is not supported"));
        assert!(Description::parse("<a").unwrap_err().contains("not valid XML"));
    }
}
