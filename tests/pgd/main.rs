//! Vademecum tests: convergence against full FEM on a small mesh, and the file format.

mod common;
mod convergence;
mod file_format;
mod inclusion;
mod nonlinear;
mod outputs;
