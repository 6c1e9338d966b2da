//! Blocks of liver tissue, their full matrices, and reduced models over them.

use nalgebra::DMatrix;
use pgd_surgery_core::dynamics::{ModalBasis, ReducedKsv};
use pgd_surgery_core::fem::{Dirichlet, FemModel, Law, Material};
use pgd_surgery_core::mesh::box_mesh;
use pgd_surgery_core::pgd::{BuildSettings, OrganModel, PgdSettings, Silent, Vademecum, build};

/// The basis size of the tests in the vademecum's basis.
pub const KEEP: usize = 12;

/// A 6 × 4 × 3 cm block of `cells`, clamped underneath when `clamped`.
pub fn block(cells: [usize; 3], material: Material, clamped: bool) -> FemModel {
    let mesh = box_mesh([0.06, 0.04, 0.03], cells).unwrap();
    if !clamped {
        return FemModel::free_body(mesh, material).unwrap();
    }
    let mut dirichlet = Dirichlet::new(mesh.node_count());
    dirichlet.clamp(mesh.node_set("z0").unwrap()).unwrap();
    FemModel::new(mesh, material, dirichlet).unwrap()
}

pub fn liver_block(cells: [usize; 3], law: Law) -> FemModel {
    block(cells, Material::liver(law), true)
}

/// The identity over all dofs, column-major: the whole space as a subspace.
pub fn whole_space(model: &FemModel) -> Vec<f64> {
    let n = 3 * model.mesh().node_count();
    let mut columns = vec![0.0; n * n];
    for i in 0..n {
        columns[i * n + i] = 1.0;
    }
    columns
}

/// The `keep` lowest vibration modes of `model` as a basis, and its reduced model.
pub fn lowest_modes(model: &FemModel, keep: usize) -> (ModalBasis, ReducedKsv) {
    let basis = ModalBasis::ritz(model, &whole_space(model), keep).unwrap();
    let reduced = ReducedKsv::new(model, &basis).unwrap();
    (basis, reduced)
}

/// A sparse matrix over free dofs (values of the model's pattern) as a dense one.
pub fn dense(model: &FemModel, values: &[f64]) -> DMatrix<f64> {
    let n = model.dofs().free_count();
    let mut out = DMatrix::zeros(n, n);
    let mut e = vec![0.0; n];
    let mut column = vec![0.0; n];
    for j in 0..n {
        e[j] = 1.0;
        column.fill(0.0);
        model.pattern().mul(values, &e, &mut column);
        out.set_column(j, &nalgebra::DVector::from_column_slice(&column));
        e[j] = 0.0;
    }
    out
}

/// A reproducible pseudo-random vector in [-1, 1].
pub fn pseudo_random(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = fastrand::Rng::with_seed(seed);
    (0..n).map(|_| 2.0 * rng.f64() - 1.0).collect()
}

/// The block's linear vademecum, converged far enough that its spatial modes span the
/// response to any load of its top face.
pub fn block_vademecum(model: &FemModel) -> Vademecum {
    let organ = OrganModel {
        source: "block".into(),
        model,
        clamped_region: "z0".into(),
        accessible_region: "z1".into(),
    };
    let settings = BuildSettings {
        tool_tip_radius_m: 0.012,
        local_radius_m: 0.015,
        target_error: 1e-3,
        pgd: PgdSettings {
            max_modes: 40,
            ..PgdSettings::default()
        },
        ..BuildSettings::default()
    };
    build(&organ, &settings, &Silent).unwrap().0
}

/// The [`KEEP`] lowest modes found from [`block_vademecum`], and the reduced model in them.
pub fn vademecum_basis(model: &FemModel) -> (ModalBasis, ReducedKsv) {
    let vademecum = block_vademecum(model);
    let basis = ModalBasis::of_vademecum(model, &vademecum, KEEP).unwrap();
    let reduced = ReducedKsv::new(model, &basis).unwrap();
    (basis, reduced)
}
