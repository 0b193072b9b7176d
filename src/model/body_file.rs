//! The body file (`resources/body.json`, docs/fmu.md, "The body file"): mesh, material defaults,
//! interfaces, damping, gravity and solver defaults. The default body (B1 of docs/benchmarks.md: a
//! clamped steel cantilever with a force interface `tip`) is embedded in the binary.

use crate::error::{Error, Result};
use crate::mesh::{ElementKind, Mesh, NodeSelector};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The embedded default body.
pub const DEFAULT_BODY_JSON: &str = include_str!("../../examples/cantilever.json");

/// A body file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct BodyFile {
    /// Model name shown by importers.
    pub name: String,
    #[serde(default)]
    pub description: String,
    pub mesh: MeshSpec,
    pub material: MaterialSpec,
    /// Material regions: elements with their own Young's modulus (and density); the body's
    /// `material` elsewhere.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub regions: Vec<RegionSpec>,
    #[serde(default)]
    pub damping: DampingSpec,
    /// Gravitational acceleration (m/s²), global frame.
    #[serde(default)]
    pub gravity: [f64; 3],
    /// Supports and interfaces, each with a unique name.
    pub interfaces: Vec<InterfaceSpec>,
    #[serde(default)]
    pub solver: SolverSpec,
    #[serde(default)]
    pub model: ModelSpec,
}

/// The mesh of the body.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub enum MeshSpec {
    /// Structured box `[0, length] × [−width/2, width/2] × [−height/2, height/2]` (m).
    Beam {
        length: f64,
        width: f64,
        height: f64,
        /// Elements along x, y, z.
        divisions: [usize; 3],
        element: ElementKind,
    },
    /// A Gmsh mesh file (MSH 4.1, ASCII or binary; see [`crate::mesh::gmsh`]): `file` relative to
    /// the body file's directory (in an FMU: `resources/`), coordinates multiplied by `scale`.
    Gmsh {
        file: String,
        #[serde(default = "MeshSpec::default_scale")]
        scale: f64,
    },
}

impl MeshSpec {
    fn default_scale() -> f64 {
        1.0
    }

    /// Builds the mesh; a relative mesh file is looked up in `base_dir` (the directory of the body
    /// file; `None`: the current directory).
    pub fn build(&self, base_dir: Option<&Path>) -> Result<Mesh> {
        match self {
            MeshSpec::Beam {
                length,
                width,
                height,
                divisions,
                element,
            } => crate::mesh::beam(*length, *width, *height, *divisions, *element),
            MeshSpec::Gmsh { file, scale } => {
                let path = match base_dir {
                    Some(dir) => dir.join(file),
                    None => Path::new(file).to_path_buf(),
                };
                crate::mesh::gmsh::read(&path, *scale)
                    .map_err(|e| Error::new(format!("mesh.gmsh: {}", e.message)))
            }
        }
    }
}

/// Material defaults (the FMU's `material.*` parameters start here).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct MaterialSpec {
    pub youngs_modulus: f64,
    pub poisson_ratio: f64,
    pub density: f64,
}

/// A material region (body file: `{ "name": "stiff", "elements": { "box": { "min": [..],
/// "max": [..] } }, "youngsModulus": 2.1e15, "density": 7850 }`): the selected elements get
/// this Young's modulus (Pa) and, if given, density (kg/m³); Poisson's ratio stays the body's.
/// The FMU's `material.*` parameters set the material outside every region; a region's values
/// are fixed by the body file. Where regions overlap the later one wins.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct RegionSpec {
    pub name: String,
    pub elements: ElementSelector,
    pub youngs_modulus: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
}

/// A rule selecting elements of a mesh.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub enum ElementSelector {
    /// Elements whose centroid (mean of the element's node positions) lies in the closed
    /// axis-aligned box (m), with the node selectors' tolerance
    /// ([`crate::mesh::selector::RELATIVE_TOLERANCE`] × bounding-box diagonal).
    Box { min: [f64; 3], max: [f64; 3] },
}

impl ElementSelector {
    /// Whether element `e`'s centroid is selected; `tolerance` in m.
    fn contains(&self, mesh: &Mesh, e: usize, tolerance: f64) -> bool {
        match self {
            ElementSelector::Box { min, max } => {
                let c = mesh.element_centroid(e);
                (0..3).all(|d| c[d] >= min[d] - tolerance && c[d] <= max[d] + tolerance)
            }
        }
    }
}

/// Rayleigh damping of the deformation, `f_d = hR (α M + β K) dū/dt`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct DampingSpec {
    #[serde(default)]
    pub alpha: f64,
    #[serde(default)]
    pub beta: f64,
}

/// What an interface does (docs/fmu.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub enum InterfaceKind {
    /// Inputs force and torque, distributed RBE3-like; outputs the power-conjugate motion.
    Force,
    /// Clamps the node set where the body was placed; outputs the reaction.
    Fixed,
    /// Spherical joint to the ground: the weighted centroid of the node set stays where the body
    /// was placed (a Lagrange-multiplier constraint); rotation is free. Outputs the reaction
    /// force (the torque about the centroid is zero).
    Pin,
    /// Revolute joint to the ground about `axis` through the node set's centroid: a pin plus
    /// two more Lagrange-multiplier constraints; only the rotation about the axis is free.
    Hinge,
    /// Clamps the node set to a frame given as input (position, rotation, velocity, angular
    /// velocity; extrapolated over a step with the input velocities); outputs the constraint load.
    Motion,
}

/// A support or interface: a named node set with a reference point.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct InterfaceSpec {
    pub name: String,
    pub kind: InterfaceKind,
    pub nodes: NodeSelector,
    /// Reference point in body coordinates (m); default: the mass-weighted centroid of the nodes.
    #[serde(default)]
    pub reference_point: Option<[f64; 3]>,
    /// Axis of a `hinge` (body coordinates); it passes through the node set's centroid.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<[f64; 3]>,
    /// The node set moves as one rigid body (an RBE2 spider: exact, with Lagrange multipliers;
    /// docs/formulation.md, "Rigid attachments"). A `fixed` support and a `motion` interface
    /// clamp their set rigidly anyway.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub rigid: bool,
    /// A lumped rigid body carried by a rigid attachment: its mass (kg)...
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass: Option<f64>,
    /// ...its inertia tensor about the reference point in body axes (kg m², rows; default 0: a
    /// point mass)...
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia: Option<[[f64; 3]; 3]>,
    /// ...and its centre of mass (m, body coordinates; default the reference point).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub center_of_mass: Option<[f64; 3]>,
}

/// Solver defaults (the FMU's `solver.*` parameters start here).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct SolverSpec {
    /// Largest internal step (s).
    #[serde(default = "SolverSpec::default_step_size")]
    pub step_size: f64,
    /// Generalized-α spectral radius at infinite frequency.
    #[serde(default = "SolverSpec::default_rho_inf")]
    pub rho_inf: f64,
    /// Relative tolerance of the fixed-point iteration.
    #[serde(default = "SolverSpec::default_tolerance")]
    pub tolerance: f64,
    #[serde(default = "SolverSpec::default_max_iterations")]
    pub max_iterations: u32,
    /// History of Anderson's acceleration of the fixed-point iteration (0: plain; at most 8).
    #[serde(default = "SolverSpec::default_anderson_depth")]
    pub anderson_depth: u32,
    /// Time integration scheme.
    #[serde(default)]
    pub integrator: Integrator,
}

/// The time integration scheme (`solver.integrator`), the enumeration of `variables.json`.
pub use super::enumerations::Integrator;

impl SolverSpec {
    fn default_step_size() -> f64 {
        1e-3
    }
    fn default_rho_inf() -> f64 {
        0.9
    }
    fn default_tolerance() -> f64 {
        1e-10
    }
    fn default_max_iterations() -> u32 {
        25
    }
    fn default_anderson_depth() -> u32 {
        crate::solver::anderson::DEFAULT_DEPTH as u32
    }
}

impl Default for SolverSpec {
    fn default() -> Self {
        SolverSpec {
            step_size: Self::default_step_size(),
            rho_inf: Self::default_rho_inf(),
            tolerance: Self::default_tolerance(),
            max_iterations: Self::default_max_iterations(),
            anderson_depth: Self::default_anderson_depth(),
            integrator: Integrator::default(),
        }
    }
}

/// Model switches.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct ModelSpec {
    /// Include the nonlinear internal force `f_nl` (docs/formulation.md, "The internal force"). Off by default.
    #[serde(default)]
    pub nonlinear_forces: bool,
    /// Co-moving frames (`model.frames`, see `body::patches`): 1 (the default) is one frame for
    /// the whole body.
    #[serde(default = "ModelSpec::default_frames")]
    pub frames: u32,
    /// Reduced body (`model.modes`, see `body::reduction`): 0 (the default) moves every mesh
    /// node; `n > 0` restricts the deformation to `n` fixed-interface modes plus the interfaces'
    /// constraint and attachment modes (component mode synthesis in absolute coordinates);
    /// `"auto"` takes the modes `model.accuracy` needs.
    #[serde(default)]
    pub modes: ModesSpec,
    /// `model.auto` (default true): the nonlinear force and the stiffening are upper bounds, each
    /// switched on per step only when it changes the result beyond the solver tolerance; `f_nl`
    /// stays off on a supported body with one frame.
    #[serde(default = "ModelSpec::default_auto")]
    pub auto: bool,
    /// `model.accuracy`: the accepted error relative to the deformation scale, which sets the
    /// internal step (docs/formulation.md, "Time error control"); 0 (the default): the fixed
    /// step `solver.stepSize`.
    #[serde(default = "ModelSpec::default_accuracy")]
    pub accuracy: f64,
    /// `model.linear`: the geometrically linear body forced (docs/formulation.md, "The linear
    /// body"); false (the default): `model.auto` decides.
    #[serde(default)]
    pub linear: bool,
}

impl Default for ModelSpec {
    fn default() -> Self {
        ModelSpec {
            nonlinear_forces: false,
            frames: ModelSpec::default_frames(),
            modes: ModesSpec::default(),
            auto: ModelSpec::default_auto(),
            accuracy: ModelSpec::default_accuracy(),
            linear: false,
        }
    }
}

impl ModelSpec {
    fn default_frames() -> u32 {
        1
    }
    fn default_auto() -> bool {
        true
    }
    /// `model.accuracy`'s default (also what `model.modes = auto` meets when it is 0).
    pub fn default_accuracy() -> f64 {
        1e-2
    }
}

/// `model.modes` as an FMU parameter: the reduced body with the modes its accuracy needs.
pub const MODES_AUTO: i32 = -1;

/// `model.modes` in a body file: a count (0: the full mesh) or `"auto"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModesSpec {
    Count(u32),
    Auto,
}

impl Default for ModesSpec {
    fn default() -> Self {
        ModesSpec::Count(0)
    }
}

impl ModesSpec {
    /// The FMU parameter's value: the count, or [`MODES_AUTO`].
    pub fn parameter(self) -> i32 {
        match self {
            ModesSpec::Count(n) => n.min(i32::MAX as u32) as i32,
            ModesSpec::Auto => MODES_AUTO,
        }
    }
}

impl Serialize for ModesSpec {
    fn serialize<S: serde::Serializer>(
        &self,
        serializer: S,
    ) -> std::result::Result<S::Ok, S::Error> {
        match self {
            ModesSpec::Count(n) => serializer.serialize_u32(*n),
            ModesSpec::Auto => serializer.serialize_str("auto"),
        }
    }
}

impl<'de> Deserialize<'de> for ModesSpec {
    fn deserialize<D: serde::Deserializer<'de>>(
        deserializer: D,
    ) -> std::result::Result<Self, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = ModesSpec;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("model.modes: a mode count (0: the full mesh, n > 0) or \"auto\"")
            }
            fn visit_u64<E: serde::de::Error>(self, n: u64) -> std::result::Result<ModesSpec, E> {
                u32::try_from(n)
                    .map(ModesSpec::Count)
                    .map_err(|_| E::invalid_value(serde::de::Unexpected::Unsigned(n), &self))
            }
            fn visit_i64<E: serde::de::Error>(self, n: i64) -> std::result::Result<ModesSpec, E> {
                u64::try_from(n)
                    .map_err(|_| E::invalid_value(serde::de::Unexpected::Signed(n), &self))
                    .and_then(|n| self.visit_u64(n))
            }
            fn visit_str<E: serde::de::Error>(self, s: &str) -> std::result::Result<ModesSpec, E> {
                match s {
                    "auto" => Ok(ModesSpec::Auto),
                    _ => Err(E::invalid_value(serde::de::Unexpected::Str(s), &self)),
                }
            }
        }
        deserializer.deserialize_any(Visitor)
    }
}

impl BodyFile {
    /// Parses and checks a body file; the error says what is wrong and where.
    pub fn from_json(text: &str) -> Result<BodyFile> {
        let body: BodyFile =
            serde_json::from_str(text).map_err(|e| Error::new(format!("body file: {e}")))?;
        body.check()?;
        Ok(body)
    }

    /// The embedded default body (B1).
    pub fn default_body() -> BodyFile {
        BodyFile::from_json(DEFAULT_BODY_JSON).expect("the embedded default body is valid")
    }

    /// The region of each element of `mesh` (index into `regions`; `None`: the body's material).
    /// Error if a region selects no element, naming it.
    pub fn element_regions(&self, mesh: &Mesh) -> Result<Vec<Option<usize>>> {
        let (lo, hi) = mesh.bounding_box();
        let diagonal = (0..3).map(|d| (hi[d] - lo[d]).powi(2)).sum::<f64>().sqrt();
        let tolerance = crate::mesh::selector::RELATIVE_TOLERANCE * diagonal;
        let mut regions = vec![None; mesh.element_count()];
        for (k, region) in self.regions.iter().enumerate() {
            let mut any = false;
            for (e, slot) in regions.iter_mut().enumerate() {
                if region.elements.contains(mesh, e, tolerance) {
                    *slot = Some(k);
                    any = true;
                }
            }
            if !any {
                return Err(Error::new(format!(
                    "body file: region '{}' selects no element (no element centroid in {:?})",
                    region.name, region.elements
                )));
            }
        }
        Ok(regions)
    }

    /// Canonical JSON text (used for the GUID).
    pub fn to_canonical_json(&self) -> String {
        serde_json::to_string(self).expect("a body file serializes")
    }

    /// Checks what serde cannot: unique, FMI-safe interface names, at least one interface.
    pub fn check(&self) -> Result<()> {
        let mut seen = std::collections::BTreeSet::new();
        for i in &self.interfaces {
            let ok = !i.name.is_empty()
                && i.name
                    .chars()
                    .next()
                    .is_some_and(|c| c.is_ascii_alphabetic())
                && i.name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_');
            if !ok {
                return Err(Error::new(format!(
                    "body file: interface name '{}' must start with a letter and contain only letters, digits and '_'",
                    i.name
                )));
            }
            if matches!(
                i.name.as_str(),
                "body"
                    | "material"
                    | "damping"
                    | "gravity"
                    | "initial"
                    | "solver"
                    | "model"
                    | "output"
            ) {
                return Err(Error::new(format!(
                    "body file: interface name '{}' is reserved for the FMU's own variables",
                    i.name
                )));
            }
            if !seen.insert(i.name.as_str()) {
                return Err(Error::new(format!(
                    "body file: interface name '{}' is used twice",
                    i.name
                )));
            }
        }
        let mut region_names = std::collections::BTreeSet::new();
        for r in &self.regions {
            let fail = |what: &str| {
                Err(Error::new(format!(
                    "body file: region '{}': {what}",
                    r.name
                )))
            };
            if r.name.is_empty() || !region_names.insert(r.name.as_str()) {
                return fail("region names must be non-empty and unique");
            }
            if !(r.youngs_modulus.is_finite() && r.youngs_modulus > 0.0) {
                return fail(&format!(
                    "youngsModulus = {} must be positive and finite",
                    r.youngs_modulus
                ));
            }
            if let Some(d) = r.density.filter(|d| !(d.is_finite() && *d > 0.0)) {
                return fail(&format!("density = {d} must be positive and finite"));
            }
            let ElementSelector::Box { min, max } = &r.elements;
            if (0..3).any(|d| !(min[d].is_finite() && max[d].is_finite() && min[d] <= max[d])) {
                return fail("elements.box: min must not exceed max and all bounds must be finite");
            }
        }
        if self.model.frames < 1 {
            return Err(Error::new(
                "body file: model.frames = 0: a body needs at least one co-moving frame",
            ));
        }
        if self.solver.anderson_depth > crate::solver::anderson::MAX_DEPTH as u32 {
            return Err(Error::new(format!(
                "body file: solver.andersonDepth = {} exceeds the largest history, {}",
                self.solver.anderson_depth,
                crate::solver::anderson::MAX_DEPTH
            )));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modes_take_a_count_or_auto_and_name_anything_else() {
        let parse = |text: &str| serde_json::from_str::<ModesSpec>(text);
        assert_eq!(parse("8").unwrap(), ModesSpec::Count(8));
        assert_eq!(parse("\"auto\"").unwrap(), ModesSpec::Auto);
        for bad in ["-3", "\"many\"", "1.5", "4294967296"] {
            let e = parse(bad).unwrap_err().to_string();
            assert!(
                e.contains("model.modes") && e.contains("auto"),
                "{bad}: {e}"
            );
        }
        for spec in [ModesSpec::Count(3), ModesSpec::Auto] {
            assert_eq!(parse(&serde_json::to_string(&spec).unwrap()).unwrap(), spec);
        }
        assert_eq!(ModesSpec::Auto.parameter(), MODES_AUTO);
    }
}
