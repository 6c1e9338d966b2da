//! Tetrahedral meshes: the validated volume mesh, its named regions, its boundary surface,
//! and structured meshes for reference problems. Plain Rust, no Bevy.

mod boundary;
mod box_mesh;
mod error;
pub mod io;
pub mod organs;
mod quality;
mod select;
mod shell;
mod split;
mod stuffing;
mod tet_mesh;

pub use boundary::{NOT_ON_SURFACE, Surface, area_vector, vertex_normals};
pub use box_mesh::box_mesh;
pub use error::MeshError;
pub use quality::{QualityReport, aspect_ratio, dihedral_range_deg};
pub use select::{RegionSelectors, SELECTOR_FORMS, SelectionReport, Selector};
pub use shell::{MidSurface, extrude, revolution, spherical_cap};
pub use stuffing::{Implicit, MOST_NODES, MeshDensity, stuff, stuff_to, stuff_to_node_count};
pub use tet_mesh::{DEGENERATE_QUALITY, Regions, TetMesh, quality, signed_volume};
