//! A tetrahedron split by a plane into tetrahedra on either side, so that a function constant
//! on each side (a Heaviside enrichment) is integrated exactly over the element: the shape
//! functions' gradients of a linear tetrahedron are constant, so an enriched stiffness needs
//! only the volume on each side.

use nalgebra::Point3;

pub type Tet = [Point3<f64>; 4];

/// The pieces of `tet` on the positive and the negative side of the plane whose signed
/// distances at the four corners are `phi` (corners within the snapping tolerance already set
/// to exactly zero). A side the tetrahedron does not reach is empty.
pub fn split(tet: &Tet, phi: [f64; 4]) -> (Vec<Tet>, Vec<Tet>) {
    if phi.iter().all(|&d| d >= 0.0) {
        return (vec![*tet], vec![]);
    }
    if phi.iter().all(|&d| d <= 0.0) {
        return (vec![], vec![*tet]);
    }
    let positive = |d: f64| d > 0.0;
    let count = |f: &dyn Fn(f64) -> bool| phi.iter().filter(|&&d| f(d)).count();
    let (p, n) = (count(&positive), count(&|d| d < 0.0));
    // Work with the side holding fewer corners strictly on it as the "lone" side.
    if p <= n {
        split_lone(tet, phi)
    } else {
        let (minus, plus) = split_lone(tet, phi.map(|d| -d));
        (plus, minus)
    }
}

/// `phi` has at most as many positive corners as negative ones, and at least one of each.
fn split_lone(tet: &Tet, phi: [f64; 4]) -> (Vec<Tet>, Vec<Tet>) {
    let on = |side: fn(f64) -> bool| -> Vec<usize> { (0..4).filter(|&i| side(phi[i])).collect() };
    let pos = on(|d| d > 0.0);
    let neg = on(|d| d < 0.0);
    let zero = on(|d| d == 0.0);
    let cut = |a: usize, b: usize| {
        let t = phi[a] / (phi[a] - phi[b]);
        tet[a] + (tet[b] - tet[a]) * t
    };
    let p = |i: usize| tet[i];
    match (pos.len(), neg.len(), zero.len()) {
        (1, 3, 0) => {
            let x = neg.iter().map(|&b| cut(pos[0], b)).collect::<Vec<_>>();
            let plus = vec![[p(pos[0]), x[0], x[1], x[2]]];
            let minus = prism([p(neg[0]), p(neg[1]), p(neg[2])], [x[0], x[1], x[2]]);
            (plus, minus)
        }
        (2, 2, 0) => {
            let x = |a: usize, b: usize| cut(pos[a], neg[b]);
            let plus = prism([p(pos[0]), x(0, 0), x(0, 1)], [p(pos[1]), x(1, 0), x(1, 1)]);
            let minus = prism([p(neg[0]), x(0, 0), x(1, 0)], [p(neg[1]), x(0, 1), x(1, 1)]);
            (plus, minus)
        }
        (1, 2, 1) => {
            let (a, z) = (pos[0], zero[0]);
            let (x0, x1) = (cut(a, neg[0]), cut(a, neg[1]));
            let plus = vec![[p(a), p(z), x0, x1]];
            // The pyramid with base (n0, n1, x1, x0) and apex z.
            let minus = vec![[p(z), p(neg[0]), p(neg[1]), x1], [p(z), p(neg[0]), x1, x0]];
            (plus, minus)
        }
        (1, 1, 2) => {
            let x = cut(pos[0], neg[0]);
            let (z0, z1) = (p(zero[0]), p(zero[1]));
            (vec![[p(pos[0]), z0, z1, x]], vec![[p(neg[0]), z0, z1, x]])
        }
        _ => unreachable!("a tetrahedron with corners on both sides: {phi:?}"),
    }
}

/// The three tetrahedra of the prism between triangles `a` and `b` (edges `a_i b_i`).
fn prism(a: [Point3<f64>; 3], b: [Point3<f64>; 3]) -> Vec<Tet> {
    vec![
        [a[0], a[1], a[2], b[0]],
        [a[1], a[2], b[0], b[1]],
        [a[2], b[0], b[1], b[2]],
    ]
}

/// The volume of a tetrahedron, whatever its orientation (m³).
pub fn volume(tet: &Tet) -> f64 {
    let [a, b, c, d] = tet;
    ((b - a).cross(&(c - a)).dot(&(d - a)) / 6.0).abs()
}

pub fn centroid(tet: &Tet) -> Point3<f64> {
    Point3::from((tet[0].coords + tet[1].coords + tet[2].coords + tet[3].coords) / 4.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit() -> Tet {
        [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
            Point3::new(0.0, 0.0, 1.0),
        ]
    }

    fn total(tets: &[Tet]) -> f64 {
        tets.iter().map(volume).sum()
    }

    /// Every way a plane can cut the unit tetrahedron: the pieces fill it, each on its side,
    /// and the side of a lone corner, `x > 0.7`, is the small tetrahedron `0.3³/6` (exact).
    #[test]
    fn the_pieces_fill_the_tetrahedron_each_on_its_side() {
        let tet = unit();
        let planes: [(nalgebra::Vector3<f64>, f64); 6] = [
            (nalgebra::Vector3::new(1.0, 0.0, 0.0), 0.3),
            (nalgebra::Vector3::new(-1.0, 0.0, 0.0), -0.3),
            (nalgebra::Vector3::new(1.0, 1.0, 0.0), 0.5),
            (nalgebra::Vector3::new(1.0, -1.0, 0.2), 0.0),
            (nalgebra::Vector3::new(0.0, 1.0, -1.0), 0.0),
            (nalgebra::Vector3::new(1.0, 1.0, 1.0), 0.9),
        ];
        for (normal, offset) in planes {
            let phi = tet.map(|p| normal.dot(&p.coords) - offset);
            let (plus, minus) = split(&tet, phi);
            assert!((total(&plus) + total(&minus) - 1.0 / 6.0).abs() < 1e-15);
            for piece in &plus {
                assert!(
                    normal.dot(&centroid(piece).coords) - offset > 0.0,
                    "{phi:?}"
                );
            }
            for piece in &minus {
                assert!(
                    normal.dot(&centroid(piece).coords) - offset < 0.0,
                    "{phi:?}"
                );
            }
        }
        let (small, _) = split(&tet, tet.map(|p| p.x - 0.7));
        assert!((total(&small) - 0.3f64.powi(3) / 6.0).abs() < 1e-15);
    }
}
