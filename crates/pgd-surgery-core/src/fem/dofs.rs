//! Dirichlet conditions and the numbering of free degrees of freedom.
//!
//! Node `n` owns dofs `3n, 3n+1, 3n+2` (x, y, z). Prescribed dofs are removed from the linear
//! systems, so every sparse matrix of the solver is indexed by free dofs only.

use super::FemError;

/// Marks a prescribed dof in [`DofMap::free_index`].
pub const PRESCRIBED: usize = usize::MAX;

/// Prescribed displacements, in metres, per dof.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Dirichlet {
    values: Vec<Option<f64>>,
}

impl Dirichlet {
    pub fn new(node_count: usize) -> Self {
        Self {
            values: vec![None; 3 * node_count],
        }
    }

    /// Holds every component of these nodes at zero.
    pub fn clamp(&mut self, nodes: &[usize]) -> Result<(), FemError> {
        for &n in nodes {
            self.prescribe(n, [0.0; 3])?;
        }
        Ok(())
    }

    /// Prescribes the displacement of one node (m).
    pub fn prescribe(&mut self, node: usize, displacement_m: [f64; 3]) -> Result<(), FemError> {
        let nodes = self.values.len() / 3;
        if node >= nodes {
            return Err(FemError::NodeOutOfRange { node, nodes });
        }
        for (c, value) in displacement_m.into_iter().enumerate() {
            if !value.is_finite() {
                return Err(FemError::InvalidInput {
                    what: "prescribed displacement",
                    value,
                    problem: "not finite",
                });
            }
            self.values[3 * node + c] = Some(value);
        }
        Ok(())
    }

    /// Prescribes one component (0 = x, 1 = y, 2 = z) of a node's displacement (m), leaving
    /// the others free: a roller on a plane of symmetry.
    pub fn prescribe_component(
        &mut self,
        node: usize,
        component: usize,
        displacement_m: f64,
    ) -> Result<(), FemError> {
        let nodes = self.values.len() / 3;
        if node >= nodes {
            return Err(FemError::NodeOutOfRange { node, nodes });
        }
        if component > 2 || !displacement_m.is_finite() {
            return Err(FemError::InvalidInput {
                what: "prescribed displacement component",
                value: if component > 2 {
                    component as f64
                } else {
                    displacement_m
                },
                problem: "not a component 0-2 with a finite value",
            });
        }
        self.values[3 * node + component] = Some(displacement_m);
        Ok(())
    }

    pub fn value(&self, dof: usize) -> Option<f64> {
        self.values[dof]
    }

    pub fn dof_count(&self) -> usize {
        self.values.len()
    }

    /// The full displacement vector holding the prescribed values scaled by `factor`, zero
    /// elsewhere: the start of a load step.
    pub fn scaled_values(&self, factor: f64) -> Vec<f64> {
        self.values
            .iter()
            .map(|v| v.map_or(0.0, |v| v * factor))
            .collect()
    }
}

/// Full dof ↔ free dof numbering.
#[derive(Clone, Debug, PartialEq)]
pub struct DofMap {
    /// Full dof → free index, or [`PRESCRIBED`].
    pub free_index: Vec<usize>,
    /// Free index → full dof.
    pub free_dofs: Vec<usize>,
}

impl DofMap {
    pub fn new(dirichlet: &Dirichlet) -> Self {
        let mut free_index = vec![PRESCRIBED; dirichlet.dof_count()];
        let mut free_dofs = Vec::with_capacity(dirichlet.dof_count());
        for (dof, slot) in free_index.iter_mut().enumerate() {
            if dirichlet.value(dof).is_none() {
                *slot = free_dofs.len();
                free_dofs.push(dof);
            }
        }
        Self {
            free_index,
            free_dofs,
        }
    }

    pub fn free_count(&self) -> usize {
        self.free_dofs.len()
    }

    /// Gathers the free entries of a full vector.
    pub fn restrict(&self, full: &[f64]) -> Vec<f64> {
        self.free_dofs.iter().map(|&d| full[d]).collect()
    }
}
