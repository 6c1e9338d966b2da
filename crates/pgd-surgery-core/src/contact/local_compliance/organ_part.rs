//! One organ's side of the near-field compliance, as the pointshell loads it: the load
//! positions its nodes blend, the corrections between them, and the directions along which
//! the nodes' forces are summed at each position.

use std::collections::{BTreeMap, HashMap};

use nalgebra::{Matrix3, Vector3};

use crate::pgd::Vademecum;

/// One organ's positions under the pointshell, numbered in the order the nodes first load
/// them.
pub(super) struct OrganPart {
    /// Per node, the positions (this part's numbers) its force is shared among, with weights.
    pub blends: Vec<Vec<(usize, f64)>>,
    /// Per position `a`, for each position `b` whose near field reaches it, `S_ab`: the
    /// symmetric part of the linear step's correction at `a` under a unit load at `b` (m/N,
    /// columns along the load). Symmetric as a whole: `S_ba = S_abᵀ`.
    pub blocks: Vec<BTreeMap<usize, Matrix3<f64>>>,
}

impl OrganPart {
    /// `vademecum`'s side for nodes that load its positions as `blends` (its position
    /// indices, with weights).
    pub fn new(vademecum: &Vademecum, blends: impl IntoIterator<Item = Vec<(usize, f64)>>) -> Self {
        let mut numbers: HashMap<usize, usize> = HashMap::new();
        let mut positions = Vec::new();
        let blends: Vec<Vec<(usize, f64)>> = blends
            .into_iter()
            .map(|blend| {
                let mut number = |p: usize| {
                    *numbers.entry(p).or_insert_with(|| {
                        positions.push(p);
                        positions.len() - 1
                    })
                };
                blend.into_iter().map(|(p, w)| (number(p), w)).collect()
            })
            .collect();
        let blocks = near_field_blocks(vademecum, &positions);
        Self { blends, blocks }
    }

    /// Per position, the unit vectors along which the forces of the nodes that load it are
    /// summed and its motion is read: their common normal where they share one (a boundary
    /// node alone at its position), otherwise the three axes. One direction where one will
    /// do keeps the solve's block as small as the nodes.
    pub fn directions(&self, normals: &[Vector3<f64>]) -> Vec<Vec<Vector3<f64>>> {
        let mut seen: Vec<Option<Vector3<f64>>> = vec![None; self.blocks.len()];
        let mut shared = vec![true; self.blocks.len()];
        for (blend, normal) in self.blends.iter().zip(normals) {
            for &(a, _) in blend {
                match seen[a] {
                    None => seen[a] = Some(*normal),
                    Some(n) => shared[a] &= n == *normal,
                }
            }
        }
        seen.into_iter()
            .zip(shared)
            .map(|(normal, shared)| match (normal, shared) {
                (Some(n), true) => vec![n],
                _ => vec![Vector3::x(), Vector3::y(), Vector3::z()],
            })
            .collect()
    }
}

/// `S_ab` between `positions` (the vademecum's indices) from the linear step's near-field
/// corrections: each correction of `b` that lands on a position `a` of the list gives half of
/// itself to `S_ab` and its transpose to `S_ba`.
fn near_field_blocks(
    vademecum: &Vademecum,
    positions: &[usize],
) -> Vec<BTreeMap<usize, Matrix3<f64>>> {
    let number_of_node: HashMap<u32, usize> = positions
        .iter()
        .enumerate()
        .map(|(a, &p)| (vademecum.positions[p], a))
        .collect();
    let local = &vademecum.steps[0].local;
    let mut blocks = vec![BTreeMap::new(); positions.len()];
    for (b, &p) in positions.iter().enumerate() {
        for e in local.corrections_of(p) {
            let Some(&a) = number_of_node.get(&local.correction_nodes[e]) else {
                continue;
            };
            let column = |d: Vector3<f64>| local.residual(e, &d);
            let r = 0.5
                * Matrix3::from_columns(&[Vector3::x(), Vector3::y(), Vector3::z()].map(column));
            *blocks[a].entry(b).or_insert_with(Matrix3::zeros) += r;
            *blocks[b].entry(a).or_insert_with(Matrix3::zeros) += r.transpose();
        }
    }
    blocks
}
