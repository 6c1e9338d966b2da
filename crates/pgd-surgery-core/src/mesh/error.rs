//! What can be wrong with a mesh, said so that a user can find and fix it.

use thiserror::Error;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum MeshError {
    #[error("{mesh}: the mesh has no tetrahedra")]
    Empty { mesh: String },

    #[error(
        "{mesh}: an element size of {size_mm} mm would mesh it with more than {most} nodes; ask for {finest_mm:.2} mm or more"
    )]
    TooFine {
        mesh: String,
        size_mm: f64,
        finest_mm: f64,
        most: usize,
    },

    #[error("{mesh}: node {node} has a non-finite coordinate {position:?}")]
    NonFiniteNode {
        mesh: String,
        node: usize,
        position: [f64; 3],
    },

    #[error(
        "{mesh}: tetrahedron {tet} refers to node {index}, but the mesh has only {nodes} nodes"
    )]
    TetIndex {
        mesh: String,
        tet: usize,
        index: usize,
        nodes: usize,
    },

    #[error(
        "{mesh}: tetrahedron {tet} (nodes {nodes:?}) is inverted: its volume is {volume_m3:.3e} m³; \
         swap two of its nodes, or check the mesher's node ordering convention"
    )]
    InvertedTet {
        mesh: String,
        tet: usize,
        nodes: [usize; 4],
        volume_m3: f64,
    },

    #[error(
        "{mesh}: tetrahedron {tet} (nodes {nodes:?}) is degenerate: volume {volume_m3:.3e} m³, \
         normalized quality {quality:.2e} (1 is a regular tetrahedron); remesh this region"
    )]
    DegenerateTet {
        mesh: String,
        tet: usize,
        nodes: [usize; 4],
        volume_m3: f64,
        quality: f64,
    },

    #[error("region '{region}' refers to node {index}, but the mesh has only {nodes} nodes")]
    RegionIndex {
        region: String,
        index: usize,
        nodes: usize,
    },

    #[error("no region named '{region}' in this mesh (it has: {known:?})")]
    UnknownRegion { region: String, known: Vec<String> },
}
