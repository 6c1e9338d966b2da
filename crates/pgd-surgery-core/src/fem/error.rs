//! Errors of the finite-element layer. Each names what is wrong and where.

use thiserror::Error;

use crate::mesh::MeshError;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum FemError {
    #[error(transparent)]
    Mesh(#[from] MeshError),

    #[error("material: {field} = {value} is out of range; expected {expected}")]
    Material {
        field: &'static str,
        value: f64,
        expected: &'static str,
    },

    #[error("load on node {node}: component {component} is {value}; loads must be finite")]
    NonFiniteLoad {
        node: usize,
        component: usize,
        value: f64,
    },

    #[error("{what}: {value} is {problem}")]
    InvalidInput {
        what: &'static str,
        value: f64,
        problem: &'static str,
    },

    #[error("node {node} is out of range: the mesh has {nodes} nodes")]
    NodeOutOfRange { node: usize, nodes: usize },

    #[error(
        "the system is singular: {component_nodes} connected nodes (including node {example_node}) \
         are not held against rigid-body motion ({rank} of 6 rigid modes constrained); clamp at \
         least three non-collinear nodes of every connected part"
    )]
    Unconstrained {
        example_node: usize,
        component_nodes: usize,
        rank: usize,
    },

    #[error(
        "the stiffness matrix is not positive definite: the model is singular (check its clamped \
         nodes) or has lost stability under compression (use more load steps or a smaller load)"
    )]
    NotPositiveDefinite,

    #[error("sparse factorization failed: {0}")]
    Factorization(String),

    #[error(
        "Newton did not converge in load step {step} of {steps}: relative residual {relative_residual:.3e} \
         after {iterations} iterations (tolerance {tolerance:.1e}); use more load steps or a smaller load"
    )]
    NewtonNotConverged {
        step: usize,
        steps: usize,
        iterations: usize,
        relative_residual: f64,
        tolerance: f64,
    },

    #[error("PGD mode {mode} became non-finite; check the material and the loads")]
    NonFiniteMode { mode: usize },

    #[error("the solution became non-finite in load step {step} of {steps}, iteration {iteration}")]
    NonFiniteSolution {
        step: usize,
        steps: usize,
        iteration: usize,
    },
}
