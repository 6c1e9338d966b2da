//! Boundary extraction: watertight, outward, with consistent numbering maps.

use std::collections::HashMap;

use nalgebra::Point3;
use pgd_surgery_core::mesh::{NOT_ON_SURFACE, Surface, area_vector, box_mesh};

#[test]
fn the_box_surface_is_closed_outward_and_has_the_right_area() {
    let size = [0.08, 0.05, 0.03];
    let mesh = box_mesh(size, [5, 4, 3]).unwrap();
    let surface = Surface::extract(&mesh);
    let [a, b, c] = size;
    let area = 2.0 * (a * b + b * c + c * a);
    assert!((surface.area(&mesh) - area).abs() < 1e-12 * area);

    // Every directed edge appears once and its reverse once: closed, manifold, consistently oriented.
    let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
    for f in &surface.triangles {
        for i in 0..3 {
            *edges.entry((f[i], f[(i + 1) % 3])).or_default() += 1;
        }
    }
    for (&(p, q), &count) in &edges {
        assert_eq!(count, 1, "edge {p}-{q} used twice in the same direction");
        assert_eq!(
            edges.get(&(q, p)),
            Some(&1),
            "edge {p}-{q} has no twin: surface not closed"
        );
    }
    // Euler characteristic of a sphere-like surface.
    let euler =
        surface.nodes.len() as i64 - (edges.len() / 2) as i64 + surface.triangles.len() as i64;
    assert_eq!(euler, 2);

    // Outward: the normal points away from the box centre.
    let centre = Point3::new(a / 2.0, b / 2.0, c / 2.0);
    for f in &surface.triangles {
        let mid =
            (mesh.nodes()[f[0]].coords + mesh.nodes()[f[1]].coords + mesh.nodes()[f[2]].coords)
                / 3.0;
        assert!(area_vector(mesh.nodes(), f).dot(&(mid - centre.coords)) > 0.0);
    }
}

#[test]
fn surface_and_volume_numbering_map_both_ways() {
    let mesh = box_mesh([0.04, 0.04, 0.04], [3, 3, 3]).unwrap();
    let surface = Surface::extract(&mesh);
    assert_eq!(surface.nodes.len(), 4 * 4 * 4 - 2 * 2 * 2);
    for (local, &node) in surface.nodes.iter().enumerate() {
        assert_eq!(surface.surface_index_of[node], local);
    }
    let interior = surface
        .surface_index_of
        .iter()
        .filter(|&&s| s == NOT_ON_SURFACE)
        .count();
    assert_eq!(interior, 8);
    for (f, local) in surface.triangles.iter().zip(surface.local_triangles()) {
        assert_eq!(f.map(|n| surface.surface_index_of[n]), local);
    }
    for (f, &t) in surface.triangles.iter().zip(&surface.triangle_tet) {
        assert!(
            f.iter().all(|n| mesh.tets()[t].contains(n)),
            "face {f:?} not on its tet {t}"
        );
    }
}

#[test]
fn vertex_normals_of_a_box_corner_point_along_the_diagonal_and_faces_are_flat() {
    let mesh = box_mesh([1.0, 1.0, 1.0], [2, 2, 2]).unwrap();
    let surface = Surface::extract(&mesh);
    let positions: Vec<[f32; 3]> = surface
        .nodes
        .iter()
        .map(|&n| mesh.nodes()[n].coords.map(|c| c as f32).into())
        .collect();
    let normals = pgd_surgery_core::mesh::vertex_normals(&surface.local_triangles(), &positions);
    for (p, n) in positions.iter().zip(&normals) {
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!((len - 1.0).abs() < 1e-6);
        // The centre of a side: the normal is that side's outward axis.
        let on_side_centre = p.iter().filter(|&&c| c == 0.5).count() == 2;
        if on_side_centre {
            let axis = p.iter().position(|&c| c != 0.5).unwrap();
            let sign = if p[axis] == 1.0 { 1.0 } else { -1.0 };
            assert!((n[axis] - sign).abs() < 1e-6, "normal {n:?} at {p:?}");
        }
        // A corner of the cube: every component points outward.
        if p.iter().all(|&c| c == 0.0 || c == 1.0) {
            for k in 0..3 {
                assert!(
                    n[k] * (p[k] - 0.5) > 0.0,
                    "corner normal {n:?} at {p:?} not outward"
                );
            }
        }
    }
}
