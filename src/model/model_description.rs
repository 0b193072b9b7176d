//! Writes `modelDescription.xml` (FMI 2.0 co-simulation) from the variable table.
//! (Placeholder until the writer lands.)

use super::variables::{Variable, VariableTable};

/// What the XML says about the model besides its variables.
#[derive(Debug, Clone)]
pub struct ModelInfo {
    pub model_name: String,
    pub description: String,
    pub guid: String,
    pub generation_tool: String,
    pub default_step_size: f64,
}

pub fn model_description(
    table: &VariableTable,
    info: &ModelInfo,
    start: &dyn Fn(&Variable) -> String,
) -> String {
    let _ = (table, info, start);
    todo!()
}
