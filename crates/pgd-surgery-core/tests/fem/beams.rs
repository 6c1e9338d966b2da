//! A slender cantilever: the reference problem for bending, shared by several tests.

use pgd_surgery_core::fem::{
    Dirichlet, FemModel, Law, Loads, Material, NewtonSettings, StaticSolution,
};
use pgd_surgery_core::mesh::box_mesh;

/// Beam length, and the side of its square cross-section (m): slenderness 10.
pub const LENGTH_M: f64 = 0.1;
pub const SIDE_M: f64 = 0.01;
pub const YOUNG_PA: f64 = 1.0e5;

pub struct Cantilever {
    pub model: FemModel,
    pub loads: Loads,
    pub tip_nodes: Vec<usize>,
}

/// A beam along x, clamped at x = 0, with a downward (−z) tip force spread as a uniform
/// traction over the end face x = L. `cells_across` cubes over the side, `10 ×` that along.
pub fn cantilever(cells_across: usize, law: Law, poisson: f64, tip_force_n: f64) -> Cantilever {
    let mesh = box_mesh(
        [LENGTH_M, SIDE_M, SIDE_M],
        [10 * cells_across, cells_across, cells_across],
    )
    .unwrap();
    let mut dirichlet = Dirichlet::new(mesh.node_count());
    dirichlet.clamp(mesh.node_set("x0").unwrap()).unwrap();
    let mut loads = Loads::new(mesh.node_count());
    let traction = -tip_force_n / (SIDE_M * SIDE_M);
    loads
        .add_traction(&mesh, mesh.face_set("x1").unwrap(), [0.0, 0.0, traction])
        .unwrap();
    let tip_nodes = mesh.node_set("x1").unwrap().to_vec();
    let material = Material::new(law, YOUNG_PA, poisson, 1000.0).unwrap();
    let model = FemModel::new(mesh, material, dirichlet).unwrap();
    Cantilever {
        model,
        loads,
        tip_nodes,
    }
}

impl Cantilever {
    pub fn solve(&self, settings: &NewtonSettings) -> StaticSolution {
        self.model.solve_static(&self.loads, settings).unwrap()
    }

    /// Mean downward deflection of the end face (m).
    pub fn tip_deflection_m(&self, solution: &StaticSolution) -> f64 {
        let sum: f64 = self.tip_nodes.iter().map(|&n| -solution.node(n)[2]).sum();
        sum / self.tip_nodes.len() as f64
    }
}

/// Tip deflection of a clamped beam of square section under a tip force: Euler–Bernoulli
/// bending `PL³/3EI` plus Timoshenko shear `PL/κGA` (0.8 % of the total at this slenderness).
pub fn beam_theory_deflection_m(tip_force_n: f64, poisson: f64) -> f64 {
    let inertia = SIDE_M.powi(4) / 12.0;
    let area = SIDE_M * SIDE_M;
    let shear_modulus = YOUNG_PA / (2.0 * (1.0 + poisson));
    let kappa = 10.0 * (1.0 + poisson) / (12.0 + 11.0 * poisson);
    tip_force_n * LENGTH_M.powi(3) / (3.0 * YOUNG_PA * inertia)
        + tip_force_n * LENGTH_M / (kappa * shear_modulus * area)
}
