//! The model as the importer sees it: the body file (serde), the variable table with its value
//! references, and the generated `modelDescription.xml`.

pub mod body_file;
pub mod model_description;
pub mod variables;

pub use body_file::{BodyFile, InterfaceKind, InterfaceSpec};
pub use variables::{Causality, Target, Variability, Variable, VariableTable, VariableType};

/// The `modelIdentifier` of the FMU: the shared library is `binaries/linux64/flexbody.so`.
pub const MODEL_IDENTIFIER: &str = "flexbody";
