//! The FMU's variables as FMI 3.0 array variables.
//!
//! FMI 2.0 has scalar variables only: a vector is `tip.position[1]`, `tip.position[2]`,
//! `tip.position[3]` with consecutive value references. FMI 3.0 describes it as one variable
//! `tip.position` of shape `[3]` (a rotation matrix `[3,3]`, row-major as in FMI 3.0's
//! serialization of arrays), read and written with one value reference and as many values as
//! elements. Here the value reference of an array variable is the one of its element 1, so
//! element `k` (1-based, row-major) is the scalar variable with value reference
//! `value_reference + k - 1` of the same [`VariableTable`]: the FMI 3.0 layer turns a request into
//! scalar requests without a second table.

use super::variables::{Variable, VariableTable};

/// One FMI 3.0 variable: a scalar of the table, or a run of its elements `name[1..len]`.
#[derive(Debug, Clone, PartialEq)]
pub struct ArrayVariable {
    /// The name without the index (`tip.position`), or the scalar's name.
    pub name: String,
    /// The value reference of element 1 (of the scalar).
    pub value_reference: u32,
    /// The number of elements (1 for a scalar).
    pub len: usize,
    /// The dimensions: empty for a scalar, `[len]` for a vector, `[3, 3]` for a rotation matrix.
    pub dimensions: Vec<usize>,
    /// The position of element 1 in the table (its metadata stands for the whole array).
    pub first: usize,
}

impl ArrayVariable {
    /// The scalar value references of the elements, in order.
    pub fn element_references(&self) -> std::ops::Range<u32> {
        self.value_reference..self.value_reference + self.len as u32
    }
}

/// `base` and the index `k` of a name `base[k]`.
fn split_index(name: &str) -> Option<(&str, usize)> {
    let open = name.rfind('[')?;
    let index = name.strip_suffix(']')?.get(open + 1..)?;
    let k = index.parse().ok()?;
    Some((&name[..open], k))
}

/// Whether `next` continues the array that starts with `first`: element `k` of the same base,
/// type, causality and variability, at the next value reference.
fn continues(first: &Variable, base: &str, k: usize, next: &Variable) -> bool {
    split_index(&next.name) == Some((base, k))
        && next.ty == first.ty
        && next.causality == first.causality
        && next.variability == first.variability
        && next.value_reference == first.value_reference + (k as u32 - 1)
}

/// The table's variables as FMI 3.0 variables, in table order: runs `base[1..n]` become arrays
/// (shape `[3, 3]` when `n = 9`: every 9-element quantity of this FMU is a rotation matrix), other
/// variables stay scalars.
pub fn array_variables(table: &VariableTable) -> Vec<ArrayVariable> {
    let variables: Vec<&Variable> = table.iter().collect();
    let mut arrays = Vec::new();
    let mut i = 0;
    while i < variables.len() {
        let first = variables[i];
        let mut len = 1;
        let name = match split_index(&first.name) {
            Some((base, 1)) => {
                while i + len < variables.len()
                    && continues(first, base, len + 1, variables[i + len])
                {
                    len += 1;
                }
                base.to_string()
            }
            _ => first.name.clone(),
        };
        let dimensions = match len {
            1 if name == first.name => Vec::new(),
            9 => vec![3, 3],
            n => vec![n],
        };
        arrays.push(ArrayVariable {
            name,
            value_reference: first.value_reference,
            len,
            dimensions,
            first: i,
        });
        i += len;
    }
    arrays
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::BodyFile;

    #[test]
    fn indices_are_split_from_names() {
        assert_eq!(split_index("tip.position[3]"), Some(("tip.position", 3)));
        assert_eq!(split_index("a[b][12]"), Some(("a[b]", 12)));
        assert_eq!(split_index("solver.stepSize"), None);
        assert_eq!(split_index("x[]"), None);
    }

    #[test]
    fn vectors_and_rotations_of_the_default_body_become_arrays() {
        let body = BodyFile::default_body();
        let table = VariableTable::new(&body.interfaces);
        let arrays = array_variables(&table);
        let find = |name: &str| arrays.iter().find(|a| a.name == name).unwrap();
        let gravity = find("gravity");
        assert_eq!((gravity.len, gravity.dimensions.clone()), (3, vec![3]));
        let rotation = find("body.rotation");
        assert_eq!((rotation.len, rotation.dimensions.clone()), (9, vec![3, 3]));
        assert!(find("solver.stepSize").dimensions.is_empty());
        // Every scalar of the table is an element of exactly one array variable, at the value
        // reference the array's element numbering says.
        let mut covered = 0;
        for a in &arrays {
            for (k, vr) in a.element_references().enumerate() {
                let v = table.iter().nth(a.first + k).unwrap();
                assert_eq!(v.value_reference, vr, "{}", v.name);
                if a.len > 1 {
                    assert_eq!(v.name, format!("{}[{}]", a.name, k + 1));
                }
                covered += 1;
            }
            if a.len == 9 {
                assert!(a.name.ends_with("rotation"), "{} has 9 elements", a.name);
            }
        }
        assert_eq!(covered, table.len());
    }
}
