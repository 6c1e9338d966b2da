//! A pointshell: the nodes of one organ that probe the master's distance field, with what the
//! contact stage needs of each, gathered once (rest position and distance, penalty area, the
//! organ's modes there, and the master position that takes the reaction).

use nalgebra::Vector3;

use super::modal_rows::ModalRows;
use super::{ContactSurface, DistanceField};
use crate::pgd::Vademecum;

#[derive(Clone, Debug, PartialEq)]
pub struct Pointshell {
    /// Load positions of the shell organ.
    pub positions: Vec<u32>,
    pub rest_m: Vec<Vector3<f32>>,
    /// The master's rest distance at each node (m), from the lattice.
    pub rest_distance_m: Vec<f32>,
    /// The rest field's outward direction at each node.
    pub rest_normal: Vec<Vector3<f64>>,
    /// Lumped surface area of each node (m²): its share of the penalty.
    pub area_m2: Vec<f32>,
    /// The shell organ's displacement and load modes at each node.
    pub displacement: ModalRows,
    pub load: ModalRows,
    /// The master position nearest each node at rest: where the reaction goes.
    pub master_positions: Vec<u32>,
    /// The master's load modes there.
    pub master_load: ModalRows,
    /// Per shell mode, the largest displacement of any node.
    pub mode_bounds: Vec<f32>,
}

impl Pointshell {
    /// Every accessible position of `shell` inside the master's lattice: the boundary nodes
    /// that can meet the master at all.
    pub fn boundary(
        shell: &Vademecum,
        master: &Vademecum,
        master_surface: &ContactSurface,
        field: &DistanceField,
    ) -> Self {
        let inside: Vec<(u32, f64, Vector3<f64>)> = (0..shell.positions.len())
            .filter_map(|m| {
                let p = Vector3::from(shell.position_coords_m[m].map(f64::from));
                let sample = field.at_rest(&p)?;
                Some((m as u32, sample.distance_m, sample.normal))
            })
            .collect();
        let positions: Vec<u32> = inside.iter().map(|n| n.0).collect();
        let rest_m: Vec<Vector3<f32>> = positions
            .iter()
            .map(|&m| Vector3::from(shell.position_coords_m[m as usize]))
            .collect();
        let master_positions: Vec<u32> = rest_m
            .iter()
            .map(|p| nearest_corner(master, master_surface, &p.map(f64::from)))
            .collect();
        let displacement = ModalRows::displacements(
            shell,
            positions
                .iter()
                .map(|&m| shell.positions[m as usize] as usize),
        );
        Self {
            rest_distance_m: inside.iter().map(|n| n.1 as f32).collect(),
            rest_normal: inside.iter().map(|n| n.2).collect(),
            area_m2: positions
                .iter()
                .map(|&m| shell.position_areas_m2[m as usize])
                .collect(),
            load: ModalRows::loads(shell, positions.iter().map(|&m| m as usize)),
            master_load: ModalRows::loads(master, master_positions.iter().map(|&m| m as usize)),
            mode_bounds: displacement.bounds(),
            displacement,
            positions,
            rest_m,
            master_positions,
        }
    }

    pub fn len(&self) -> usize {
        self.positions.len()
    }

    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// `Σ_k |α_k| max|X^k|`: no node moves farther than this (m).
    pub fn movement_bound_m(&self, alpha: &[f32]) -> f32 {
        super::modal_rows::movement_bound(alpha, &self.mode_bounds)
    }
}

/// The master position nearest `p` on its rest surface: the corner of the closest triangle
/// with the largest barycentric weight.
fn nearest_corner(master: &Vademecum, surface: &ContactSurface, p: &Vector3<f64>) -> u32 {
    let hit = surface
        .closest(p)
        .expect("a finite point always has a closest surface point");
    let corners = master.triangles[hit.at.triangle];
    let best = (0..3)
        .max_by(|&a, &b| hit.at.barycentric[a].total_cmp(&hit.at.barycentric[b]))
        .expect("three corners");
    corners[best]
}
