pub mod fem;
pub mod mesh;
