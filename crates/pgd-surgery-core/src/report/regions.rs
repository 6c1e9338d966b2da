//! A picture of an organ's regions: its surface seen from an oblique view, the clamped part in
//! red, the accessible surface in green, the rest grey, shaded by the light on each face; so
//! that whoever picks the regions of a patient's organ sees what the selectors picked.

use std::path::Path;

use nalgebra::{Rotation3, Vector3};
use plotters::prelude::*;

use super::plot::save_png;
use crate::mesh::organs::region;
use crate::mesh::{Surface, TetMesh, area_vector};

/// The view: turned 35° about the vertical and tipped 25° towards the viewer.
fn view() -> Rotation3<f64> {
    Rotation3::from_euler_angles(25f64.to_radians(), 0.0, 35f64.to_radians())
}

/// Draws `mesh`'s surface with its `clamped` and `accessible` regions into a 900 × 700 PNG at
/// `path`; errors name the file.
pub fn draw_regions(path: &Path, mesh: &TetMesh, title: &str) -> Result<(), String> {
    let surface = Surface::extract(mesh);
    let clamped: std::collections::HashSet<usize> = (mesh.node_set(region::CLAMPED))
        .map(|n| n.iter().copied().collect())
        .unwrap_or_default();
    let accessible: std::collections::HashSet<[usize; 3]> = (mesh.face_set(region::ACCESSIBLE))
        .map(|faces| faces.iter().map(|f| sorted(*f)).collect())
        .unwrap_or_default();
    let rotation = view();
    let seen: Vec<Vector3<f64>> = mesh.nodes().iter().map(|p| rotation * p.coords).collect();
    // Painter's order: the faces farthest from the viewer (largest y after the view) first.
    let mut order: Vec<usize> = (0..surface.triangles.len()).collect();
    let depth = |f: usize| surface.triangles[f].iter().map(|&n| seen[n].y).sum::<f64>();
    order.sort_by(|&a, &b| depth(b).total_cmp(&depth(a)));
    let (lo, hi) = seen.iter().fold(
        (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    );
    let light = Vector3::new(-0.3, -1.0, 0.6).normalize();
    let drawn = save_png(path, (900, 700), |root| {
        let root = root.titled(title, ("sans-serif", 22))?;
        let (width, height) = root.dim_in_pixel();
        let scale =
            ((width as f64 - 60.0) / (hi.x - lo.x)).min((height as f64 - 80.0) / (hi.z - lo.z));
        let pixel = |p: &Vector3<f64>| {
            (
                30 + ((p.x - lo.x) * scale) as i32,
                height as i32 - 50 - ((p.z - lo.z) * scale) as i32,
            )
        };
        for f in order {
            let face = surface.triangles[f];
            let normal = rotation * area_vector(mesh.nodes(), &face).normalize();
            let shade = 0.35 + 0.65 * normal.dot(&light).max(0.0);
            let (r, g, b) = match (
                face.iter().any(|n| clamped.contains(n)),
                accessible.contains(&sorted(face)),
            ) {
                (true, _) => (210.0, 50.0, 40.0),
                (false, true) => (60.0, 170.0, 80.0),
                (false, false) => (170.0, 170.0, 170.0),
            };
            let colour = RGBColor((r * shade) as u8, (g * shade) as u8, (b * shade) as u8);
            let corners: Vec<(i32, i32)> = face.iter().map(|&n| pixel(&seen[n])).collect();
            root.draw(&Polygon::new(corners, colour.filled()))?;
        }
        let legend = [
            ("clamped", RGBColor(210, 50, 40)),
            ("accessible", RGBColor(60, 170, 80)),
            ("other surface", RGBColor(170, 170, 170)),
        ];
        for (k, (name, colour)) in legend.into_iter().enumerate() {
            let y = 10 + 24 * k as i32;
            root.draw(&Rectangle::new([(12, y), (28, y + 16)], colour.filled()))?;
            root.draw(&Text::new(name, (36, y), ("sans-serif", 18)))?;
        }
        Ok(())
    });
    drawn.map_err(|e| format!("{}: {e}", path.display()))
}

fn sorted(mut face: [usize; 3]) -> [usize; 3] {
    face.sort_unstable();
    face
}
