//! The visual model's share of a vademecum: its spatial modes at the accessible surface's
//! vertices (the load positions' nodes) only, so that a frame forms the drawn surface without
//! the whole field. On the liver the surface is a third of the nodes, and the interior nodes
//! of each load's near field are skipped as well.

use nalgebra::Vector3;

use super::Vademecum;
use super::vademecum::add_scaled_modes;

/// A vademecum's spatial modes restricted to its load positions, and where each volume node
/// sits among them.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceModes {
    /// Per load step, mode after mode, each over `3 × positions` values.
    steps: Vec<Vec<f32>>,
    /// Per volume node, its load position (`NOT_ON_SURFACE` for the others).
    position_of_node: Vec<u32>,
}

const NOT_ON_SURFACE: u32 = u32::MAX;

impl SurfaceModes {
    pub fn new(vademecum: &Vademecum) -> Self {
        let mut position_of_node = vec![NOT_ON_SURFACE; vademecum.header.node_count];
        for (m, &node) in vademecum.positions.iter().enumerate() {
            position_of_node[node as usize] = m as u32;
        }
        let dofs = vademecum.dof_count();
        let steps = vademecum
            .steps
            .iter()
            .map(|step| {
                step.spatial
                    .chunks_exact(dofs)
                    .flat_map(|mode| {
                        vademecum.positions.iter().flat_map(move |&node| {
                            let at = 3 * node as usize;
                            mode[at..at + 3].iter().copied()
                        })
                    })
                    .collect()
            })
            .collect();
        Self {
            steps,
            position_of_node,
        }
    }

    /// The load position at volume node `node`, if it is one.
    pub fn position_of(&self, node: usize) -> Option<usize> {
        match self.position_of_node[node] {
            NOT_ON_SURFACE => None,
            m => Some(m as usize),
        }
    }

    /// Adds `vademecum`'s near-field correction of load step `step` for a force on `shares`
    /// at the positions to `u` (`3 × positions`): the entries at interior nodes are skipped.
    pub fn add_corrections(
        &self,
        vademecum: &Vademecum,
        step: usize,
        load: (&[(usize, f64)], &Vector3<f64>),
        u: &mut [f64],
    ) {
        let (shares, force_n) = load;
        vademecum.add_corrections_at(step, shares, force_n, |node| self.position_of(node), u);
    }

    /// Adds `Σ_k c_k X^k` of load step `step` at the positions to `u` (`3 × positions`).
    pub fn add_modes(&self, step: usize, coefficients: &[f64], u: &mut [f64]) {
        add_scaled_modes(&self.steps[step], coefficients, u);
    }
}
