//! A shaft described by a table of elements, as a scene embeds it (serde, SI with the unit in
//! each key's name, lengths in mm):
//!
//! ```toml
//! [materials.steel]
//! density_kg_m3 = 7810.0
//! modulus_pa = 211e9
//! shear_modulus_pa = 81.2e9      # or poisson = 0.3
//!
//! [[element]]                    # from the left end; element i joins nodes i and i + 1
//! length_mm = 50.0
//! outer_diameter_mm = 40.0
//! inner_diameter_mm = 0.0        # default 0
//! material = "steel"
//! split = 2                      # optional: two equal elements of 25 mm
//!
//! [[disk]]
//! node = 3
//! mass_kg = 4.0
//! diametral_inertia_kg_m2 = 0.01
//! polar_inertia_kg_m2 = 0.02
//!
//! [[bearing]]                    # linear springs to the ground (optional)
//! node = 1
//! stiffness_n_per_m = 1e6
//! ```
//!
//! Node numbers count the elements after their splits. Every error names the key, its value
//! and unit.

use super::rotor::{Disk, LinearBearing, Rotor};
use super::shaft::{Material, ShaftElement, ShearMethod};
use super::FlexError;
use std::collections::BTreeMap;

/// A material: density and two of modulus, shear modulus and Poisson's ratio.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialRow {
    /// Density (kg/m³).
    pub density_kg_m3: Option<f64>,
    /// Young's modulus (Pa).
    pub modulus_pa: Option<f64>,
    /// Shear modulus (Pa).
    pub shear_modulus_pa: Option<f64>,
    /// Poisson's ratio (when the shear modulus is not given).
    pub poisson: Option<f64>,
}

/// One row of the element table.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ElementRow {
    /// Length (mm).
    pub length_mm: f64,
    /// Outer diameter at the left end (mm).
    pub outer_diameter_mm: f64,
    /// Inner diameter at the left end (mm).
    #[serde(default)]
    pub inner_diameter_mm: f64,
    /// Outer diameter at the right end (mm); the left one if absent (a cylinder).
    pub outer_diameter_right_mm: Option<f64>,
    /// Inner diameter at the right end (mm); the left one if absent.
    pub inner_diameter_right_mm: Option<f64>,
    /// The material's name in `materials`.
    pub material: String,
    /// Split into this many equal elements (cylinders only); 1 if absent.
    pub split: Option<usize>,
}

/// A rigid disk.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiskRow {
    /// Node.
    pub node: usize,
    /// Mass (kg).
    pub mass_kg: f64,
    /// Diametral moment of inertia (kg·m²).
    pub diametral_inertia_kg_m2: f64,
    /// Polar moment of inertia (kg·m²).
    pub polar_inertia_kg_m2: f64,
}

/// A linear, isotropic bearing to the ground.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BearingRow {
    /// Node.
    pub node: usize,
    /// Stiffness (N/m).
    pub stiffness_n_per_m: f64,
    /// Damping (N·s/m).
    #[serde(default)]
    pub damping_n_s_per_m: f64,
}

/// The table.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShaftTable {
    /// Materials by name.
    pub materials: BTreeMap<String, MaterialRow>,
    /// Elements, left to right.
    #[serde(rename = "element")]
    pub elements: Vec<ElementRow>,
    /// Disks.
    #[serde(default, rename = "disk")]
    pub disks: Vec<DiskRow>,
    /// Linear bearings.
    #[serde(default, rename = "bearing")]
    pub bearings: Vec<BearingRow>,
    /// Shear coefficient formula (`cowper`, ROSS's default, or `hutchinson`).
    #[serde(default)]
    pub shear_method: ShearMethod,
}

fn positive(element: String, key: &'static str, value: f64, unit: &'static str) -> Result<(), FlexError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(FlexError::NotPositive { element, key, value, unit })
    }
}

impl MaterialRow {
    /// The material, or an error naming `materials.<name>.<key>`.
    pub fn material(&self, name: &str) -> Result<Material, FlexError> {
        let at = format!("materials.{name}");
        let missing = |key: &'static str, unit: &'static str| FlexError::Material {
            element: at.clone(),
            key,
            value: f64::NAN,
            unit,
        };
        let density = self.density_kg_m3.ok_or_else(|| missing("density_kg_m3", "kg/m³"))?;
        let modulus = self.modulus_pa.ok_or_else(|| missing("modulus_pa", "Pa"))?;
        for (key, v, unit) in [("density_kg_m3", density, "kg/m³"), ("modulus_pa", modulus, "Pa")] {
            if !(v.is_finite() && v > 0.0) {
                return Err(FlexError::Material { element: at.clone(), key, value: v, unit });
            }
        }
        let shear_modulus = match (self.shear_modulus_pa, self.poisson) {
            (Some(g), _) => g,
            (None, Some(nu)) => {
                if !(nu.is_finite() && nu > -1.0 && nu < 0.5) {
                    return Err(FlexError::Material { element: at, key: "poisson", value: nu, unit: "" });
                }
                modulus / (2.0 * (1.0 + nu))
            }
            (None, None) => return Err(missing("shear_modulus_pa (or poisson)", "Pa")),
        };
        if !(shear_modulus.is_finite() && shear_modulus > 0.0) {
            return Err(FlexError::Material { element: at, key: "shear_modulus_pa", value: shear_modulus, unit: "Pa" });
        }
        Ok(Material { density, modulus, shear_modulus })
    }
}

impl ShaftTable {
    /// The rotor the table describes (validated).
    pub fn rotor(&self) -> Result<Rotor, FlexError> {
        // Counted before any element is made: `split = 10^12` must not allocate first.
        let count = self.elements.iter().fold(0usize, |n, row| n.saturating_add(row.split.unwrap_or(1)));
        if count > super::MAX_ELEMENTS {
            return Err(FlexError::TooManyElements { count, limit: super::MAX_ELEMENTS });
        }
        let mut elements = Vec::new();
        for (i, row) in self.elements.iter().enumerate() {
            let at = || format!("element[{i}]");
            positive(at(), "length_mm", row.length_mm, "mm")?;
            positive(at(), "outer_diameter_mm", row.outer_diameter_mm, "mm")?;
            let outer_right = row.outer_diameter_right_mm.unwrap_or(row.outer_diameter_mm);
            positive(at(), "outer_diameter_right_mm", outer_right, "mm")?;
            let inner_right = row.inner_diameter_right_mm.unwrap_or(row.inner_diameter_mm);
            for (key, inner, outer) in [
                ("inner_diameter_mm", row.inner_diameter_mm, row.outer_diameter_mm),
                ("inner_diameter_right_mm", inner_right, outer_right),
            ] {
                if !(inner.is_finite() && inner >= 0.0 && inner < outer) {
                    return Err(FlexError::InnerDiameter {
                        element: at(),
                        key,
                        value: inner * 1e-3,
                        outer: outer * 1e-3,
                    });
                }
            }
            let material = self
                .materials
                .get(&row.material)
                .ok_or_else(|| FlexError::Ross {
                    file: "shaft table".into(),
                    message: format!("{}: material = \"{}\" is not in [materials]", at(), row.material),
                })?
                .material(&row.material)?;
            let split = row.split.unwrap_or(1);
            if split == 0
                || (split > 1 && (outer_right != row.outer_diameter_mm || inner_right != row.inner_diameter_mm))
            {
                return Err(FlexError::Value {
                    key: "split (a positive count, cylinders only)",
                    value: split as f64,
                    unit: "",
                });
            }
            for _ in 0..split {
                let mut el = ShaftElement::cylinder(
                    row.length_mm * 1e-3 / split as f64,
                    row.inner_diameter_mm * 1e-3,
                    row.outer_diameter_mm * 1e-3,
                    material,
                );
                el.outer_right = outer_right * 1e-3;
                el.inner_right = inner_right * 1e-3;
                el.shear_method = self.shear_method;
                elements.push(el);
            }
        }
        let nodes = elements.len() + 1;
        let mut disks = Vec::new();
        for (i, d) in self.disks.iter().enumerate() {
            if d.node >= nodes {
                return Err(FlexError::NodeOutOfRange { what: format!("disk[{i}].node"), node: d.node, nodes });
            }
            positive(format!("disk[{i}]"), "mass_kg", d.mass_kg, "kg")?;
            positive(format!("disk[{i}]"), "diametral_inertia_kg_m2", d.diametral_inertia_kg_m2, "kg·m²")?;
            positive(format!("disk[{i}]"), "polar_inertia_kg_m2", d.polar_inertia_kg_m2, "kg·m²")?;
            disks.push(Disk {
                node: d.node,
                mass: d.mass_kg,
                diametral_inertia: d.diametral_inertia_kg_m2,
                polar_inertia: d.polar_inertia_kg_m2,
            });
        }
        let mut bearings = Vec::new();
        for (i, b) in self.bearings.iter().enumerate() {
            if b.node >= nodes {
                return Err(FlexError::NodeOutOfRange { what: format!("bearing[{i}].node"), node: b.node, nodes });
            }
            positive(format!("bearing[{i}]"), "stiffness_n_per_m", b.stiffness_n_per_m, "N/m")?;
            let mut lb = LinearBearing::spring(b.node, b.stiffness_n_per_m);
            lb.damping = [[b.damping_n_s_per_m, 0.0], [0.0, b.damping_n_s_per_m]];
            bearings.push(lb);
        }
        let rotor = Rotor { elements, disks, bearings, alpha: 0.0, beta: 0.0 };
        rotor.validate()?;
        Ok(rotor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The element bound holds for a rotor however it is made: a table's splits are counted
    /// before any element is made, a rotor given whole (a ROSS file's) is refused by `validate`.
    #[test]
    fn a_shaft_past_the_element_bound_is_refused() {
        let steel = Material { density: 7810.0, modulus: 211e9, shear_modulus: 81.2e9 };
        let rotor = |n: usize| Rotor {
            elements: vec![ShaftElement::cylinder(1e-3, 0.0, 0.04, steel); n],
            disks: Vec::new(),
            bearings: Vec::new(),
            alpha: 0.0,
            beta: 0.0,
        };
        assert_eq!(rotor(super::super::MAX_ELEMENTS).validate(), Ok(()));
        let e = rotor(super::super::MAX_ELEMENTS + 1).validate().unwrap_err();
        assert_eq!(e, FlexError::TooManyElements { count: 2001, limit: 2000 });
        assert!(e.to_string().contains("the shaft has 2001 elements, more than the 2000"), "{e}");
    }

    const TABLE: &str = r#"
        [materials.steel]
        density_kg_m3 = 7810.0
        modulus_pa = 211e9
        shear_modulus_pa = 81.2e9

        [[element]]
        length_mm = 100.0
        outer_diameter_mm = 40.0
        material = "steel"
        split = 4

        [[element]]
        length_mm = 50.0
        outer_diameter_mm = 40.0
        outer_diameter_right_mm = 30.0
        inner_diameter_mm = 10.0
        material = "steel"

        [[disk]]
        node = 2
        mass_kg = 2.0
        diametral_inertia_kg_m2 = 1e-3
        polar_inertia_kg_m2 = 2e-3
    "#;

    fn table() -> ShaftTable {
        toml::from_str(TABLE).unwrap()
    }

    #[test]
    fn a_table_builds_its_rotor() {
        let rotor = table().rotor().unwrap();
        assert_eq!(rotor.node_count(), 6);
        let z = rotor.node_positions();
        assert!((z[4] - 0.1).abs() < 1e-12 && (z[5] - 0.15).abs() < 1e-12, "{z:?}");
        let shaft = 7810.0 * std::f64::consts::PI * 0.02f64.powi(2) * 0.1;
        let cone = 7810.0 * std::f64::consts::PI * 0.05 / 12.0
            * ((0.04f64.powi(2) + 0.04 * 0.03 + 0.03f64.powi(2)) - 3.0 * 0.01f64.powi(2));
        assert!((rotor.mass() - (shaft + cone + 2.0)).abs() < 1e-9, "{}", rotor.mass());
    }

    #[test]
    fn bad_tables_are_refused_naming_the_key_value_and_unit() {
        type Spoil = fn(&mut ShaftTable);
        let cases: Vec<(Spoil, &str)> = vec![
            (|t| t.elements[1].length_mm = 0.0, "element[1]: length_mm = 0 mm must be positive"),
            (|t| t.elements[0].outer_diameter_mm = -40.0, "element[0]: outer_diameter_mm = -40 mm must be positive"),
            (|t| t.elements[1].inner_diameter_mm = 45.0, "element[1]: inner_diameter_mm = 0.045 m"),
            (|t| t.materials.get_mut("steel").unwrap().density_kg_m3 = None, "materials.steel: material density_kg_m3"),
            (|t| t.materials.get_mut("steel").unwrap().modulus_pa = None, "materials.steel: material modulus_pa"),
            (|t| t.materials.get_mut("steel").unwrap().modulus_pa = Some(-1.0), "modulus_pa = -1 Pa must be positive"),
            (|t| t.disks[0].node = 6, "disk[0].node: node 6 is out of range (the shaft has nodes 0 to 5)"),
            (|t| t.elements[0].material = "brass".into(), "material = \"brass\" is not in [materials]"),
        ];
        for (spoil, expect) in cases {
            let mut t = table();
            spoil(&mut t);
            let err = t.rotor().expect_err(expect).to_string();
            assert!(err.contains(expect), "{err}\nshould contain: {expect}");
        }
        let unknown = TABLE.replace("split = 4", "split = 4\nlenght_mm = 3.0");
        assert!(toml::from_str::<ShaftTable>(&unknown).unwrap_err().to_string().contains("lenght_mm"));
    }
}
