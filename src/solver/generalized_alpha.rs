//! Generalized-α time integration with the constant iteration matrix (DESIGN.md section 3).
