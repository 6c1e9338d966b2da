//! A 6 × 4 × 3 cm block of liver tissue clamped underneath, loadable on its top face; and a
//! folder for a test's files.

use pgd_surgery_core::fem::{Dirichlet, FemModel, Law, Material};
use pgd_surgery_core::mesh::{TetMesh, box_mesh};
use pgd_surgery_core::pgd::{BuildSettings, OrganModel, PgdSettings, Silent, Vademecum, build};

pub fn block_mesh(cells: [usize; 3]) -> TetMesh {
    box_mesh([0.06, 0.04, 0.03], cells).unwrap()
}

pub fn block_model(mesh: TetMesh) -> FemModel {
    block_model_of(mesh, Law::Linear)
}

pub fn block_model_of(mesh: TetMesh, law: Law) -> FemModel {
    let mut dirichlet = Dirichlet::new(mesh.node_count());
    dirichlet.clamp(mesh.node_set("z0").unwrap()).unwrap();
    FemModel::new(mesh, Material::liver(law), dirichlet).unwrap()
}

pub fn organ(model: &FemModel) -> OrganModel<'_> {
    OrganModel {
        source: "block".into(),
        model,
        clamped_region: "z0".into(),
        accessible_region: "z1".into(),
    }
}

/// Settings for the block: a tool patch wider than its 1 cm elements.
pub fn settings(max_modes: usize, target_error: f64) -> BuildSettings {
    BuildSettings {
        tool_tip_radius_m: 0.012,
        local_radius_m: 0.015,
        target_error,
        pgd: PgdSettings {
            max_modes,
            ..PgdSettings::default()
        },
        ..BuildSettings::default()
    }
}

pub fn build_block(model: &FemModel, max_modes: usize) -> Vademecum {
    build(&organ(model), &settings(max_modes, 1e-9), &Silent)
        .unwrap()
        .0
}

/// A folder of its own for the files of the test `name`, in the system's temporary folder.
pub fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("pgd-outputs-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}
