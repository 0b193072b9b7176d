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
            .filter(|e| e.name == "Unknown" && e.path.last().map(String::as_str) == Some(parent))
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
