//! Binary legacy VTK grids, as VTK writes them (`SetFileTypeToBinary`: big-endian numbers of
//! each section's data type): a generated liver in the classic cell layout with double points
//! and in format 5's offsets and connectivity with single-precision points reads back as the
//! mesh written; a file cut short is refused with its byte.

use pgd_surgery_core::mesh::TetMesh;
use pgd_surgery_core::mesh::io::{ImportOptions, load};
use pgd_surgery_core::mesh::organs::{self, Organ, OrganSettings};

use super::import::{assert_cut_short, file};

fn liver() -> TetMesh {
    let settings = OrganSettings {
        resolution: 0.25,
        ..OrganSettings::default()
    };
    organs::generate(Organ::Liver, &settings).unwrap()
}

fn header(version: &str, points: usize, kind: &str) -> Vec<u8> {
    format!(
        "# vtk DataFile Version {version}\nliver\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS {points} {kind}\n"
    )
    .into_bytes()
}

/// The cell types' section: every cell a tetrahedron.
fn cell_types(bytes: &mut Vec<u8>, cells: usize) {
    bytes.extend(format!("\nCELL_TYPES {cells}\n").bytes());
    (0..cells).for_each(|_| bytes.extend(10i32.to_be_bytes()));
    bytes.push(b'\n');
}

/// Format 3: double points; `CELLS n size`, each cell its point count and points as `int`s.
pub fn classic(mesh: &TetMesh) -> Vec<u8> {
    let (nodes, tets) = (mesh.nodes(), mesh.tets());
    let mut bytes = header("3.0", nodes.len(), "double");
    for p in nodes {
        bytes.extend(p.coords.iter().flat_map(|c| c.to_be_bytes()));
    }
    bytes.extend(format!("\nCELLS {} {}\n", tets.len(), 5 * tets.len()).bytes());
    for tet in tets {
        bytes.extend(4i32.to_be_bytes());
        bytes.extend(tet.iter().flat_map(|&n| (n as i32).to_be_bytes()));
    }
    cell_types(&mut bytes, tets.len());
    bytes
}

/// Format 5.1: single-precision points; offsets and connectivity as 64-bit integers.
pub fn offsets(mesh: &TetMesh) -> Vec<u8> {
    let (nodes, tets) = (mesh.nodes(), mesh.tets());
    let mut bytes = header("5.1", nodes.len(), "float");
    for p in nodes {
        bytes.extend(p.coords.iter().flat_map(|&c| (c as f32).to_be_bytes()));
    }
    let cells = tets.len();
    bytes.extend(
        format!(
            "\nCELLS {} {}\nOFFSETS vtktypeint64\n",
            cells + 1,
            4 * cells
        )
        .bytes(),
    );
    (0..=cells).for_each(|k| bytes.extend((4 * k as i64).to_be_bytes()));
    bytes.extend(b"\nCONNECTIVITY vtktypeint64\n");
    for tet in tets {
        bytes.extend(tet.iter().flat_map(|&n| (n as i64).to_be_bytes()));
    }
    cell_types(&mut bytes, cells);
    bytes
}

#[test]
fn binary_legacy_vtk_reads_back_as_the_mesh_written() {
    let mesh = liver();
    let back = load(
        &file("classic.vtk", &classic(&mesh)),
        &ImportOptions::default(),
    )
    .unwrap();
    assert_eq!(back.nodes(), mesh.nodes());
    assert_eq!(back.tets(), mesh.tets());

    let back = load(
        &file("offsets.vtk", &offsets(&mesh)),
        &ImportOptions::default(),
    )
    .unwrap();
    let single: Vec<_> = (mesh.nodes().iter())
        .map(|p| p.map(|c| f64::from(c as f32)))
        .collect();
    assert_eq!(back.nodes(), &single[..]);
    assert_eq!(back.tets(), mesh.tets());
}

/// A binary file cut in its cells is refused with the file and the byte where the field cut
/// short starts, counted from the file's start.
#[test]
fn a_binary_vtk_file_cut_short_names_its_byte() {
    let bytes = classic(&liver());
    let cut = &bytes[..bytes.len() * 2 / 3];
    assert_cut_short("cut.vtk", cut, 4);
}
