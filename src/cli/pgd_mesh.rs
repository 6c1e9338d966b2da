//! `pgd mesh`: a mesh's statistics, regions and quality, and its `.vtu` for ParaView.

use std::path::Path;
use std::process::ExitCode;

use super::output::{fail, print_json};
use crate::mesh::io::write_vtu;
use crate::mesh::{QualityReport, TetMesh};

/// Prints a mesh's statistics, regions and quality, writes it if asked, and fails if the mesh
/// cannot be simulated.
pub fn report_mesh(source: &str, mesh: &TetMesh, out: Option<&Path>, json: bool) -> ExitCode {
    let report = QualityReport::measure(mesh.nodes(), mesh.tets());
    let regions = mesh.regions();
    if json {
        print_json(&serde_json::json!({
            "source": source,
            "quality": report,
            "usable": report.refusal().is_none(),
            "node_sets": regions.node_sets.iter().map(|(k, v)| (k.clone(), v.len())).collect::<std::collections::BTreeMap<_, _>>(),
            "face_sets": regions.face_sets.iter().map(|(k, v)| (k.clone(), v.len())).collect::<std::collections::BTreeMap<_, _>>(),
        }));
    } else {
        println!("{source}\n{report}");
        for (name, nodes) in &regions.node_sets {
            println!("  node set {name}: {} nodes", nodes.len());
        }
        for (name, faces) in &regions.face_sets {
            println!("  face set {name}: {} faces", faces.len());
        }
    }
    if let Some(path) = out {
        if let Err(e) = write_vtu(path, mesh, &[]) {
            return fail("pgd mesh", &format!("{}: {e}", path.display()));
        }
        if !json {
            println!("wrote {}", path.display());
        }
    }
    if report.refusal().is_some() {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}
