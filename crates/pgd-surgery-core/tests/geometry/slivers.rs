//! A volume mesh with a sliver: measured, the refusal names the worst tetrahedron (one of the
//! moved node's) and its angle;
//! read from a file, it is meshed anew from its boundary, its quality accepted, its volume
//! kept and its regions carried over where they lie.

use nalgebra::Point3;
use pgd_surgery_core::mesh::io::{ImportOptions, load, write_vtu};
use pgd_surgery_core::mesh::{QualityReport, TetMesh, box_mesh};

use super::import::file;

const SIZE_M: [f64; 3] = [0.04, 0.03, 0.02];

/// A box whose interior node nearest its centre is moved 99.9 % of the way to the far face
/// of one of its tetrahedra: that one a sliver, every other still positive (the node stays
/// inside its own star, which is convex); and the node moved.
fn box_with_sliver() -> (TetMesh, usize) {
    let mesh = box_mesh(SIZE_M, [4, 3, 2]).unwrap();
    let centre = Point3::from(nalgebra::Vector3::from(SIZE_M) / 2.0);
    let node = (0..mesh.node_count())
        .min_by(|&a, &b| {
            let d = |n: usize| (mesh.nodes()[n] - centre).norm();
            d(a).total_cmp(&d(b))
        })
        .unwrap();
    let tet = (mesh.tets().iter())
        .find(|tet| tet.contains(&node))
        .unwrap();
    let others: Vec<Point3<f64>> = (tet.iter())
        .filter(|&&n| n != node)
        .map(|&n| mesh.nodes()[n])
        .collect();
    let normal = (others[1] - others[0])
        .cross(&(others[2] - others[0]))
        .normalize();
    let p = mesh.nodes()[node];
    let to_face = normal * normal.dot(&(others[0] - p));
    let mut nodes = mesh.nodes().to_vec();
    nodes[node] = p + to_face * 0.999;
    let moved = TetMesh::new(
        "sliver",
        nodes,
        mesh.tets().to_vec(),
        mesh.regions().clone(),
    );
    (moved.unwrap(), node)
}

#[test]
fn a_sliver_is_named_then_meshed_anew_from_the_boundary() {
    let (mesh, moved) = box_with_sliver();
    let report = QualityReport::measure(mesh.nodes(), mesh.tets());
    assert_eq!(report.inverted, 0);
    let reason = report.refusal().expect("a sliver refused as it is");
    let sliver = report.min_dihedral_tet.unwrap();
    assert!(report.min_dihedral_deg < 1.0 && mesh.tets()[sliver].contains(&moved));
    assert!(
        reason.contains(&format!("(tetrahedron {sliver})")) && reason.contains("dihedral"),
        "{reason}"
    );

    let path = file("sliver.vtu", b"");
    write_vtu(&path, &mesh, &[]).unwrap();
    let mended = load(&path, &ImportOptions::default()).unwrap();
    let after = QualityReport::measure(mended.nodes(), mended.tets());
    assert!(after.refusal().is_none(), "{after}");
    // Stuffing rounds the box's edges and corners within about an element (4,000 nodes in
    // the box: about 2 mm): the volume is kept to 1 % and the side's area to 5 %, which is
    // what rounding a band of that width along its edges allows.
    let volume = SIZE_M.iter().product::<f64>();
    let lost = 1.0 - mended.volume() / volume;
    let nodes = mended.node_set("x0").unwrap();
    let off_side_m = (nodes.iter()).fold(0.0_f64, |m, &n| m.max(mended.nodes()[n].x.abs()));
    let faces = mended.face_set("x0").unwrap();
    let area: f64 = (faces.iter())
        .map(|f| {
            let [a, b, c] = f.map(|n| mended.nodes()[n]);
            0.5 * (b - a).cross(&(c - a)).norm()
        })
        .sum();
    let area_share = area / (SIZE_M[1] * SIZE_M[2]);
    eprintln!(
        "volume lost {lost:.4}, x0 nodes off the side up to {off_side_m:.2e} m, x0 area {area_share:.4} of the side"
    );
    assert!(lost.abs() < 0.01, "{lost}");
    assert!(!nodes.is_empty() && off_side_m < 1e-9, "{off_side_m}");
    assert!((area_share - 1.0).abs() < 0.05, "{area_share}");
}
