//! The check on the X-FEM solver itself: a cut that follows element faces, made by doubling
//! the nodes on it, so that plain FEM solves the cut organ. The elements on the cut face's
//! negative side take the copies; the nodes on the face's edge (the cut's front) stay shared.

use super::CutError;
use super::incision::CutFace;
use crate::fem::{Dirichlet, FemModel};
use crate::mesh::{Regions, TetMesh};

/// The model with the nodes strictly inside `face` doubled, and for each copy the node it
/// copies (copy `k` is node `node_count + k`). Refused when the face's plane crosses an element
/// with a corner within one face size of the face (a conservative test: the cut must run
/// along element faces).
pub fn split_along(model: &FemModel, face: &CutFace) -> Result<(FemModel, Vec<usize>), CutError> {
    let mesh = model.mesh();
    let snap_m = 1e-9 * face.size_m();
    let phi: Vec<f64> = mesh
        .nodes()
        .iter()
        .map(|p| face.signed_distance(p))
        .map(|d| if d.abs() <= snap_m { 0.0 } else { d })
        .collect();
    if let Some(t) = mesh.tets().iter().position(|tet| {
        tet.iter().any(|&n| phi[n] > 0.0)
            && tet.iter().any(|&n| phi[n] < 0.0)
            && tet
                .iter()
                .any(|&n| face.covers(&mesh.nodes()[n], face.size_m()))
    }) {
        return Err(CutError::Degenerate(format!(
            "element {t} is crossed by the cut: a split mesh needs a cut along element faces"
        )));
    }
    let doubled: Vec<usize> = (0..mesh.node_count())
        .filter(|&n| phi[n] == 0.0 && face.covers(&mesh.nodes()[n], -snap_m))
        .collect();
    let mut copy_of = vec![usize::MAX; mesh.node_count()];
    for (k, &n) in doubled.iter().enumerate() {
        copy_of[n] = mesh.node_count() + k;
    }
    let tets = mesh
        .tets()
        .iter()
        .map(|tet| {
            let below = tet.iter().any(|&n| phi[n] < 0.0);
            tet.map(|n| {
                if below && copy_of[n] != usize::MAX {
                    copy_of[n]
                } else {
                    n
                }
            })
        })
        .collect();
    let mut nodes = mesh.nodes().to_vec();
    nodes.extend(doubled.iter().map(|&n| mesh.nodes()[n]));
    let split = TetMesh::new("split mesh", nodes, tets, Regions::default())
        .map_err(|e| CutError::Solve(e.to_string()))?;
    let dirichlet = doubled_dirichlet(model, &doubled)?;
    let split = FemModel::new(split, *model.material(), dirichlet).map_err(|e| match e {
        crate::fem::FemError::Unconstrained { .. } => CutError::Detached,
        other => CutError::Solve(other.to_string()),
    })?;
    Ok((split, doubled))
}

/// The model's prescribed displacements, with each copy held as its node is.
fn doubled_dirichlet(model: &FemModel, doubled: &[usize]) -> Result<Dirichlet, CutError> {
    let nodes = model.mesh().node_count();
    let held = model.dirichlet();
    let mut dirichlet = Dirichlet::new(nodes + doubled.len());
    let copies = doubled.iter().enumerate().map(|(k, &n)| (n, nodes + k));
    for (from, to) in (0..nodes).map(|n| (n, n)).chain(copies) {
        let values = [0, 1, 2].map(|c| held.value(3 * from + c));
        if values.iter().any(Option::is_some) {
            dirichlet
                .prescribe(to, values.map(|v| v.unwrap_or(0.0)))
                .map_err(|e| CutError::Solve(e.to_string()))?;
        }
    }
    Ok(dirichlet)
}
