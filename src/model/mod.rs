//! The model as the importer sees it: the body file (serde), the variable table with its value
//! references, and the generated `modelDescription.xml`.

pub mod arrays;
pub mod body_file;
pub mod enumerations;
pub mod model_description;
pub mod variables;

pub use body_file::{BodyFile, InterfaceKind, InterfaceSpec};
pub use variables::{Causality, Target, Variability, Variable, VariableTable, VariableType};

/// The `modelIdentifier` of the FMU: the shared library is `binaries/linux64/flexbody.so`.
pub const MODEL_IDENTIFIER: &str = "flexbody";

/// Log category names (all declared in `<LogCategories>`, from `modelDescription/variables.json`):
/// the debug categories of the slave's events and the status categories of the FMI layer.
pub mod category {
    pub const EVENTS: &str = "logEvents";
    pub const SOLVER: &str = "logSolver";
    pub const WARNING: &str = "logStatusWarning";
    pub const DISCARD: &str = "logStatusDiscard";
    pub const ERROR: &str = "logStatusError";
    pub const FATAL: &str = "logStatusFatal";
}
