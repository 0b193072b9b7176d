//! The ACF-RS body (DESIGN.md section 2): co-moving frame, local deformation, internal force with
//! the nonlinear term `f_nl`, damping, interfaces.
