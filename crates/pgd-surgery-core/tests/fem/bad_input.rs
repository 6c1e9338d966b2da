//! Bad input gets an error that says what and where; nothing panics.

use nalgebra::{Point3, Vector3};
use pgd_surgery_core::fem::{Dirichlet, FemError, FemModel, Law, Loads, Material, NewtonSettings};
use pgd_surgery_core::mesh::{MeshError, TetMesh, box_mesh};

fn unit_tet() -> Vec<Point3<f64>> {
    vec![
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(0.0, 1.0, 0.0),
        Point3::new(0.0, 0.0, 1.0),
    ]
}

#[test]
fn an_inverted_tet_is_refused_with_its_index() {
    let mut nodes = unit_tet();
    nodes.push(Point3::new(1.0, 1.0, 1.0));
    let err = TetMesh::new(
        "t.msh",
        nodes,
        vec![[0, 1, 2, 3], [1, 3, 2, 4]],
        Default::default(),
    )
    .unwrap_err();
    assert!(
        matches!(err, MeshError::InvertedTet { tet: 1, .. }),
        "{err:?}"
    );
    let text = err.to_string();
    assert!(
        text.contains("t.msh") && text.contains("tetrahedron 1"),
        "{text}"
    );
}

#[test]
fn a_flat_tet_is_refused_as_degenerate() {
    let mut nodes = unit_tet();
    nodes[3] = Point3::new(0.3, 0.3, 1e-12);
    let err = TetMesh::new("flat", nodes, vec![[0, 1, 2, 3]], Default::default()).unwrap_err();
    assert!(
        matches!(err, MeshError::DegenerateTet { tet: 0, .. }),
        "{err:?}"
    );
}

#[test]
fn repeated_nodes_and_bad_indices_are_refused() {
    let err = TetMesh::new("dup", unit_tet(), vec![[0, 1, 1, 3]], Default::default()).unwrap_err();
    assert!(matches!(err, MeshError::DegenerateTet { .. }), "{err:?}");
    let err = TetMesh::new("idx", unit_tet(), vec![[0, 1, 2, 9]], Default::default()).unwrap_err();
    assert!(
        matches!(err, MeshError::TetIndex { index: 9, .. }),
        "{err:?}"
    );
    let mut nodes = unit_tet();
    nodes[2].y = f64::NAN;
    let err = TetMesh::new("nan", nodes, vec![[0, 1, 2, 3]], Default::default()).unwrap_err();
    assert!(
        matches!(err, MeshError::NonFiniteNode { node: 2, .. }),
        "{err:?}"
    );
}

fn liver() -> Material {
    Material::liver(Law::Linear)
}

#[test]
fn an_unclamped_body_is_refused_as_singular() {
    let mesh = box_mesh([0.1, 0.05, 0.05], [4, 2, 2]).unwrap();
    let free = Dirichlet::new(mesh.node_count());
    let err = FemModel::new(mesh.clone(), liver(), free).err().unwrap();
    assert!(
        matches!(err, FemError::Unconstrained { rank: 0, .. }),
        "{err:?}"
    );

    // Two clamped nodes leave the rotation about the line through them free.
    let mut two = Dirichlet::new(mesh.node_count());
    two.clamp(&[0, mesh.node_count() - 1]).unwrap();
    let err = FemModel::new(mesh, liver(), two).err().unwrap();
    assert!(
        matches!(err, FemError::Unconstrained { rank: 5, .. }),
        "{err:?}"
    );
    assert!(
        err.to_string()
            .contains("clamp at least three non-collinear nodes")
    );
}

#[test]
fn non_finite_loads_name_the_node() {
    let mut loads = Loads::new(4);
    let err = loads
        .add_nodal_force(2, [0.0, f64::INFINITY, 0.0])
        .unwrap_err();
    assert_eq!(
        err,
        FemError::NonFiniteLoad {
            node: 2,
            component: 1,
            value: f64::INFINITY
        }
    );
    assert_eq!(
        loads.total_force_n().norm(),
        0.0,
        "a refused load must leave the loads untouched"
    );
    let err = Loads::from_vec(vec![0.0, 0.0, 0.0, 0.0, 0.0, f64::NAN]).unwrap_err();
    assert!(
        matches!(
            err,
            FemError::NonFiniteLoad {
                node: 1,
                component: 2,
                ..
            }
        ),
        "{err:?}"
    );
    assert!(matches!(
        loads.add_nodal_force(7, [1.0; 3]),
        Err(FemError::NodeOutOfRange { node: 7, nodes: 4 })
    ));
}

#[test]
fn out_of_range_material_constants_name_the_field() {
    for (e, nu, rho, field) in [
        (-1.0, 0.3, 1000.0, "young_pa"),
        (f64::NAN, 0.3, 1000.0, "young_pa"),
        (1e3, 0.5, 1000.0, "poisson"),
        (1e3, -1.0, 1000.0, "poisson"),
        (1e3, 0.3, 0.0, "density_kg_m3"),
    ] {
        let err = Material::new(Law::Linear, e, nu, rho).unwrap_err();
        assert!(
            matches!(err, FemError::Material { field: f, .. } if f == field),
            "{err:?}"
        );
    }
}

#[test]
fn a_point_load_radius_below_the_mesh_spacing_is_refused() {
    let mesh = box_mesh([0.1, 0.1, 0.1], [2, 2, 2]).unwrap();
    let surface = pgd_surgery_core::mesh::Surface::extract(&mesh);
    let mut loads = Loads::new(mesh.node_count());
    let err = loads
        .add_point_load(
            &mesh,
            &surface,
            Point3::new(0.025, 0.025, 0.1),
            Vector3::z(),
            [0.0, 0.0, -1.0],
            1e-3,
        )
        .unwrap_err();
    assert!(err.to_string().contains("radius"), "{err}");
}

#[test]
fn newton_failure_names_the_load_step() {
    let mesh = box_mesh([0.1, 0.01, 0.01], [10, 1, 1]).unwrap();
    let mut dirichlet = Dirichlet::new(mesh.node_count());
    dirichlet.clamp(mesh.node_set("x0").unwrap()).unwrap();
    let mut loads = Loads::new(mesh.node_count());
    loads
        .add_traction(&mesh, mesh.face_set("x1").unwrap(), [0.0, 0.0, -2e3])
        .unwrap();
    let model = FemModel::new(mesh, Material::liver(Law::KirchhoffSaintVenant), dirichlet).unwrap();
    let settings = NewtonSettings {
        load_steps: 2,
        max_iterations: 2,
        ..NewtonSettings::default()
    };
    let err = model.solve_static(&loads, &settings).unwrap_err();
    assert!(
        matches!(
            err,
            FemError::NewtonNotConverged {
                step: 1,
                steps: 2,
                ..
            }
        ),
        "{err:?}"
    );
    assert!(err.to_string().contains("load step 1 of 2"), "{err}");
    let zero_steps = NewtonSettings {
        load_steps: 0,
        ..NewtonSettings::default()
    };
    assert!(matches!(
        model.solve_static(&loads, &zero_steps),
        Err(FemError::InvalidInput { .. })
    ));
}
