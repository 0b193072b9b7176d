//! Writes the FMI 3.0 `modelDescription.xml` (co-simulation) from the same variable table as the
//! FMI 2.0 one, so that both describe the same slave.
//!
//! Differences from FMI 2.0 (FMI 3.0 sections 2.4 and 4.3):
//! * `instantiationToken` instead of `guid` (the same string: `fmi3InstantiateCoSimulation`
//!   compares it like `fmi2Instantiate` compares the GUID);
//! * typed variable elements: `Float64` (FMI 2.0 `Real`), `Int32` (`Integer`), `Enumeration`
//!   (read and written with `fmi3GetInt64`/`fmi3SetInt64`), `Boolean`, `String` (its start value
//!   in a `<Start value>` child);
//! * vectors and rotation matrices as array variables (see [`crate::model::arrays`]): one
//!   variable with `<Dimension start="3"/>` (twice for a 3×3 rotation), its start values
//!   space-separated in row-major order;
//! * the independent variable `time` ([`TIME_VALUE_REFERENCE`]), which FMI 3.0 requires;
//! * `<ModelStructure>` lists outputs by value reference (`<Output>`, `<InitialUnknown>`).

use super::{
    enumeration_items, escape_attribute, format_real, integer_bounds, log_categories,
    real_attributes, unit_definitions, variable_attributes, ModelInfo,
};
use crate::model::arrays::array_variables;
use crate::model::variables::{Causality, Variable, VariableTable, VariableType, ENUMERATIONS};
use crate::model::MODEL_IDENTIFIER;
use std::fmt::Write as _;

/// The value reference of FMI 3.0's independent variable `time` (no variable of the table has
/// it: theirs start at 1).
pub const TIME_VALUE_REFERENCE: u32 = 0;

/// The complete FMI 3.0 `modelDescription.xml`; `start` as in [`super::model_description`].
pub fn model_description_fmi3(
    table: &VariableTable,
    info: &ModelInfo,
    start: &dyn Fn(&Variable) -> String,
) -> String {
    let mut x = String::new();
    let a = escape_attribute;
    x.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        x,
        "<fmiModelDescription fmiVersion=\"3.0\" modelName=\"{}\" instantiationToken=\"{}\" description=\"{}\" generationTool=\"{}\" variableNamingConvention=\"structured\">",
        a(&info.model_name),
        a(&info.guid),
        a(&info.description),
        a(&info.generation_tool),
    );
    let _ = writeln!(
        x,
        // Capabilities: what src/fmi3 and src/slave implement. No event mode and no early return
        // (the body has no events to stop at); no intermediate update (see docs/fmu.md).
        "  <CoSimulation modelIdentifier=\"{}\" needsExecutionTool=\"false\" canBeInstantiatedOnlyOncePerProcess=\"false\" canGetAndSetFMUState=\"true\" canSerializeFMUState=\"true\" providesDirectionalDerivatives=\"false\" providesAdjointDerivatives=\"false\" canHandleVariableCommunicationStepSize=\"true\" maxOutputDerivativeOrder=\"2\" providesIntermediateUpdate=\"false\" mightReturnEarlyFromDoStep=\"false\" canReturnEarlyAfterIntermediateUpdate=\"false\" hasEventMode=\"false\"/>",
        a(MODEL_IDENTIFIER)
    );
    unit_definitions(&mut x, table);

    let declared: Vec<&str> = table.iter().filter_map(|v| v.declared_type).collect();
    if !declared.is_empty() {
        x.push_str("  <TypeDefinitions>\n");
        for e in ENUMERATIONS.iter().filter(|e| declared.contains(&e.name)) {
            let _ = writeln!(
                x,
                "    <EnumerationType name=\"{}\" description=\"{}\">",
                a(e.name),
                a(e.description)
            );
            enumeration_items(&mut x, e, "      ");
            x.push_str("    </EnumerationType>\n");
        }
        x.push_str("  </TypeDefinitions>\n");
    }
    log_categories(&mut x, true);
    let _ = writeln!(
        x,
        "  <DefaultExperiment startTime=\"0.0\" stepSize=\"{}\"/>",
        format_real(info.default_step_size)
    );

    x.push_str("  <ModelVariables>\n");
    let _ = writeln!(
        x,
        "    <Float64 name=\"time\" valueReference=\"{TIME_VALUE_REFERENCE}\" causality=\"independent\" variability=\"continuous\" description=\"Simulation time\"/>"
    );
    let variables: Vec<&Variable> = table.iter().collect();
    let mut outputs = Vec::new();
    for array in array_variables(table) {
        let elements = &variables[array.first..array.first + array.len];
        let v = elements[0];
        let element = match v.ty {
            VariableType::Real => "Float64",
            VariableType::Integer if v.declared_type.is_some() => "Enumeration",
            VariableType::Integer => "Int32",
            VariableType::Boolean => "Boolean",
            VariableType::String => "String",
        };
        let _ = write!(x, "    <{element}");
        variable_attributes(&mut x, &array.name, array.value_reference, v);
        match v.ty {
            VariableType::Real => real_attributes(&mut x, v),
            VariableType::Integer => {
                if let Some(declared) = v.declared_type {
                    let _ = write!(x, " declaredType=\"{}\"", a(declared));
                }
                integer_bounds(&mut x, v);
            }
            VariableType::Boolean | VariableType::String => {}
        }
        let start_values = match v.causality {
            Causality::Parameter => {
                x.push_str(" initial=\"exact\"");
                Some(elements.iter().map(|e| start(e)).collect::<Vec<_>>())
            }
            Causality::Input => Some(elements.iter().map(|e| start(e)).collect()),
            Causality::Output => {
                outputs.push(array.value_reference);
                None
            }
        };
        let string_start = match (&start_values, v.ty) {
            (Some(values), VariableType::String) => Some(values.clone()),
            (Some(values), _) => {
                let _ = write!(x, " start=\"{}\"", a(&values.join(" ")));
                None
            }
            (None, _) => None,
        };
        if array.dimensions.is_empty() && string_start.is_none() {
            x.push_str("/>\n");
            continue;
        }
        x.push_str(">\n");
        for values in string_start.iter().flatten() {
            let _ = writeln!(x, "      <Start value=\"{}\"/>", a(values));
        }
        for d in &array.dimensions {
            let _ = writeln!(x, "      <Dimension start=\"{d}\"/>");
        }
        let _ = writeln!(x, "    </{element}>");
    }
    x.push_str("  </ModelVariables>\n");

    x.push_str("  <ModelStructure>\n");
    for element in ["Output", "InitialUnknown"] {
        for vr in &outputs {
            let _ = writeln!(x, "    <{element} valueReference=\"{vr}\"/>");
        }
    }
    x.push_str("  </ModelStructure>\n");
    x.push_str("</fmiModelDescription>\n");
    x
}
