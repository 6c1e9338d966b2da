//! Vademecum tests: convergence against full FEM on a small mesh, the file format, nonlinear
//! load steps, inclusions, surfaces and what a build writes.

mod common;
mod convergence;
mod file_format;
mod inclusion;
mod nonlinear;
mod outputs;
mod shards;
mod surface;
