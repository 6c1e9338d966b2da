//! The trainer's built-in default until the vademecum-driven scene lands: a slab of liver
//! tissue clamped underneath and pressed from above by a probe, solved once with full
//! Kirchhoff–Saint Venant FEM.

use bevy::prelude::Resource;
use nalgebra::Point3;

use crate::fem::{Dirichlet, FemError, FemModel, Law, Loads, Material, NewtonSettings};
use crate::mesh::{Surface, box_mesh};

/// Slab extent (m): x wide, y thick (up), z deep.
const SIZE_M: [f64; 3] = [0.18, 0.06, 0.10];
const CELLS: [usize; 3] = [18, 6, 10];
/// The probe's push (N, downward) and the radius of tissue it loads (m).
const PRESS_FORCE_N: f64 = 0.15;
const PROBE_RADIUS_M: f64 = 0.012;

/// The solved scene, in render-ready single precision, centred on the origin.
#[derive(Resource, Clone, Debug)]
pub struct PressedSlab {
    /// Surface triangles in surface-vertex numbering.
    pub triangles: Vec<[usize; 3]>,
    pub rest_positions: Vec<[f32; 3]>,
    pub deformed_positions: Vec<[f32; 3]>,
    /// Where the probe touches the deformed surface.
    pub probe_tip: [f32; 3],
    pub press_force_n: f64,
    pub max_displacement_m: f64,
    pub newton_iterations: usize,
    pub nodes: usize,
    pub tets: usize,
}

impl PressedSlab {
    pub fn solve() -> Result<Self, FemError> {
        let mesh = box_mesh(SIZE_M, CELLS)?;
        let surface = Surface::extract(&mesh);
        let mut dirichlet = Dirichlet::new(mesh.node_count());
        dirichlet.clamp(mesh.node_set("y0")?)?;
        let top_centre = Point3::new(SIZE_M[0] / 2.0, SIZE_M[1], SIZE_M[2] / 2.0);
        let mut loads = Loads::new(mesh.node_count());
        loads.add_point_load(
            &mesh,
            &surface,
            top_centre,
            [0.0, -PRESS_FORCE_N, 0.0],
            PROBE_RADIUS_M,
        )?;
        let model = FemModel::new(mesh, Material::liver(Law::KirchhoffSaintVenant), dirichlet)?;
        let settings = NewtonSettings {
            load_steps: 4,
            ..NewtonSettings::default()
        };
        let solution = model.solve_static(&loads, &settings)?;

        let centre = Point3::from(SIZE_M.map(|s| s / 2.0));
        let place = |p: Point3<f64>| (p - centre).map(|c| c as f32).into();
        let nodes = model.mesh().nodes();
        let deformed = |n: usize| nodes[n] + nalgebra::Vector3::from(solution.node(n));
        let top = nodes
            .iter()
            .enumerate()
            .min_by(|(_, a), (_, b)| {
                (*a - top_centre)
                    .norm()
                    .total_cmp(&(*b - top_centre).norm())
            })
            .map_or(0, |(n, _)| n);
        Ok(Self {
            triangles: surface.local_triangles(),
            rest_positions: surface.nodes.iter().map(|&n| place(nodes[n])).collect(),
            deformed_positions: surface.nodes.iter().map(|&n| place(deformed(n))).collect(),
            probe_tip: place(deformed(top)),
            press_force_n: PRESS_FORCE_N,
            max_displacement_m: (0..nodes.len())
                .map(|n| nalgebra::Vector3::from(solution.node(n)).norm())
                .fold(0.0, f64::max),
            newton_iterations: solution.steps.iter().map(|s| s.step_lengths.len()).sum(),
            nodes: model.mesh().node_count(),
            tets: model.mesh().tet_count(),
        })
    }

    /// One line for the console and the on-screen HUD.
    pub fn summary(&self) -> String {
        format!(
            "liver-tissue slab ({} nodes, {} tets, KSV, E = 1.6 kPa, Poisson ratio 0.48) pressed with {:.2} N: \
             max displacement {:.1} mm after {} Newton iterations",
            self.nodes,
            self.tets,
            self.press_force_n,
            self.max_displacement_m * 1e3,
            self.newton_iterations
        )
    }
}
