//! The volume mesh every organ is simulated on: linear tetrahedra plus named regions.

use std::collections::BTreeMap;

use nalgebra::{Point3, Vector3};

use super::error::MeshError;

/// Below this normalized quality a tetrahedron counts as degenerate (flat). The quality is
/// `6√2·V / l_rms³`: 1 for a regular tetrahedron, 0 for a flat one, and invariant to scale,
/// so the threshold means the same thing for a cornea in millimetres and a liver in decimetres.
pub const DEGENERATE_QUALITY: f64 = 1e-6;

/// Named node and face sets stored with a mesh: clamped nodes, the accessible surface,
/// attachment interfaces, pressurized faces. Names are free-form; the FEM and PGD layers look
/// them up by name, so a missing one is a clear error rather than a silent empty set.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Regions {
    pub node_sets: BTreeMap<String, Vec<usize>>,
    pub face_sets: BTreeMap<String, Vec<[usize; 3]>>,
}

/// A validated tetrahedral mesh in metres: every tetrahedron is positively oriented
/// (`det[b−a, c−a, d−a] > 0`) and not degenerate, every index is in range, every coordinate
/// finite. Construction is the only way in, so downstream code never re-checks.
#[derive(Clone, Debug, PartialEq)]
pub struct TetMesh {
    nodes: Vec<Point3<f64>>,
    tets: Vec<[usize; 4]>,
    regions: Regions,
}

impl TetMesh {
    /// Validates and builds a mesh. `source` names where the data came from (a file path, or
    /// a generator name) so that an error can say which mesh is broken.
    pub fn new(
        source: &str,
        nodes: Vec<Point3<f64>>,
        tets: Vec<[usize; 4]>,
        regions: Regions,
    ) -> Result<Self, MeshError> {
        let mesh = Self {
            nodes,
            tets,
            regions,
        };
        mesh.validate(source)?;
        Ok(mesh)
    }

    pub fn nodes(&self) -> &[Point3<f64>] {
        &self.nodes
    }

    pub fn tets(&self) -> &[[usize; 4]] {
        &self.tets
    }

    pub fn regions(&self) -> &Regions {
        &self.regions
    }

    /// Adds or replaces a node set, checking its indices.
    pub fn set_node_set(&mut self, name: &str, nodes: Vec<usize>) -> Result<(), MeshError> {
        self.check_region(name, nodes.iter())?;
        self.regions.node_sets.insert(name.to_owned(), nodes);
        Ok(())
    }

    /// Removes the node set and the face set `name`, if there are any.
    pub fn remove_region(&mut self, name: &str) {
        self.regions.node_sets.remove(name);
        self.regions.face_sets.remove(name);
    }

    /// Adds or replaces a face set, checking its indices.
    pub fn set_face_set(&mut self, name: &str, faces: Vec<[usize; 3]>) -> Result<(), MeshError> {
        self.check_region(name, faces.iter().flatten())?;
        self.regions.face_sets.insert(name.to_owned(), faces);
        Ok(())
    }

    fn check_region<'a>(
        &self,
        name: &str,
        mut indices: impl Iterator<Item = &'a usize>,
    ) -> Result<(), MeshError> {
        match indices.find(|&&n| n >= self.nodes.len()) {
            Some(&bad) => Err(MeshError::RegionIndex {
                region: name.to_owned(),
                index: bad,
                nodes: self.nodes.len(),
            }),
            None => Ok(()),
        }
    }

    /// Looks up a node set by name.
    pub fn node_set(&self, name: &str) -> Result<&[usize], MeshError> {
        self.regions
            .node_sets
            .get(name)
            .map(Vec::as_slice)
            .ok_or_else(|| MeshError::UnknownRegion {
                region: name.to_owned(),
                known: self.regions.node_sets.keys().cloned().collect(),
            })
    }

    /// Looks up a face set by name.
    pub fn face_set(&self, name: &str) -> Result<&[[usize; 3]], MeshError> {
        self.regions
            .face_sets
            .get(name)
            .map(Vec::as_slice)
            .ok_or_else(|| MeshError::UnknownRegion {
                region: name.to_owned(),
                known: self.regions.face_sets.keys().cloned().collect(),
            })
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    pub fn tet_count(&self) -> usize {
        self.tets.len()
    }

    /// The four corner positions of tetrahedron `t`.
    pub fn tet_points(&self, t: usize) -> [Point3<f64>; 4] {
        self.tets[t].map(|n| self.nodes[n])
    }

    /// Signed volume of tetrahedron `t` in m³ (positive for every tet of a valid mesh).
    pub fn tet_volume(&self, t: usize) -> f64 {
        signed_volume(&self.tet_points(t))
    }

    /// Total volume in m³.
    pub fn volume(&self) -> f64 {
        (0..self.tets.len()).map(|t| self.tet_volume(t)).sum()
    }

    fn validate(&self, source: &str) -> Result<(), MeshError> {
        let here = || source.to_owned();
        if self.tets.is_empty() {
            return Err(MeshError::Empty { mesh: here() });
        }
        if let Some((node, p)) = self
            .nodes
            .iter()
            .enumerate()
            .find(|(_, p)| !p.coords.iter().all(|c| c.is_finite()))
        {
            return Err(MeshError::NonFiniteNode {
                mesh: here(),
                node,
                position: [p.x, p.y, p.z],
            });
        }
        for (t, tet) in self.tets.iter().enumerate() {
            self.validate_tet(source, t, tet)?;
        }
        for (name, set) in &self.regions.node_sets {
            self.check_region(name, set.iter())?;
        }
        for (name, set) in &self.regions.face_sets {
            self.check_region(name, set.iter().flatten())?;
        }
        Ok(())
    }

    fn validate_tet(&self, source: &str, t: usize, tet: &[usize; 4]) -> Result<(), MeshError> {
        if let Some(&bad) = tet.iter().find(|&&n| n >= self.nodes.len()) {
            return Err(MeshError::TetIndex {
                mesh: source.to_owned(),
                tet: t,
                index: bad,
                nodes: self.nodes.len(),
            });
        }
        let distinct = (0..4).all(|i| (i + 1..4).all(|j| tet[i] != tet[j]));
        let points = self.tet_points(t);
        let volume = signed_volume(&points);
        let quality = if distinct { quality(&points) } else { 0.0 };
        if quality.abs() < DEGENERATE_QUALITY {
            return Err(MeshError::DegenerateTet {
                mesh: source.to_owned(),
                tet: t,
                nodes: *tet,
                volume_m3: volume,
                quality,
            });
        }
        if volume < 0.0 {
            return Err(MeshError::InvertedTet {
                mesh: source.to_owned(),
                tet: t,
                nodes: *tet,
                volume_m3: volume,
            });
        }
        Ok(())
    }
}

/// Signed volume `det[b−a, c−a, d−a] / 6`.
pub fn signed_volume(p: &[Point3<f64>; 4]) -> f64 {
    let e: [Vector3<f64>; 3] = [p[1] - p[0], p[2] - p[0], p[3] - p[0]];
    e[0].cross(&e[1]).dot(&e[2]) / 6.0
}

/// Scale-invariant signed quality `6√2·V / l_rms³`, 1 for the regular tetrahedron.
pub fn quality(p: &[Point3<f64>; 4]) -> f64 {
    let mut sum_sq = 0.0;
    for i in 0..4 {
        for j in i + 1..4 {
            sum_sq += (p[i] - p[j]).norm_squared();
        }
    }
    let l_rms = (sum_sq / 6.0).sqrt();
    if l_rms == 0.0 {
        return 0.0;
    }
    6.0 * std::f64::consts::SQRT_2 * signed_volume(p) / l_rms.powi(3)
}
