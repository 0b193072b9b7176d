//! Writes `modelDescription.xml` (FMI 2.0 co-simulation) from the variable table.
//!
//! Element order follows the FMI 2.0 schema: `CoSimulation`, `UnitDefinitions`, `LogCategories`,
//! `DefaultExperiment`, `ModelVariables`, `ModelStructure`. Variables appear in table order, so
//! the 1-based `index` of `<Unknown>` is the variable's position in the table plus one.
//! Causality, variability and `initial` follow FMI 2.0 section 2.2.7:
//! parameters `initial="exact"` with a `start`; inputs with a `start` (no `initial`, which is
//! not allowed for inputs); outputs without `start` and without `initial` (the default for a
//! continuous output is `calculated`). Every output is listed once under `<Outputs>` and once
//! under `<InitialUnknowns>` (no dependencies attribute: depends on all inputs).

use super::variables::{
    Causality, EnumerationSpec, Variability, Variable, VariableTable, VariableType, ENUMERATIONS,
    LOG_CATEGORIES, UNITS,
};
use super::MODEL_IDENTIFIER;
use std::fmt::Write as _;

/// What the XML says about the model besides its variables.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelInfo {
    /// `modelName`.
    pub model_name: String,
    /// `description`.
    pub description: String,
    /// `guid`: must equal what the binary's `fmi2Instantiate` compares with.
    pub guid: String,
    /// `generationTool`.
    pub generation_tool: String,
    /// `DefaultExperiment/@stepSize` (s): the suggested communication step.
    pub default_step_size: f64,
}

/// A Real as an `xs:double` that reads back to the same `f64` (shortest round-trip digits; the
/// special values as `INF`, `-INF`, `NaN`).
pub fn format_real(x: f64) -> String {
    if x.is_nan() {
        "NaN".into()
    } else if x == f64::INFINITY {
        "INF".into()
    } else if x == f64::NEG_INFINITY {
        "-INF".into()
    } else {
        format!("{x:?}")
    }
}

/// Escapes `s` for an attribute value in double quotes. Tab, newline and carriage return become
/// character references (so attribute-value normalization keeps them); other control characters,
/// which XML 1.0 forbids, become U+FFFD.
pub fn escape_attribute(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\t' => out.push_str("&#9;"),
            '\n' => out.push_str("&#10;"),
            '\r' => out.push_str("&#13;"),
            c if (c as u32) < 0x20 || c == '\u{fffe}' || c == '\u{ffff}' => out.push('\u{fffd}'),
            c => out.push(c),
        }
    }
    out
}

fn causality_name(c: Causality) -> &'static str {
    match c {
        Causality::Parameter => "parameter",
        Causality::Input => "input",
        Causality::Output => "output",
    }
}

fn variability_name(v: Variability) -> &'static str {
    match v {
        Variability::Fixed => "fixed",
        Variability::Tunable => "tunable",
        Variability::Discrete => "discrete",
        Variability::Continuous => "continuous",
    }
}

/// `min`/`max` of an Integer as an integer literal.
fn format_integer_bound(x: f64) -> String {
    format!("{}", x.round() as i64)
}

/// The complete `modelDescription.xml`. `start(v)` gives the formatted start value of each
/// parameter and input (use [`format_real`] for Reals, `true`/`false` for Booleans); it is not
/// called for outputs. The text is escaped here.
pub fn model_description(
    table: &VariableTable,
    info: &ModelInfo,
    start: &dyn Fn(&Variable) -> String,
) -> String {
    let mut x = String::new();
    let a = escape_attribute;
    x.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        x,
        "<fmiModelDescription fmiVersion=\"2.0\" modelName=\"{}\" guid=\"{}\" description=\"{}\" generationTool=\"{}\" variableNamingConvention=\"structured\" numberOfEventIndicators=\"0\">",
        a(&info.model_name),
        a(&info.guid),
        a(&info.description),
        a(&info.generation_tool),
    );
    let _ = writeln!(
        x,
        // Capabilities: what src/fmi2 and src/slave implement (MAX_OUTPUT_DERIVATIVE_ORDER = 2,
        // force-input derivatives up to order 2, serialized states).
        "  <CoSimulation modelIdentifier=\"{}\" needsExecutionTool=\"false\" canHandleVariableCommunicationStepSize=\"true\" canInterpolateInputs=\"true\" maxOutputDerivativeOrder=\"2\" canRunAsynchronuously=\"false\" canBeInstantiatedOnlyOncePerProcess=\"false\" canNotUseMemoryManagementFunctions=\"true\" canGetAndSetFMUstate=\"true\" canSerializeFMUstate=\"true\" providesDirectionalDerivative=\"false\"/>",
        a(MODEL_IDENTIFIER)
    );

    unit_definitions(&mut x, table);

    // Enumeration types used by the variables, in the order of ENUMERATIONS.
    let declared: Vec<&str> = table.iter().filter_map(|v| v.declared_type).collect();
    if !declared.is_empty() {
        x.push_str("  <TypeDefinitions>\n");
        for e in ENUMERATIONS.iter().filter(|e| declared.contains(&e.name)) {
            let _ = writeln!(
                x,
                "    <SimpleType name=\"{}\" description=\"{}\">\n      <Enumeration>",
                a(e.name),
                a(e.description)
            );
            enumeration_items(&mut x, e, "        ");
            x.push_str("      </Enumeration>\n    </SimpleType>\n");
        }
        x.push_str("  </TypeDefinitions>\n");
    }

    log_categories(&mut x, false);

    let _ = writeln!(
        x,
        "  <DefaultExperiment startTime=\"0.0\" stepSize=\"{}\"/>",
        format_real(info.default_step_size)
    );

    x.push_str("  <ModelVariables>\n");
    let mut outputs = Vec::new();
    for (i, v) in table.iter().enumerate() {
        let index = i + 1;
        let _ = writeln!(x, "    <!-- Index {index} -->");
        x.push_str("    <ScalarVariable");
        variable_attributes(&mut x, &v.name, v.value_reference, v);
        let has_start = match v.causality {
            Causality::Parameter => {
                x.push_str(" initial=\"exact\"");
                true
            }
            Causality::Input => true,
            Causality::Output => {
                outputs.push(index);
                false
            }
        };
        x.push_str(">\n      <");
        match v.ty {
            VariableType::Real => {
                x.push_str("Real");
                real_attributes(&mut x, v);
            }
            VariableType::Integer if v.declared_type.is_some() => {
                let _ = write!(
                    x,
                    "Enumeration declaredType=\"{}\"",
                    a(v.declared_type.unwrap_or_default())
                );
            }
            VariableType::Integer => {
                x.push_str("Integer");
                integer_bounds(&mut x, v);
            }
            VariableType::Boolean => x.push_str("Boolean"),
            VariableType::String => x.push_str("String"),
        }
        if has_start {
            let _ = write!(x, " start=\"{}\"", a(&start(v)));
        }
        x.push_str("/>\n    </ScalarVariable>\n");
    }
    x.push_str("  </ModelVariables>\n");

    x.push_str("  <ModelStructure>\n");
    if !outputs.is_empty() {
        for element in ["Outputs", "InitialUnknowns"] {
            let _ = writeln!(x, "    <{element}>");
            for index in &outputs {
                let _ = writeln!(x, "      <Unknown index=\"{index}\"/>");
            }
            let _ = writeln!(x, "    </{element}>");
        }
    }
    x.push_str("  </ModelStructure>\n");
    x.push_str("</fmiModelDescription>\n");
    x
}

/// `name`, `valueReference`, `description` (if any), `causality` and `variability` of a
/// variable element, each with a leading space (FMI 2.0 and 3.0 alike).
fn variable_attributes(x: &mut String, name: &str, value_reference: u32, v: &Variable) {
    let a = escape_attribute;
    let _ = write!(
        x,
        " name=\"{}\" valueReference=\"{value_reference}\"",
        a(name)
    );
    if !v.description.is_empty() {
        let _ = write!(x, " description=\"{}\"", a(&v.description));
    }
    let _ = write!(
        x,
        " causality=\"{}\" variability=\"{}\"",
        causality_name(v.causality),
        variability_name(v.variability)
    );
}

/// `unit`, `min` and `max` of a Real (FMI 3.0: Float64) variable, if set.
fn real_attributes(x: &mut String, v: &Variable) {
    if let Some(unit) = v.unit {
        let _ = write!(x, " unit=\"{}\"", escape_attribute(unit));
    }
    if let Some(min) = v.min {
        let _ = write!(x, " min=\"{}\"", format_real(min));
    }
    if let Some(max) = v.max {
        let _ = write!(x, " max=\"{}\"", format_real(max));
    }
}

/// `min` and `max` of an Integer (FMI 3.0: Int32 or Enumeration) variable, if set.
fn integer_bounds(x: &mut String, v: &Variable) {
    if let Some(min) = v.min {
        let _ = write!(x, " min=\"{}\"", format_integer_bound(min));
    }
    if let Some(max) = v.max {
        let _ = write!(x, " max=\"{}\"", format_integer_bound(max));
    }
}

/// The `<Item>`s of an enumeration type, values 1, 2, ... (FMI 2.0 and 3.0 alike).
fn enumeration_items(x: &mut String, e: &EnumerationSpec, indent: &str) {
    let a = escape_attribute;
    for (k, (item, description)) in e.items.iter().enumerate() {
        let _ = writeln!(
            x,
            "{indent}<Item name=\"{}\" value=\"{}\" description=\"{}\"/>",
            a(item),
            k + 1,
            a(description)
        );
    }
}

/// `<UnitDefinitions>`: the units the variables use, in the order of `UNITS`; a used unit missing
/// from `UNITS` is still declared (without base units) so that every `unit` attribute refers to a
/// declared unit. The same element in FMI 2.0 and 3.0.
fn unit_definitions(x: &mut String, table: &VariableTable) {
    let a = escape_attribute;
    let used: Vec<&str> = {
        let mut u: Vec<&str> = Vec::new();
        for v in table.iter() {
            if let Some(name) = v.unit {
                if !u.contains(&name) {
                    u.push(name);
                }
            }
        }
        u
    };
    if !used.is_empty() {
        x.push_str("  <UnitDefinitions>\n");
        for unit in UNITS.iter().filter(|u| used.contains(&u.name)) {
            let mut base = String::new();
            for (attr, e) in [
                ("kg", unit.kg),
                ("m", unit.m),
                ("s", unit.s),
                ("rad", unit.rad),
            ] {
                if e != 0 {
                    let _ = write!(base, " {attr}=\"{e}\"");
                }
            }
            let _ = writeln!(
                x,
                "    <Unit name=\"{}\">\n      <BaseUnit{base}/>\n    </Unit>",
                a(unit.name)
            );
        }
        for name in used.iter().filter(|n| !UNITS.iter().any(|u| u.name == **n)) {
            let _ = writeln!(x, "    <Unit name=\"{}\"/>", a(name));
        }
        x.push_str("  </UnitDefinitions>\n");
    }
}

/// `<LogCategories>`: the same element in FMI 2.0 and 3.0.
fn log_categories(x: &mut String, fmi3: bool) {
    let a = escape_attribute;
    if !LOG_CATEGORIES.is_empty() {
        x.push_str("  <LogCategories>\n");
        for (name, description) in LOG_CATEGORIES {
            // The descriptions name FMI 2.0's statuses (fmi2Warning, ...).
            let description = if fmi3 {
                description.replace("fmi2", "fmi3")
            } else {
                description.to_string()
            };
            let _ = writeln!(
                x,
                "    <Category name=\"{}\" description=\"{}\"/>",
                a(name),
                a(&description)
            );
        }
        x.push_str("  </LogCategories>\n");
    }
}

pub mod fmi3;

#[cfg(test)]
mod tests;
