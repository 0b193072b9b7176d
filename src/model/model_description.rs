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
    Causality, Variability, Variable, VariableTable, VariableType, ENUMERATIONS, LOG_CATEGORIES,
    UNITS,
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
        // Capabilities: what src/fmi2 and src/slave.rs implement (MAX_OUTPUT_DERIVATIVE_ORDER = 2,
        // force-input derivatives up to order 2, serialized states).
        "  <CoSimulation modelIdentifier=\"{}\" needsExecutionTool=\"false\" canHandleVariableCommunicationStepSize=\"true\" canInterpolateInputs=\"true\" maxOutputDerivativeOrder=\"2\" canRunAsynchronuously=\"false\" canBeInstantiatedOnlyOncePerProcess=\"false\" canNotUseMemoryManagementFunctions=\"true\" canGetAndSetFMUstate=\"true\" canSerializeFMUstate=\"true\" providesDirectionalDerivative=\"false\"/>",
        a(MODEL_IDENTIFIER)
    );

    // Units: those used, in the order of UNITS; a used unit missing from UNITS is still declared
    // (without base units) so that every `unit` attribute refers to a declared unit.
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
            for (k, (item, description)) in e.items.iter().enumerate() {
                let _ = writeln!(
                    x,
                    "        <Item name=\"{}\" value=\"{}\" description=\"{}\"/>",
                    a(item),
                    k + 1,
                    a(description)
                );
            }
            x.push_str("      </Enumeration>\n    </SimpleType>\n");
        }
        x.push_str("  </TypeDefinitions>\n");
    }

    if !LOG_CATEGORIES.is_empty() {
        x.push_str("  <LogCategories>\n");
        for (name, description) in LOG_CATEGORIES {
            let _ = writeln!(
                x,
                "    <Category name=\"{}\" description=\"{}\"/>",
                a(name),
                a(description)
            );
        }
        x.push_str("  </LogCategories>\n");
    }

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
        let _ = write!(
            x,
            "    <ScalarVariable name=\"{}\" valueReference=\"{}\"",
            a(&v.name),
            v.value_reference
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
                if let Some(unit) = v.unit {
                    let _ = write!(x, " unit=\"{}\"", a(unit));
                }
                if let Some(min) = v.min {
                    let _ = write!(x, " min=\"{}\"", format_real(min));
                }
                if let Some(max) = v.max {
                    let _ = write!(x, " max=\"{}\"", format_real(max));
                }
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
                if let Some(min) = v.min {
                    let _ = write!(x, " min=\"{}\"", format_integer_bound(min));
                }
                if let Some(max) = v.max {
                    let _ = write!(x, " max=\"{}\"", format_integer_bound(max));
                }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::BodyFile;
    use std::collections::{BTreeMap, BTreeSet};

    /// One element of a tiny XML reader: enough to check well-formedness and read attributes.
    #[derive(Debug)]
    struct Element {
        name: String,
        attributes: BTreeMap<String, String>,
        /// Names of the enclosing elements, outermost first.
        path: Vec<String>,
    }

    fn unescape(s: &str) -> String {
        let mut out = String::new();
        let mut rest = s;
        while let Some(i) = rest.find('&') {
            out.push_str(&rest[..i]);
            let end = rest[i..].find(';').expect("unterminated entity") + i;
            let entity = &rest[i + 1..end];
            out.push(match entity {
                "amp" => '&',
                "lt" => '<',
                "gt" => '>',
                "quot" => '"',
                "apos" => '\'',
                e if e.starts_with('#') => {
                    char::from_u32(e[1..].parse().expect("decimal reference")).unwrap()
                }
                e => panic!("unknown entity &{e};"),
            });
            rest = &rest[end + 1..];
        }
        out.push_str(rest);
        out
    }

    /// Parses tags (no text content is expected), checks nesting, quoting and uniqueness of
    /// attributes; panics on malformed input.
    fn parse(xml: &str) -> Vec<Element> {
        let body = xml
            .strip_prefix("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n")
            .expect("XML declaration");
        let mut stack: Vec<String> = Vec::new();
        let mut elements = Vec::new();
        let mut rest = body;
        loop {
            let trimmed = rest.trim_start();
            if trimmed.is_empty() {
                break;
            }
            assert!(
                trimmed.starts_with('<'),
                "text outside tags: {:?}",
                &trimmed[..trimmed.len().min(40)]
            );
            if let Some(comment) = trimmed.strip_prefix("<!--") {
                let end = comment.find("-->").expect("unterminated comment");
                assert!(!comment[..end].contains("--"));
                rest = &comment[end + 3..];
                continue;
            }
            let end = trimmed.find('>').expect("unterminated tag");
            let tag = &trimmed[1..end];
            rest = &trimmed[end + 1..];
            assert!(!tag.contains('<'), "'<' inside a tag: {tag}");
            if let Some(name) = tag.strip_prefix('/') {
                assert_eq!(stack.pop().as_deref(), Some(name), "mismatched closing tag");
                continue;
            }
            let self_closing = tag.ends_with('/');
            let tag = tag.trim_end_matches('/');
            let name_end = tag.find(char::is_whitespace).unwrap_or(tag.len());
            let name = tag[..name_end].to_string();
            assert!(
                !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric()),
                "bad tag name {name:?}"
            );
            let mut attributes = BTreeMap::new();
            let mut a = tag[name_end..].trim_start();
            while !a.is_empty() {
                let eq = a.find("=\"").expect("attribute without =\"");
                let key = a[..eq].to_string();
                let after = &a[eq + 2..];
                let close = after.find('"').expect("unterminated attribute value");
                let raw = &after[..close];
                assert!(!raw.contains('<'));
                assert!(
                    attributes.insert(key.clone(), unescape(raw)).is_none(),
                    "duplicate attribute {key}"
                );
                a = after[close + 1..].trim_start();
            }
            elements.push(Element {
                name: name.clone(),
                attributes,
                path: stack.clone(),
            });
            if !self_closing {
                stack.push(name);
            }
        }
        assert!(stack.is_empty(), "unclosed elements {stack:?}");
        elements
    }

    fn default_table() -> VariableTable {
        VariableTable::new(&BodyFile::default_body().interfaces)
    }

    fn info() -> ModelInfo {
        ModelInfo {
            model_name: "cantilever <B1> & \"co\"".into(),
            description: "line 1\nline 2".into(),
            guid: "{0123-abcd}".into(),
            generation_tool: "flexbody 0.1.0".into(),
            default_step_size: 1e-3,
        }
    }

    /// Start values that are distinct per variable and exercise round-trip formatting.
    fn start(v: &Variable) -> String {
        match v.ty {
            VariableType::Real => format_real(0.1 + v.value_reference as f64 / 3.0),
            VariableType::Integer => v.value_reference.to_string(),
            VariableType::Boolean => "false".into(),
            VariableType::String => format!("text & <{}>", v.value_reference),
        }
    }

    #[test]
    fn is_well_formed_and_lists_every_output_once_in_outputs_and_initial_unknowns() {
        let table = default_table();
        let xml = model_description(&table, &info(), &start);
        let elements = parse(&xml);

        let root = &elements[0];
        assert_eq!(root.name, "fmiModelDescription");
        assert_eq!(root.attributes["fmiVersion"], "2.0");
        assert_eq!(root.attributes["modelName"], "cantilever <B1> & \"co\"");
        assert_eq!(root.attributes["description"], "line 1\nline 2");
        assert_eq!(root.attributes["guid"], "{0123-abcd}");

        // Top-level order required by the schema.
        let top: Vec<&str> = elements
            .iter()
            .filter(|e| e.path.len() == 1)
            .map(|e| e.name.as_str())
            .collect();
        assert_eq!(
            top,
            [
                "CoSimulation",
                "UnitDefinitions",
                "TypeDefinitions",
                "LogCategories",
                "DefaultExperiment",
                "ModelVariables",
                "ModelStructure"
            ]
        );

        let cs = elements.iter().find(|e| e.name == "CoSimulation").unwrap();
        assert_eq!(cs.attributes["modelIdentifier"], "flexbody");
        for (k, v) in [
            ("canHandleVariableCommunicationStepSize", "true"),
            ("canGetAndSetFMUstate", "true"),
            ("canSerializeFMUstate", "true"),
            ("canNotUseMemoryManagementFunctions", "true"),
            ("canInterpolateInputs", "true"),
            ("maxOutputDerivativeOrder", "2"),
            ("providesDirectionalDerivative", "false"),
        ] {
            assert_eq!(cs.attributes[k], v, "{k}");
        }
        let de = elements
            .iter()
            .find(|e| e.name == "DefaultExperiment")
            .unwrap();
        assert_eq!(de.attributes["stepSize"].parse::<f64>().unwrap(), 1e-3);

        // ModelVariables in table order; 1-based indices of the outputs.
        let scalars: Vec<&Element> = elements
            .iter()
            .filter(|e| e.name == "ScalarVariable")
            .collect();
        assert_eq!(scalars.len(), table.len());
        let mut expected_outputs = Vec::new();
        for (i, (e, v)) in scalars.iter().zip(table.iter()).enumerate() {
            assert_eq!(e.attributes["name"], v.name);
            assert_eq!(
                e.attributes["valueReference"],
                v.value_reference.to_string()
            );
            if v.causality == Causality::Output {
                expected_outputs.push(i + 1);
            }
        }
        assert!(!expected_outputs.is_empty());
        let unknowns = |parent: &str| -> Vec<usize> {
            elements
                .iter()
                .filter(|e| {
                    e.name == "Unknown" && e.path.last().map(String::as_str) == Some(parent)
                })
                .map(|e| e.attributes["index"].parse().unwrap())
                .collect()
        };
        assert_eq!(unknowns("Outputs"), expected_outputs);
        assert_eq!(unknowns("InitialUnknowns"), expected_outputs);
        let unique: BTreeSet<usize> = expected_outputs.iter().copied().collect();
        assert_eq!(unique.len(), expected_outputs.len());
    }

    #[test]
    fn attributes_follow_the_fmi_rules_per_causality() {
        let table = default_table();
        let xml = model_description(&table, &info(), &start);
        let elements = parse(&xml);
        let declared_units: BTreeSet<String> = elements
            .iter()
            .filter(|e| e.name == "Unit")
            .map(|e| e.attributes["name"].clone())
            .collect();
        let mut i = 0;
        for (k, e) in elements.iter().enumerate() {
            if e.name != "ScalarVariable" {
                continue;
            }
            let v = table.iter().nth(i).unwrap();
            i += 1;
            let typed = &elements[k + 1];
            assert_eq!(typed.path.last().unwrap(), "ScalarVariable");
            match v.causality {
                Causality::Parameter => {
                    assert_eq!(e.attributes["causality"], "parameter");
                    assert_eq!(e.attributes["initial"], "exact", "{}", v.name);
                    assert!(matches!(
                        e.attributes["variability"].as_str(),
                        "fixed" | "tunable"
                    ));
                    assert_eq!(typed.attributes["start"], start(v), "{}", v.name);
                }
                Causality::Input => {
                    assert!(!e.attributes.contains_key("initial"), "{}", v.name);
                    assert_eq!(typed.attributes["start"], start(v), "{}", v.name);
                }
                Causality::Output => {
                    assert!(!e.attributes.contains_key("initial"), "{}", v.name);
                    assert!(!typed.attributes.contains_key("start"), "{}", v.name);
                }
            }
            match v.ty {
                VariableType::Real => {
                    assert_eq!(typed.name, "Real");
                    if let Some(u) = v.unit {
                        assert_eq!(typed.attributes["unit"], u);
                        assert!(declared_units.contains(u), "undeclared unit {u}");
                    }
                    if let Some(min) = v.min {
                        assert_eq!(typed.attributes["min"].parse::<f64>().unwrap(), min);
                    }
                    if let Some(max) = v.max {
                        assert_eq!(typed.attributes["max"].parse::<f64>().unwrap(), max);
                    }
                }
                VariableType::Integer => match v.declared_type {
                    Some(t) => {
                        assert_eq!(typed.name, "Enumeration");
                        assert_eq!(typed.attributes["declaredType"], t);
                    }
                    None => assert_eq!(typed.name, "Integer"),
                },
                VariableType::String => assert_eq!(typed.name, "String"),
                VariableType::Boolean => {
                    assert_eq!(typed.name, "Boolean");
                    if v.causality != Causality::Output {
                        assert!(matches!(
                            typed.attributes["start"].as_str(),
                            "true" | "false"
                        ));
                    }
                }
            }
        }
        assert_eq!(i, table.len());
        // Every used unit is one of UNITS (so it carries base-unit exponents).
        for u in &declared_units {
            assert!(
                UNITS.iter().any(|spec| spec.name == u),
                "unit {u} missing from variables.json"
            );
        }
        let categories: Vec<&str> = elements
            .iter()
            .filter(|e| e.name == "Category")
            .map(|e| e.attributes["name"].as_str())
            .collect();
        let expected: Vec<&str> = LOG_CATEGORIES.iter().map(|(n, _)| *n).collect();
        assert_eq!(categories, expected);
    }

    #[test]
    fn reals_round_trip_exactly() {
        for x in [
            0.1,
            1.0 / 3.0,
            2.1e11,
            7850.0,
            1e-10,
            -9.81,
            5e-324,
            f64::MAX,
            0.0,
            -0.0,
        ] {
            let s = format_real(x);
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), x.to_bits(), "{s}");
        }
        assert_eq!(format_real(f64::INFINITY), "INF");
        assert_eq!(format_real(f64::NEG_INFINITY), "-INF");
        assert_eq!(format_real(f64::NAN), "NaN");
    }

    #[test]
    fn escaping_covers_markup_and_control_characters() {
        assert_eq!(
            escape_attribute("a<b>&\"c'"),
            "a&lt;b&gt;&amp;&quot;c&apos;"
        );
        assert_eq!(escape_attribute("x\ty\n"), "x&#9;y&#10;");
        assert_eq!(escape_attribute("bell\u{7}"), "bell\u{fffd}");
    }
}
