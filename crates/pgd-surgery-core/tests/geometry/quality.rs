//! The quality report against hand-computed elements and broken meshes.

use nalgebra::Point3;
use pgd_surgery_core::mesh::{QualityReport, aspect_ratio, box_mesh, dihedral_range_deg};

#[test]
fn a_regular_tetrahedron_has_arccos_one_third_everywhere_and_unit_aspect() {
    let s = 1.0 / 2.0_f64.sqrt();
    let p = [
        Point3::new(1.0, 0.0, -s),
        Point3::new(-1.0, 0.0, -s),
        Point3::new(0.0, 1.0, s),
        Point3::new(0.0, -1.0, s),
    ];
    let expected = (1.0_f64 / 3.0).acos().to_degrees(); // 70.53°
    let (lo, hi) = dihedral_range_deg(&p);
    assert!(
        (lo - expected).abs() < 1e-9 && (hi - expected).abs() < 1e-9,
        "{lo} {hi}"
    );
    assert!((aspect_ratio(&p) - 1.0).abs() < 1e-12);
}

#[test]
fn the_corner_tetrahedron_has_right_angles() {
    let p = [
        Point3::origin(),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(0.0, 1.0, 0.0),
        Point3::new(0.0, 0.0, 1.0),
    ];
    let (lo, hi) = dihedral_range_deg(&p);
    // Three 90° angles at the corner's edges, three arccos(1/√3) = 54.74° at the slanted face.
    assert!(
        (hi - 90.0).abs() < 1e-9
            && (lo - (1.0_f64 / 3.0_f64.sqrt()).acos().to_degrees()).abs() < 1e-9
    );
}

#[test]
fn holes_inversions_and_slivers_are_reported_and_refused() {
    let mesh = box_mesh([1.0, 1.0, 1.0], [2, 2, 2]).unwrap();
    let good = QualityReport::measure(mesh.nodes(), mesh.tets());
    assert!(good.refusal().is_none() && good.watertight(), "{good}");
    assert!((good.volume_m3 - 1.0).abs() < 1e-12);

    let mut tets = mesh.tets().to_vec();
    let inverted_at = 5;
    tets[inverted_at].swap(0, 1);
    let inverted = QualityReport::measure(mesh.nodes(), &tets);
    assert_eq!(
        (inverted.inverted, inverted.first_inverted),
        (1, Some(inverted_at))
    );
    assert!(inverted.refusal().unwrap().contains("inverted"));

    let mut nodes = mesh.nodes().to_vec();
    let [a, b, c, _] = mesh.tets()[7];
    nodes.push(Point3::from(
        (nodes[a].coords + nodes[b].coords + nodes[c].coords) / 3.0,
    ));
    let mut flat = mesh.tets().to_vec();
    flat.push([a, b, c, nodes.len() - 1]);
    let degenerate = QualityReport::measure(&nodes, &flat);
    assert_eq!(degenerate.degenerate, 1);
    assert!(degenerate.refusal().unwrap().contains("degenerate"));

    // Two boxes sharing a single edge: the surface is closed but not manifold there.
    let mut nodes = mesh.nodes().to_vec();
    let offset = nodes.len();
    nodes.extend(
        mesh.nodes()
            .iter()
            .map(|p| Point3::new(p.x + 1.0, p.y + 1.0, p.z)),
    );
    let mut tets = mesh.tets().to_vec();
    tets.extend(mesh.tets().iter().map(|t| t.map(|n| n + offset)));
    // The second box's edge x = y = 1 (its own x = y = 0) coincides with the first box's
    // vertical edge x = y = 1: merge those nodes, so four boundary faces meet there.
    for n in tets.iter_mut().flatten().filter(|n| **n >= offset) {
        let q = nodes[*n];
        if let Some(m) = (0..offset).find(|&m| (nodes[m] - q).norm() < 1e-12) {
            *n = m;
        }
    }
    let pinched = QualityReport::measure(&nodes, &tets);
    assert!(pinched.non_manifold_edges > 0, "{pinched}");
    assert!(
        pinched
            .refusal()
            .unwrap()
            .contains("watertight and manifold")
    );
}
