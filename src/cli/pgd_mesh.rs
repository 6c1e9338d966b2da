//! `pgd mesh`: a mesh's statistics, regions and quality, and its `.vtu` for ParaView.

use std::path::Path;
use std::process::ExitCode;

use super::LoadedMesh;
use super::output::{fail, print_json};
use crate::mesh::QualityReport;
use crate::mesh::io::write_vtu;
use crate::report::draw_regions;

/// What `pgd mesh` is asked.
pub struct MeshReport<'a> {
    pub source: &'a str,
    pub loaded: &'a LoadedMesh,
    /// Where to write the mesh as `.vtu`.
    pub out: Option<&'a Path>,
    /// Where to draw the organ with its regions.
    pub preview: Option<&'a Path>,
    pub json: bool,
}

/// Prints a mesh's statistics, regions and quality (and what each region selector picked),
/// writes it and its picture if asked, and fails if the mesh cannot be simulated.
pub fn report_mesh(request: &MeshReport) -> ExitCode {
    let (source, mesh, json) = (request.source, &request.loaded.mesh, request.json);
    let out = request.out;
    let report = QualityReport::measure(mesh.nodes(), mesh.tets());
    let regions = mesh.regions();
    if json {
        print_json(&serde_json::json!({
            "source": source,
            "quality": report,
            "usable": report.refusal().is_none(),
            "node_sets": regions.node_sets.iter().map(|(k, v)| (k.clone(), v.len())).collect::<std::collections::BTreeMap<_, _>>(),
            "face_sets": regions.face_sets.iter().map(|(k, v)| (k.clone(), v.len())).collect::<std::collections::BTreeMap<_, _>>(),
            "selection": request.loaded.selection,
        }));
    } else {
        println!("{source}\n{report}");
        for (name, nodes) in &regions.node_sets {
            println!("  node set {name}: {} nodes", nodes.len());
        }
        for (name, faces) in &regions.face_sets {
            println!("  face set {name}: {} faces", faces.len());
        }
        if let Some(selection) = &request.loaded.selection {
            print!("picked by the selectors:\n{selection}");
        }
    }
    if let Some(path) = request.preview {
        if let Err(e) = draw_regions(path, mesh, source) {
            return fail("pgd mesh", &e);
        }
        if !json {
            println!("drew {}", path.display());
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
