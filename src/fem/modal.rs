//! Lowest eigenpairs of `K φ = ω² M φ` on the free DOFs (inverse iteration on the sparse Cholesky
//! factor of `K`).
