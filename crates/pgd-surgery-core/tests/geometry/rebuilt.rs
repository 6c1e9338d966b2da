//! A generated organ written out as Gmsh 1 (ASCII), Gmsh 4.1 (binary) and binary legacy VTK,
//! read back, builds the vademecum the organ itself builds, bit for bit: the files carry every
//! node and tetrahedron exactly, and the build is deterministic. (Its regions are the
//! organ's, given again: VTK names none.)

use pgd_surgery_core::fem::{Law, Material};
use pgd_surgery_core::mesh::TetMesh;
use pgd_surgery_core::mesh::io::{ImportOptions, load};
use pgd_surgery_core::mesh::organs::{self, Organ, OrganSettings, region};
use pgd_surgery_core::pgd::{BuildSettings, OrganModel, Silent, build, encode, organ};

use super::import::file;
use super::msh_binary::msh4;
use super::vtk_binary::classic;

/// Gmsh's version 1: nodes and tetrahedra as text, every coordinate as it reads back exactly.
fn msh1(mesh: &TetMesh) -> Vec<u8> {
    let mut text = format!("$NOD\n{}\n", mesh.node_count());
    for (k, p) in mesh.nodes().iter().enumerate() {
        text.push_str(&format!("{} {} {} {}\n", k + 1, p.x, p.y, p.z));
    }
    text.push_str(&format!("$ENDNOD\n$ELM\n{}\n", mesh.tet_count()));
    for (k, tet) in mesh.tets().iter().enumerate() {
        let [a, b, c, d] = tet.map(|n| n + 1);
        text.push_str(&format!("{} 4 0 1 4 {a} {b} {c} {d}\n", k + 1));
    }
    text.push_str("$ENDELM\n");
    text.into_bytes()
}

/// The linear vademecum of `mesh` clamped and loaded on `regions`, as its file's bytes less
/// the build's time.
fn vademecum_bytes(mesh: TetMesh) -> Vec<u8> {
    let model = organ::clamped_model(mesh, Material::liver(Law::Linear)).unwrap();
    let organ = OrganModel {
        source: "liver".into(),
        model: &model,
        clamped_region: region::CLAMPED.into(),
        accessible_region: region::ACCESSIBLE.into(),
    };
    let settings = BuildSettings::for_organ(Some(Organ::Liver));
    let (mut vademecum, _) = build(&organ, &settings, &Silent).unwrap();
    vademecum.header.build_seconds = 0.0;
    encode(&vademecum)
}

#[test]
fn an_organ_written_out_and_read_back_builds_the_same_vademecum() {
    let settings = OrganSettings {
        resolution: 0.25,
        ..OrganSettings::default()
    };
    let liver = organs::generate(Organ::Liver, &settings).unwrap();
    let reference = vademecum_bytes(liver.clone());
    for (name, bytes) in [
        ("rebuilt1.msh", msh1(&liver)),
        ("rebuilt4.msh", msh4(&liver, region::ACCESSIBLE)),
        ("rebuilt.vtk", classic(&liver)),
    ] {
        let back = load(&file(name, &bytes), &ImportOptions::default()).unwrap();
        let regions = liver.regions().clone();
        let mesh = TetMesh::new(
            "liver",
            back.nodes().to_vec(),
            back.tets().to_vec(),
            regions,
        );
        assert!(
            vademecum_bytes(mesh.unwrap()) == reference,
            "{name}: its vademecum differs from the organ's"
        );
    }
}
