//! A structured tetrahedral mesh of a box: the reference geometry for beams, patch tests and
//! benchmarks, where analytic solutions exist.

use nalgebra::Point3;

use super::{MeshError, Regions, TetMesh};

/// The six Kuhn tetrahedra of a unit cube, as corner indices `i + 2j + 4k`. Every cube is
/// split along its main diagonal the same way, so neighbouring cubes share face diagonals and
/// the mesh is conforming.
const KUHN: [[usize; 4]; 6] = [
    [0, 1, 3, 7],
    [0, 1, 7, 5],
    [0, 2, 7, 3],
    [0, 2, 6, 7],
    [0, 4, 5, 7],
    [0, 4, 7, 6],
];

/// Meshes the box `[0, size.x] × [0, size.y] × [0, size.z]` (metres) with `cells` cubes along
/// each axis, six tetrahedra each. Node sets `x0`, `x1`, `y0`, `y1`, `z0`, `z1` and matching
/// face sets name the six sides.
pub fn box_mesh(size_m: [f64; 3], cells: [usize; 3]) -> Result<TetMesh, MeshError> {
    let [nx, ny, nz] = cells.map(|c| c.max(1));
    let node_index = |i: usize, j: usize, k: usize| i + (nx + 1) * (j + (ny + 1) * k);
    let mut nodes = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                nodes.push(Point3::new(
                    size_m[0] * i as f64 / nx as f64,
                    size_m[1] * j as f64 / ny as f64,
                    size_m[2] * k as f64 / nz as f64,
                ));
            }
        }
    }
    let mut tets = Vec::with_capacity(6 * nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let corner = |c: usize| node_index(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2));
                for kuhn in KUHN {
                    tets.push(kuhn.map(corner));
                }
            }
        }
    }
    let mut mesh = TetMesh::new("box mesh", nodes, tets, Regions::default())?;
    name_sides(&mut mesh, size_m)?;
    Ok(mesh)
}

/// Names the nodes and boundary faces on each of the six sides.
fn name_sides(mesh: &mut TetMesh, size_m: [f64; 3]) -> Result<(), MeshError> {
    let surface = super::Surface::extract(mesh);
    let tolerance = 1e-9 * size_m.iter().cloned().fold(0.0, f64::max);
    for (axis, letter) in ["x", "y", "z"].into_iter().enumerate() {
        for (side, value) in [(0, 0.0), (1, size_m[axis])] {
            let on = |n: usize| (mesh.nodes()[n][axis] - value).abs() <= tolerance;
            let name = format!("{letter}{side}");
            let nodes: Vec<usize> = (0..mesh.node_count()).filter(|&n| on(n)).collect();
            let faces: Vec<[usize; 3]> = surface
                .triangles
                .iter()
                .filter(|f| f.iter().all(|&n| on(n)))
                .copied()
                .collect();
            mesh.set_node_set(&name, nodes)?;
            mesh.set_face_set(&name, faces)?;
        }
    }
    Ok(())
}
