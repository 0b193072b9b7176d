//! Writes `modelDescription.xml` (FMI 2.0 co-simulation) from the variable table.
