//! Binary Gmsh files, as Gmsh writes them with `Mesh.Binary = 1`: a generated liver written
//! in versions 4.1 and 2.2 reads back as the same mesh (nodes, tetrahedra, the accessible
//! surface as a physical group), bit for bit; a file cut short is refused with its byte.

use pgd_surgery_core::mesh::TetMesh;
use pgd_surgery_core::mesh::io::{ImportOptions, load};
use pgd_surgery_core::mesh::organs::{self, Organ, OrganSettings};

use super::import::{assert_cut_short, file, sorted_faces};

/// The physical group the accessible surface is written as.
const GROUP: i32 = 7;

/// Bytes written as Gmsh writes them on a little-endian machine.
#[derive(Default)]
struct Bytes(Vec<u8>);

impl Bytes {
    fn text(&mut self, text: &str) -> &mut Self {
        self.0.extend_from_slice(text.as_bytes());
        self
    }

    fn int(&mut self, value: i32) -> &mut Self {
        self.0.extend_from_slice(&value.to_le_bytes());
        self
    }

    fn size(&mut self, value: usize) -> &mut Self {
        self.0.extend_from_slice(&(value as u64).to_le_bytes());
        self
    }

    fn real(&mut self, value: f64) -> &mut Self {
        self.0.extend_from_slice(&value.to_le_bytes());
        self
    }

    /// The format's header for `version`, binary, and the physical group's name.
    fn header(&mut self, version: &str, group: &str) -> &mut Self {
        self.text(&format!("$MeshFormat\n{version} 1 8\n"))
            .int(1)
            .text("\n$EndMeshFormat\n$PhysicalNames\n1\n")
            .text(&format!("2 {GROUP} \"{group}\"\n$EndPhysicalNames\n"))
    }
}

fn liver() -> TetMesh {
    let settings = OrganSettings {
        resolution: 0.25,
        ..OrganSettings::default()
    };
    organs::generate(Organ::Liver, &settings).unwrap()
}

/// Version 4.1: one surface entity in the physical group of `mesh`'s face set `group`, one
/// volume; nodes and elements in blocks, tags as `size_t`.
pub fn msh4(mesh: &TetMesh, group: &str) -> Vec<u8> {
    let faces = mesh.face_set(group).unwrap();
    let (nodes, tets) = (mesh.nodes(), mesh.tets());
    let mut b = Bytes::default();
    b.header("4.1", group).text("$Entities\n");
    b.size(0).size(0).size(1).size(1);
    b.int(1);
    (0..6).for_each(|_| {
        b.real(0.0);
    });
    b.size(1).int(GROUP).size(0);
    b.int(1);
    (0..6).for_each(|_| {
        b.real(0.0);
    });
    b.size(0).size(0);
    b.text("\n$EndEntities\n$Nodes\n");
    b.size(1).size(nodes.len()).size(1).size(nodes.len());
    b.int(3).int(1).int(0).size(nodes.len());
    (1..=nodes.len()).for_each(|tag| {
        b.size(tag);
    });
    for p in nodes {
        b.real(p.x).real(p.y).real(p.z);
    }
    b.text("\n$EndNodes\n$Elements\n");
    let total = faces.len() + tets.len();
    b.size(2).size(total).size(1).size(total);
    b.int(2).int(1).int(2).size(faces.len());
    let mut tag = 0;
    for face in faces {
        tag += 1;
        b.size(tag);
        face.iter().for_each(|&n| {
            b.size(n + 1);
        });
    }
    b.int(3).int(1).int(4).size(tets.len());
    for tet in tets {
        tag += 1;
        b.size(tag);
        tet.iter().for_each(|&n| {
            b.size(n + 1);
        });
    }
    b.text("\n$EndElements\n");
    b.0
}

/// Version 2.2: nodes as `int` tag and three doubles; elements in blocks of one type, each
/// with its number, two tags (physical, elementary) and its nodes as `int`s.
pub fn msh2(mesh: &TetMesh, group: &str) -> Vec<u8> {
    let faces = mesh.face_set(group).unwrap();
    let (nodes, tets) = (mesh.nodes(), mesh.tets());
    let mut b = Bytes::default();
    b.header("2.2", group)
        .text(&format!("$Nodes\n{}\n", nodes.len()));
    for (k, p) in nodes.iter().enumerate() {
        b.int(k as i32 + 1).real(p.x).real(p.y).real(p.z);
    }
    b.text(&format!(
        "\n$EndNodes\n$Elements\n{}\n",
        faces.len() + tets.len()
    ));
    b.int(2).int(faces.len() as i32).int(2);
    for (k, face) in faces.iter().enumerate() {
        b.int(k as i32 + 1).int(GROUP).int(1);
        face.iter().for_each(|&n| {
            b.int(n as i32 + 1);
        });
    }
    b.int(4).int(tets.len() as i32).int(2);
    for (k, tet) in tets.iter().enumerate() {
        b.int((faces.len() + k) as i32 + 1).int(0).int(1);
        tet.iter().for_each(|&n| {
            b.int(n as i32 + 1);
        });
    }
    b.text("\n$EndElements\n");
    b.0
}

#[test]
fn binary_gmsh_v4_and_v2_read_back_as_the_mesh_written() {
    let mesh = liver();
    let group = "accessible";
    for (name, bytes) in [
        ("liver4.msh", msh4(&mesh, group)),
        ("liver2.msh", msh2(&mesh, group)),
    ] {
        let back = load(&file(name, &bytes), &ImportOptions::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(back.nodes(), mesh.nodes(), "{name}");
        assert_eq!(back.tets(), mesh.tets(), "{name}");
        assert_eq!(
            sorted_faces(back.face_set("accessible").unwrap()),
            sorted_faces(mesh.face_set("accessible").unwrap()),
            "{name}"
        );
    }
}

/// A binary file cut in its nodes is refused with the file, the byte where the field cut
/// short starts (within the 8 bytes before the end) and what was expected.
#[test]
fn a_binary_gmsh_file_cut_short_names_its_byte() {
    let bytes = msh4(&liver(), "accessible");
    let cut = &bytes[..bytes.len() / 3];
    assert_cut_short("cut.msh", cut, 8);
}
