//! The drawn surface formed from the modes at the surface vertices alone equals the whole
//! field's values there, tool load and contact points included.

use nalgebra::Vector3;
use pgd_surgery_core::pgd::{Deformation, PatchLoad, PointLoad, SurfaceModes, SurfacePoint};

use crate::common::{block_mesh, block_model, build_block};

/// A press on the top face and two contact points: every surface vertex of the surface-only
/// path within 1e-6 of the largest displacement of the whole field's (f32 modes summed in
/// another order).
#[test]
fn the_surface_alone_equals_the_whole_field_there() {
    let model = block_model(block_mesh([6, 4, 3]));
    let vademecum = build_block(&model, 8);
    let mut deformation = Deformation::new(&vademecum, 1);
    let at = SurfacePoint {
        triangle: vademecum.triangles.len() / 2,
        barycentric: [0.2, 0.3, 0.5],
    };
    deformation.loads[0] = PatchLoad {
        shares: vademecum.patch(&at).shares,
        force_n: Vector3::new(0.05, -0.02, -0.4),
    };
    deformation.coupling_points = vec![
        PointLoad {
            position: 3,
            force_n: Vector3::new(0.0, 0.0, -0.1),
        },
        PointLoad {
            position: vademecum.positions.len() - 2,
            force_n: Vector3::new(0.03, 0.0, -0.05),
        },
    ];
    deformation.evaluate(&vademecum);

    let mut field = vec![0.0; vademecum.dof_count()];
    deformation.field_into(&vademecum, &mut field);
    let surface = SurfaceModes::new(&vademecum);
    let mut at_vertices = vec![0.0; 3 * vademecum.positions.len()];
    deformation.surface_into(&vademecum, &surface, &mut at_vertices);

    let largest = field.iter().fold(0.0f64, |m, u| m.max(u.abs()));
    assert!(largest > 1e-4, "the loads moved nothing");
    for (m, &node) in vademecum.positions.iter().enumerate() {
        for c in 0..3 {
            let whole = field[3 * node as usize + c];
            let alone = at_vertices[3 * m + c];
            assert!(
                (whole - alone).abs() <= 1e-6 * largest,
                "position {m}, component {c}: {alone} against {whole}"
            );
        }
    }
}
