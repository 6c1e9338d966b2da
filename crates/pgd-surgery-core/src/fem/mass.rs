//! Mass matrices of linear tetrahedra with uniform density.

use nalgebra::Matrix3;

use super::element::{ElementMatrix, TetGeometry};
use super::pattern::FreePattern;

/// Lumped (row-sum) mass per node in kg: a quarter of each adjacent tetrahedron's mass.
pub fn lumped_mass(
    tets: &[[usize; 4]],
    geometry: &[TetGeometry],
    node_count: usize,
    density_kg_m3: f64,
) -> Vec<f64> {
    let mut mass = vec![0.0; node_count];
    for (tet, geo) in tets.iter().zip(geometry) {
        let quarter = density_kg_m3 * geo.volume_m3 / 4.0;
        for &n in tet {
            mass[n] += quarter;
        }
    }
    mass
}

/// Consistent mass `M_ab = ρV/20 (1 + δ_ab) I` assembled over free dofs, as values of `pattern`.
pub fn consistent_mass(
    pattern: &FreePattern,
    geometry: &[TetGeometry],
    density_kg_m3: f64,
) -> Vec<f64> {
    let mut values = pattern.zero_values();
    for (t, geo) in geometry.iter().enumerate() {
        let m = density_kg_m3 * geo.volume_m3 / 20.0;
        let mut element = ElementMatrix::zeros();
        for a in 0..4 {
            for b in 0..4 {
                let factor = if a == b { 2.0 * m } else { m };
                element
                    .fixed_view_mut::<3, 3>(3 * a, 3 * b)
                    .copy_from(&(Matrix3::identity() * factor));
            }
        }
        pattern.scatter(t, &element, &mut values);
    }
    values
}
