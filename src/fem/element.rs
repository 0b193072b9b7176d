//! Shape functions of the hexahedra in natural coordinates `ξ ∈ [−1, 1]³`.
