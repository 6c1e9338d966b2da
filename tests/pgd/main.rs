//! Vademecum tests: convergence against full FEM on a small mesh, the file format, and the
//! values of the `pgd` options.

mod common;
mod convergence;
mod file_format;
mod inclusion;
mod nonlinear;
mod option_values;
mod outputs;
mod surface;
