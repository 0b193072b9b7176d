//! Gauss–Legendre quadrature on the reference hexahedron.
