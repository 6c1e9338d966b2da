//! Import of small hand-written files in each format, export round trip, and the errors that
//! malformed files must produce (with file and line).

use std::path::PathBuf;

use pgd_surgery_core::mesh::io::{ImportError, ImportOptions, load, write_vtu};
use pgd_surgery_core::mesh::organs::{self, Organ, OrganSettings};
use pgd_surgery_core::mesh::{MeshDensity, QualityReport, box_mesh};

/// Writes `contents` to a fresh file with this name in a per-test directory.
pub fn file(name: &str, contents: &[u8]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "pgd-import-{}-{}",
        std::process::id(),
        name.replace('.', "-")
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, contents).unwrap();
    path
}

/// `faces`, each with its corners in order, in order: a face set to compare with another.
pub fn sorted_faces(faces: &[[usize; 3]]) -> Vec<[usize; 3]> {
    let mut faces: Vec<[usize; 3]> = faces
        .iter()
        .map(|f| {
            let mut f = *f;
            f.sort_unstable();
            f
        })
        .collect();
    faces.sort_unstable();
    faces
}

/// `cut`, a binary file cut short, written as `name` and read: refused with the file, the
/// byte where the field cut short starts (within `field_bytes` of the end) and what was
/// expected.
pub fn assert_cut_short(name: &str, cut: &[u8], field_bytes: usize) {
    let error = load(&file(name, cut), &ImportOptions::default()).unwrap_err();
    let ImportError::Binary {
        file,
        byte,
        message,
    } = &error
    else {
        panic!("{error}");
    };
    assert!(file.ends_with(name), "{error}");
    assert!(
        cut.len() - field_bytes < *byte && *byte <= cut.len(),
        "{error}"
    );
    assert!(message.contains("unexpected end of file"), "{error}");
}

fn import(name: &str, contents: &str) -> Result<pgd_surgery_core::mesh::TetMesh, ImportError> {
    load(&file(name, contents.as_bytes()), &ImportOptions::default())
}

/// Two tetrahedra sharing the face (1, 0, 0), (0, 1, 0), (0, 0, 1); the face z = 0 is the
/// physical surface "clamped".
pub const MSH2: &str = r#"$MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
1
2 7 "clamped"
$EndPhysicalNames
$Nodes
5
1 0 0 0
2 1 0 0
3 0 1 0
4 0 0 1
5 1 1 1
$EndNodes
$Elements
3
1 2 2 7 1 1 3 2
2 4 2 0 1 1 2 3 4
3 4 2 0 1 2 3 4 5
$EndElements
"#;

pub const MSH4: &str = r#"$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
1
2 7 "clamped"
$EndPhysicalNames
$Entities
0 0 1 1
1 0 0 0 1 1 0 1 7 0
1 0 0 0 1 1 1 0 1 1
$EndEntities
$Nodes
1 5 1 5
3 1 0 5
1
2
3
4
5
0 0 0
1 0 0
0 1 0
0 0 1
1 1 1
$EndNodes
$Elements
2 3 1 3
2 1 2 1
1 1 3 2
3 1 4 2
2 1 2 3 4
3 2 3 4 5
$EndElements
"#;

fn check_two_tets(mesh: &pgd_surgery_core::mesh::TetMesh) {
    assert_eq!((mesh.node_count(), mesh.tet_count()), (5, 2));
    assert!((mesh.volume() - (1.0 / 6.0 + 2.0 / 6.0)).abs() < 1e-12);
}

/// The two tetrahedra in Gmsh's version 1, which names no physical group: the triangle of
/// group 7 is the face set `physical_7`, which a selector (`region:physical_7`) can name.
pub const MSH1: &str = "$NOD\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n$ENDNOD\n\
    $ELM\n3\n1 2 7 1 3 1 3 2\n2 4 0 1 4 1 2 3 4\n3 4 0 1 4 2 3 4 5\n$ENDELM\n";

#[test]
fn gmsh_v1_reads_with_numbered_physical_surfaces() {
    let mesh = import("one.msh", MSH1).unwrap();
    check_two_tets(&mesh);
    assert_eq!(mesh.face_set("physical_7").unwrap().len(), 1);
    let wrong = MSH1.replace("1 2 7 1 3 1 3 2", "1 2 7 1 4 1 3 2 4");
    let error = import("wrong.msh", &wrong).unwrap_err().to_string();
    assert!(
        error.contains("wrong.msh:") && error.contains("type 2 with 4 nodes"),
        "{error}"
    );
}

#[test]
fn gmsh_v2_and_v4_read_with_physical_surfaces() {
    for (name, text) in [("two.msh", MSH2), ("two4.msh", MSH4)] {
        let mesh = import(name, text).unwrap_or_else(|e| panic!("{name}: {e}"));
        check_two_tets(&mesh);
        assert_eq!(mesh.face_set("clamped").unwrap().len(), 1, "{name}");
        let mut clamped = mesh.node_set("clamped").unwrap().to_vec();
        clamped.sort();
        assert_eq!(clamped, vec![0, 1, 2], "{name}");
    }
}

/// The two tetrahedra in legacy VTK's classic cell layout, and in version 5's offsets and
/// connectivity.
pub const VTK_CLASSIC: &str = "# vtk DataFile Version 3.0\ntwo tets\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 5 double\n0 0 0 1 0 0 0 1 0\n0 0 1 1 1 1\nCELLS 2 10\n4 0 1 2 3\n4 1 2 3 4\nCELL_TYPES 2\n10\n10\n";
pub const VTK_V5: &str = "# vtk DataFile Version 5.1\ntwo tets\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 5 double\n0 0 0 1 0 0 0 1 0\n0 0 1 1 1 1\nCELLS 3 8\nOFFSETS vtktypeint64\n0 4 8\nCONNECTIVITY vtktypeint64\n0 1 2 3 1 2 3 4\nCELL_TYPES 2\n10\n10\n";

#[test]
fn vtk_legacy_reads_both_cell_layouts() {
    check_two_tets(&import("classic.vtk", VTK_CLASSIC).unwrap());
    check_two_tets(&import("v5.vtk", VTK_V5).unwrap());
}

#[test]
fn vtu_round_trip_keeps_geometry_and_node_sets() {
    let mesh = box_mesh([0.04, 0.03, 0.02], [4, 3, 2]).unwrap();
    let path = file("box.vtu", b"");
    let displacement = vec![1e-3; 3 * mesh.node_count()];
    write_vtu(&path, &mesh, &[("displacement_m", &displacement)]).unwrap();
    let back = load(&path, &ImportOptions::default()).unwrap();
    assert_eq!(back.tets(), mesh.tets());
    for (a, b) in back.nodes().iter().zip(mesh.nodes()) {
        assert!((a - b).norm() < 1e-15);
    }
    assert_eq!(back.node_set("x0").unwrap(), mesh.node_set("x0").unwrap());
}

/// A face set (the generated liver's `accessible` surface) travels through .vtu as its nodes
/// and reads back as the same faces: the boundary triangles whose corners all lie in it.
#[test]
fn vtu_round_trip_keeps_face_sets() {
    let settings = OrganSettings {
        resolution: 0.25,
        ..OrganSettings::default()
    };
    let mesh = organs::generate(Organ::Liver, &settings).unwrap();
    let path = file("liver.vtu", b"");
    write_vtu(&path, &mesh, &[]).unwrap();
    let back = load(&path, &ImportOptions::default()).unwrap();
    let faces =
        |m: &pgd_surgery_core::mesh::TetMesh| sorted_faces(m.face_set("accessible").unwrap());
    assert_eq!(faces(&back), faces(&mesh));
}

/// A cube of side 4 cm written in millimetres, as CAD tools do.
pub const CUBE_OBJ: &str = "# cube, mm\nv 0 0 0\nv 40 0 0\nv 40 40 0\nv 0 40 0\nv 0 0 40\nv 40 0 40\nv 40 40 40\nv 0 40 40\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

#[test]
fn a_closed_obj_surface_becomes_a_valid_tet_mesh() {
    let options = ImportOptions {
        scale: 1e-3,
        density: MeshDensity::Nodes(1500),
        ..ImportOptions::default()
    };
    let mesh = load(&file("cube.obj", CUBE_OBJ.as_bytes()), &options).unwrap();
    let q = QualityReport::measure(mesh.nodes(), mesh.tets());
    assert!(q.refusal().is_none(), "{q}");
    // Stuffing rounds the cube's edges by less than a lattice cell: measured −2 % at this size.
    let exact = 0.04f64.powi(3);
    assert!(
        (q.volume_m3 - exact).abs() < 0.04 * exact,
        "volume {} vs {exact}",
        q.volume_m3
    );
    assert!(
        (mesh.node_count() as f64 - 1500.0).abs() < 0.25 * 1500.0,
        "{} nodes",
        mesh.node_count()
    );
    // Without the scale, a 40 m "organ" is refused with a hint about millimetres.
    let err = load(
        &file("cube_m.obj", CUBE_OBJ.as_bytes()),
        &ImportOptions::default(),
    )
    .unwrap_err();
    assert!(err.to_string().contains("millimetres"), "{err}");
}

fn tetra_facets() -> [[[f32; 3]; 3]; 4] {
    let p = [
        [0.0, 0.0, 0.0],
        [0.03, 0.0, 0.0],
        [0.0, 0.03, 0.0],
        [0.0, 0.0, 0.03],
    ];
    [
        [p[0], p[2], p[1]],
        [p[0], p[1], p[3]],
        [p[0], p[3], p[2]],
        [p[1], p[2], p[3]],
    ]
}

/// A tetrahedron as an ASCII and as a binary STL file.
pub fn tetra_stl() -> (String, Vec<u8>) {
    let mut ascii = String::from("solid tetra\n");
    let mut binary = vec![0u8; 80];
    binary.extend(4u32.to_le_bytes());
    for facet in tetra_facets() {
        ascii.push_str("facet normal 0 0 0\nouter loop\n");
        binary.extend([0u8; 12]);
        for v in facet {
            ascii.push_str(&format!("vertex {} {} {}\n", v[0], v[1], v[2]));
            binary.extend(v.iter().flat_map(|c| c.to_le_bytes()));
        }
        ascii.push_str("endloop\nendfacet\n");
        binary.extend([0u8; 2]);
    }
    ascii.push_str("endsolid tetra\n");
    (ascii, binary)
}

#[test]
fn ascii_and_binary_stl_read_the_same_solid() {
    let (ascii, binary) = tetra_stl();
    let options = ImportOptions {
        scale: 1.0,
        density: MeshDensity::Nodes(800),
        ..ImportOptions::default()
    };
    let a = load(&file("t.stl", ascii.as_bytes()), &options).unwrap();
    let b = load(&file("tb.stl", &binary), &options).unwrap();
    let exact = 0.03f64.powi(3) / 6.0;
    for mesh in [&a, &b] {
        let v = mesh.volume();
        assert!((v - exact).abs() < 0.1 * exact, "volume {v} vs {exact}");
    }
    let truncated = load(&file("cut.stl", &binary[..binary.len() - 7]), &options).unwrap_err();
    assert!(truncated.to_string().contains("truncated"), "{truncated}");
}

fn syntax_line(err: ImportError) -> (String, usize) {
    match err {
        ImportError::Syntax {
            file,
            line,
            message,
        } => (format!("{file}: {message}"), line),
        other => panic!("expected a syntax error, got {other}"),
    }
}

#[test]
fn malformed_files_name_file_and_line() {
    let bad_number = MSH2.replace("3 0 1 0", "3 0 one 0");
    let (message, line) = syntax_line(import("bad.msh", &bad_number).unwrap_err());
    assert_eq!(line, 12, "{message}");
    assert!(
        message.contains("bad.msh") && message.contains("'one'"),
        "{message}"
    );

    let missing_node = MSH2.replace("3 4 2 0 1 2 3 4 5", "3 4 2 0 1 2 3 4 9");
    let (message, line) = syntax_line(import("missing.msh", &missing_node).unwrap_err());
    assert_eq!(line, 20, "{message}");
    assert!(message.contains("node 9"), "{message}");

    let (message, line) =
        syntax_line(import("range.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n").unwrap_err());
    assert_eq!(line, 3, "{message}");

    let stl = "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendfacet\nendsolid x\n";
    let (message, line) = syntax_line(import("loop.stl", stl).unwrap_err());
    assert_eq!(line, 7, "{message}");
    assert!(message.contains("endloop"), "{message}");

    let misspelled = "solid x\nfacett normal 0 0 1\n";
    let (message, line) = syntax_line(import("typo.stl", misspelled).unwrap_err());
    assert_eq!(line, 2, "{message}");
    assert!(message.contains("'facett'"), "{message}");

    let vtu = "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"1\" NumberOfCells=\"0\">\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"binary\">AAAA</DataArray>\n";
    let (message, line) = syntax_line(import("bin.vtu", vtu).unwrap_err());
    assert_eq!(line, 6, "{message}");
    assert!(
        message.contains("binary data array") && message.contains("shorter than its header"),
        "{message}"
    );

    let vtk = "# vtk DataFile Version 3.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 2 double\n0 0 0\n1 0 nan?\n";
    let (_, line) = syntax_line(import("bad.vtk", vtk).unwrap_err());
    assert_eq!(line, 7);
}

#[test]
fn unusable_meshes_are_refused_with_the_reason() {
    let inverted = MSH2.replace("3 4 2 0 1 2 3 4 5", "3 4 2 0 1 3 2 4 5");
    let err = import("inv.msh", &inverted).unwrap_err();
    assert!(
        matches!(err, ImportError::Unusable { .. }) && err.to_string().contains("inverted"),
        "{err}"
    );

    // A face missing: a hole of four edges, closed by a fan in the face's plane, so the
    // cube comes back whole.
    let options = ImportOptions {
        scale: 1e-3,
        density: MeshDensity::Nodes(500),
        ..ImportOptions::default()
    };
    let open_cube = CUBE_OBJ.replace("f 4 1 5 8\n", "");
    let mended = load(&file("open.obj", open_cube.as_bytes()), &options).unwrap();
    let whole = load(&file("whole.obj", CUBE_OBJ.as_bytes()), &options).unwrap();
    assert!((mended.volume() - whole.volume()).abs() < 1e-9 * whole.volume());

    let err = import("mesh.xyz", "1 2 3").unwrap_err();
    assert!(err.to_string().contains("unknown mesh format"), "{err}");
}

/// A real organ surface: the generated liver's boundary, written as binary STL in millimetres,
/// comes back as a valid tet mesh of the same volume.
#[test]
fn an_organ_surface_in_stl_becomes_a_valid_tet_mesh() {
    use pgd_surgery_core::mesh::Surface;
    use pgd_surgery_core::mesh::organs::{Organ, OrganSettings, generate};
    let liver = generate(
        Organ::Liver,
        &OrganSettings {
            resolution: 0.5,
            seed: 1,
            ..OrganSettings::default()
        },
    )
    .unwrap();
    let surface = Surface::extract(&liver);
    let mut stl = vec![0u8; 80];
    stl.extend((surface.triangles.len() as u32).to_le_bytes());
    for f in &surface.triangles {
        stl.extend([0u8; 12]);
        for &n in f {
            let p = liver.nodes()[n] * 1000.0;
            stl.extend(
                [p.x, p.y, p.z]
                    .iter()
                    .flat_map(|&c| (c as f32).to_le_bytes()),
            );
        }
        stl.extend([0u8; 2]);
    }
    let options = ImportOptions {
        scale: 1e-3,
        density: MeshDensity::Nodes(3000),
        ..ImportOptions::default()
    };
    let mesh = load(&file("liver.stl", &stl), &options).unwrap();
    let q = QualityReport::measure(mesh.nodes(), mesh.tets());
    assert!(q.refusal().is_none(), "{q}");
    let error = (mesh.volume() - liver.volume()).abs() / liver.volume();
    assert!(
        error < 0.03,
        "re-meshed liver volume off by {:.1} %",
        error * 100.0
    );
}

/// The liver's boundary in millimetres (single precision, as segmentation tools write it),
/// as binary STL, binary and ASCII PLY, and VTK polydata, ASCII and binary.
fn liver_surface_files() -> Vec<(&'static str, Vec<u8>)> {
    use pgd_surgery_core::mesh::Surface;
    let settings = OrganSettings {
        resolution: 0.5,
        ..OrganSettings::default()
    };
    let liver = organs::generate(Organ::Liver, &settings).unwrap();
    let surface = Surface::extract(&liver);
    // Each vertex exactly as single precision holds it, printed so that it reads back exact.
    let mm = |n: usize| {
        liver.nodes()[n]
            .coords
            .map(|c| ((c * 1000.0) as f32) as f64)
    };
    let (vertices, triangles) = (liver.node_count(), surface.triangles.len());
    let mut stl = vec![0u8; 80];
    stl.extend((triangles as u32).to_le_bytes());
    for f in &surface.triangles {
        stl.extend([0u8; 12]);
        for &n in f {
            stl.extend(mm(n).iter().flat_map(|&c| (c as f32).to_le_bytes()));
        }
        stl.extend([0u8; 2]);
    }
    let ply_header = |format: &str| {
        format!(
            "ply\nformat {format} 1.0\ncomment from a segmentation\nelement vertex {vertices}\n\
             property float x\nproperty float y\nproperty float z\nproperty uchar red\n\
             element face {triangles}\nproperty list uchar int vertex_indices\nend_header\n"
        )
    };
    let mut binary = ply_header("binary_little_endian").into_bytes();
    let mut ascii = ply_header("ascii");
    let vtk_header = |format: &str| {
        format!(
            "# vtk DataFile Version 3.0\nliver\n{format}\nDATASET POLYDATA\nPOINTS {vertices} float\n"
        )
    };
    let mut vtk = vtk_header("ASCII");
    // Binary legacy VTK is big-endian.
    let mut vtk_binary = vtk_header("BINARY").into_bytes();
    for n in 0..vertices {
        let p = mm(n);
        binary.extend(p.iter().flat_map(|&c| (c as f32).to_le_bytes()));
        binary.push(200);
        ascii += &format!("{} {} {} 200\n", p.x, p.y, p.z);
        vtk += &format!("{} {} {}\n", p.x, p.y, p.z);
        vtk_binary.extend(p.iter().flat_map(|&c| (c as f32).to_be_bytes()));
    }
    vtk += &format!("POLYGONS {triangles} {}\n", 4 * triangles);
    vtk_binary.extend(format!("\nPOLYGONS {triangles} {}\n", 4 * triangles).bytes());
    for f in &surface.triangles {
        binary.push(3);
        binary.extend(f.iter().flat_map(|&n| (n as i32).to_le_bytes()));
        ascii += &format!("3 {} {} {}\n", f[0], f[1], f[2]);
        vtk += &format!("3 {} {} {}\n", f[0], f[1], f[2]);
        vtk_binary.extend(3i32.to_be_bytes());
        vtk_binary.extend(f.iter().flat_map(|&n| (n as i32).to_be_bytes()));
    }
    vtk_binary.push(b'\n');
    vec![
        ("liver.stl", stl),
        ("liver-binary.ply", binary),
        ("liver-ascii.ply", ascii.into_bytes()),
        ("liver-polydata.vtk", vtk.into_bytes()),
        ("liver-polydata-binary.vtk", vtk_binary),
    ]
}

/// The same surface in each format segmentation tools write (binary legacy VTK included) gives
/// the same tetrahedral mesh, node for node.
#[test]
fn a_surface_reads_the_same_from_stl_ply_and_vtk_polydata() {
    let options = ImportOptions {
        scale: 1e-3,
        density: MeshDensity::Nodes(2000),
        ..ImportOptions::default()
    };
    let meshes: Vec<_> = liver_surface_files()
        .into_iter()
        .map(|(name, bytes)| (name, load(&file(name, &bytes), &options).unwrap()))
        .collect();
    let (first, reference) = &meshes[0];
    assert!(
        QualityReport::measure(reference.nodes(), reference.tets())
            .refusal()
            .is_none()
    );
    for (name, mesh) in &meshes[1..] {
        assert_eq!(mesh.nodes(), reference.nodes(), "{name} against {first}");
        assert_eq!(mesh.tets(), reference.tets(), "{name} against {first}");
    }
}

/// A PLY surface with a quarter of its triangles turned the wrong way and one triangle
/// missing is mended (turned back, the hole closed) and meshed to the same volume; the same
/// surface cut open over many triangles is refused, saying where the hole is.
#[test]
fn a_damaged_surface_is_mended_or_refused_with_where() {
    let (_, ascii) = liver_surface_files().swap_remove(2);
    let text = String::from_utf8(ascii).unwrap();
    let (header, body) = text.split_once("end_header\n").unwrap();
    let mut lines: Vec<String> = body.lines().map(str::to_owned).collect();
    let faces_at = lines.iter().position(|l| l.starts_with("3 ")).unwrap();
    for (k, line) in lines[faces_at..]
        .iter_mut()
        .enumerate()
        .filter(|(k, _)| k % 4 == 0)
    {
        let v: Vec<&str> = line.split(' ').collect();
        *line = format!("3 {} {} {} {k}", v[1], v[3], v[2])
            .rsplit_once(' ')
            .unwrap()
            .0
            .to_owned();
    }
    let faces = lines.len() - faces_at;
    // The faces kept when those `cut` picks (by their corners' positions, mm) are taken out.
    let damaged = |cut: &dyn Fn(&[[f64; 3]]) -> bool| {
        let position = |v: &str| -> [f64; 3] {
            let p: Vec<f64> = lines[v.parse::<usize>().unwrap()]
                .split(' ')
                .take(3)
                .map(|c| c.parse().unwrap())
                .collect();
            [p[0], p[1], p[2]]
        };
        let kept: Vec<&String> = (lines[faces_at..].iter())
            .filter(|l| {
                let corners: Vec<[f64; 3]> = l.split(' ').skip(1).map(position).collect();
                !cut(&corners)
            })
            .collect();
        let header = header.replace(
            &format!("element face {faces}"),
            &format!("element face {}", kept.len()),
        );
        let body: Vec<&str> = (lines[..faces_at].iter().chain(kept))
            .map(|l| l.as_str())
            .collect();
        format!("{header}end_header\n{}\n", body.join("\n"))
    };
    let first_face = |corners: &[[f64; 3]]| {
        let first: Vec<[f64; 3]> = lines[faces_at]
            .split(' ')
            .skip(1)
            .map(|v| {
                let p: Vec<f64> = lines[v.parse::<usize>().unwrap()]
                    .split(' ')
                    .take(3)
                    .map(|c| c.parse().unwrap())
                    .collect();
                [p[0], p[1], p[2]]
            })
            .collect();
        corners == first.as_slice()
    };
    // Every face with a corner within 30 mm of the first face's first corner: a round hole
    // of many edges.
    let first_corner: usize = lines[faces_at].split(' ').nth(1).unwrap().parse().unwrap();
    let centre: Vec<f64> = (lines[first_corner].split(' ').take(3))
        .map(|c| c.parse().unwrap())
        .collect();
    let near = |corners: &[[f64; 3]]| {
        let distance = |p: &[f64; 3]| (0..3).map(|k| (p[k] - centre[k]).powi(2)).sum::<f64>();
        corners.iter().any(|p| distance(p) < 30.0f64.powi(2))
    };
    let options = ImportOptions {
        scale: 1e-3,
        density: MeshDensity::Nodes(2000),
        ..ImportOptions::default()
    };
    let mended = load(
        &file("mended.ply", damaged(&first_face).as_bytes()),
        &options,
    )
    .unwrap();
    let (whole_name, whole) = liver_surface_files().swap_remove(0);
    let whole = load(&file(whole_name, &whole), &options).unwrap();
    let error = (mended.volume() - whole.volume()).abs() / whole.volume();
    assert!(error < 0.01, "mended volume off by {:.2} %", error * 100.0);
    let Err(refused) = load(&file("open.ply", damaged(&near).as_bytes()), &options) else {
        panic!("a surface cut open over 30 mm was meshed");
    };
    let refused = refused.to_string();
    assert!(
        refused.contains("open.ply") && refused.contains("a hole of"),
        "{refused}"
    );
    assert!(refused.contains(") mm"), "{refused}");
}

/// 3D Slicer states the frame in the file's header: the same surface written in LPS, saying
/// so, comes back as the RAS one (x and y reversed); `frame` overrides what the file says.
#[test]
fn a_surface_in_lps_is_turned_into_ras() {
    use pgd_surgery_core::mesh::io::Frame;
    let ras: Vec<[f64; 3]> = vec![
        [0.0, 0.0, 0.0],
        [20.0, 0.0, 0.0],
        [0.0, 20.0, 0.0],
        [0.0, 0.0, 20.0],
    ];
    let obj = |space: &str, sign: f64| {
        let mut text = format!("# {space}\n");
        for p in &ras {
            text += &format!("v {} {} {}\n", sign * p[0], sign * p[1], p[2]);
        }
        text + "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
    };
    let options = |frame: Option<Frame>| ImportOptions {
        scale: 1e-3,
        density: MeshDensity::Nodes(300),
        frame,
        ..ImportOptions::default()
    };
    let read = |name: &str, text: String, frame| {
        load(&file(name, text.as_bytes()), &options(frame)).unwrap()
    };
    let reference = read("ras.obj", obj("SPACE=RAS", 1.0), None);
    let stated = read("lps.obj", obj("SPACE=LPS", -1.0), None);
    let told = read("told.obj", obj("exported", -1.0), Some(Frame::Lps));
    assert_eq!(stated.nodes(), reference.nodes());
    assert_eq!(told.nodes(), reference.nodes());
    let untold = read("untold.obj", obj("exported", -1.0), None);
    assert_ne!(untold.nodes(), reference.nodes());
    assert_eq!("LPS".parse::<Frame>(), Ok(Frame::Lps));
    assert!("xyz".parse::<Frame>().unwrap_err().contains("ras"));
}

/// Two cubes of 4 cm in one file, the second moved 2 cm along each axis into the first: each
/// closed, together crossing. Refused with two triangles that cross and a point inside both
/// cubes, where they overlap; either cube alone is meshed.
#[test]
fn a_surface_crossing_itself_is_refused_with_where() {
    let moved: String = (CUBE_OBJ.lines())
        .map(|line| match line.strip_prefix("v ") {
            Some(v) => {
                let c: Vec<f64> = v.split(' ').map(|x| x.parse().unwrap()).collect();
                format!("v {} {} {}\n", c[0] + 20.0, c[1] + 20.0, c[2] + 20.0)
            }
            None => match line.strip_prefix("f ") {
                Some(f) => {
                    let ids: Vec<String> = (f.split(' '))
                        .map(|i| (i.parse::<usize>().unwrap() + 8).to_string())
                        .collect();
                    format!("f {}\n", ids.join(" "))
                }
                None => String::new(),
            },
        })
        .collect();
    let options = ImportOptions {
        scale: 1e-3,
        density: MeshDensity::Nodes(500),
        ..ImportOptions::default()
    };
    let both = format!("{CUBE_OBJ}{moved}");
    let error = load(&file("crossing.obj", both.as_bytes()), &options)
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("crossing.obj") && error.contains("crosses itself"),
        "{error}"
    );
    let near: Vec<f64> = (error
        .split_once("near (")
        .unwrap()
        .1
        .split_once(") mm")
        .unwrap()
        .0)
        .split(", ")
        .map(|x| x.parse().unwrap())
        .collect();
    assert!(near.iter().all(|&x| (20.0..=40.0).contains(&x)), "{error}");
    assert!(load(&file("alone.obj", CUBE_OBJ.as_bytes()), &options).is_ok());
}

/// The lengths of a mesh's edges, each once, sorted; and those of its boundary's.
fn edge_lengths(mesh: &pgd_surgery_core::mesh::TetMesh) -> (Vec<f64>, Vec<f64>) {
    use pgd_surgery_core::mesh::Surface;
    let length = |a: usize, b: usize| (mesh.nodes()[a] - mesh.nodes()[b]).norm();
    let sorted = |edges: std::collections::BTreeSet<(usize, usize)>| {
        let mut lengths: Vec<f64> = edges.into_iter().map(|(a, b)| length(a, b)).collect();
        lengths.sort_by(f64::total_cmp);
        lengths
    };
    let pairs = |corners: &[usize]| {
        let mut pairs = Vec::new();
        for i in 0..corners.len() {
            for j in i + 1..corners.len() {
                pairs.push((corners[i].min(corners[j]), corners[i].max(corners[j])));
            }
        }
        pairs
    };
    let all = mesh.tets().iter().flat_map(|t| pairs(t)).collect();
    let boundary = Surface::extract(mesh).triangles;
    let outer = boundary.iter().flat_map(|f| pairs(f)).collect();
    (sorted(all), sorted(outer))
}

/// `--element-mm`: the liver's surface (in millimetres) remeshed to elements of the size asked,
/// coarser than the file's, inside and on its surface, its volume kept; a size finer than the
/// node limit allows refused with the finest it would take.
#[test]
fn a_surface_is_remeshed_to_the_element_size_asked() {
    let (_, stl) = liver_surface_files().remove(0);
    let source = file("sized-liver.stl", &stl);
    let sized = |size_mm: f64| {
        let options = ImportOptions {
            scale: 1e-3,
            density: MeshDensity::ElementSize {
                size_m: size_mm * 1e-3,
            },
            ..ImportOptions::default()
        };
        load(&source, &options)
    };
    let median = |lengths: &[f64]| lengths[lengths.len() / 2] * 1e3;
    let settings = OrganSettings {
        resolution: 0.5,
        ..OrganSettings::default()
    };
    let liver = organs::generate(Organ::Liver, &settings).unwrap();
    let (_, file_surface) = edge_lengths(&liver);
    let file_mm = median(&file_surface);
    let file_faces = pgd_surgery_core::mesh::Surface::extract(&liver)
        .triangles
        .len();
    let (mut nodes, mut coarsest) = (Vec::new(), None);
    for size_mm in [14.0, 10.0] {
        let mesh = sized(size_mm).unwrap();
        let (all, outer) = edge_lengths(&mesh);
        let (inside_mm, surface_mm) = (median(&all), median(&outer));
        let faces = pgd_surgery_core::mesh::Surface::extract(&mesh)
            .triangles
            .len();
        nodes.push(mesh.node_count() as f64);
        coarsest.get_or_insert((faces, surface_mm));
        // The lattice's edges are the size and √3/2 of it; the surface's are cut shorter.
        assert!(
            (0.75 * size_mm..=1.05 * size_mm).contains(&inside_mm),
            "{size_mm} mm asked, median edge {inside_mm:.2} mm"
        );
        assert!(
            (0.6 * size_mm..=1.05 * size_mm).contains(&surface_mm),
            "{size_mm} mm asked, median surface edge {surface_mm:.2} mm"
        );
        let error = (mesh.volume() - liver.volume()).abs() / liver.volume();
        assert!(
            error < 0.05,
            "{size_mm} mm: volume off by {:.1} %",
            100.0 * error
        );
    }
    // At 14 mm, half as long again as the file's triangles, its surface is decimated.
    let (faces, surface_mm) = coarsest.unwrap();
    assert!(
        faces < file_faces,
        "{faces} faces against the file's {file_faces}"
    );
    assert!(
        surface_mm > file_mm,
        "{surface_mm:.2} mm, the file's {file_mm:.2} mm"
    );
    // Nodes go as the inverse cube of the size, up to the surface's share.
    let ratio = nodes[1] / nodes[0];
    let cubed = (14.0f64 / 10.0).powi(3);
    assert!(
        (0.7 * cubed..=1.3 * cubed).contains(&ratio),
        "nodes {nodes:?}: ratio {ratio:.2} against {cubed:.2}"
    );
    let refused = sized(0.2).unwrap_err().to_string();
    assert!(
        refused.contains("0.2 mm") && refused.contains("ask for") && refused.contains("200000"),
        "{refused}"
    );
}
