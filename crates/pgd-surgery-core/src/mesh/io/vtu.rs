//! VTK XML unstructured grids (`.vtu`), ASCII data arrays: read, and written for ParaView.
//!
//! Regions travel as `UInt8` point-data arrays named `region:<name>` (1 = in the set): node
//! sets as they are, face sets as their faces' corners, which read back as the node set and
//! the surface faces within it.

use std::fmt::Write as _;
use std::path::Path;

use nalgebra::Point3;
use quick_xml::Reader;
use quick_xml::events::{BytesStart, Event};

use super::tokens::Tokens;
use super::{ImportError, RawMesh};
use crate::mesh::TetMesh;

const VTK_TETRA: usize = 10;
const REGION_PREFIX: &str = "region:";

/// Where a data array goes.
#[derive(Clone, Debug, PartialEq)]
enum Target {
    Points,
    Connectivity,
    Offsets,
    Types,
    Region(String),
    Ignored,
}

pub(super) fn read(file: &str, text: &str) -> Result<RawMesh, ImportError> {
    let mut reader = Reader::from_str(text);
    let line_at = |pos: u64| 1 + text[..pos as usize].bytes().filter(|&b| b == b'\n').count();
    let syntax = |pos: u64, message: String| ImportError::Syntax {
        file: file.to_owned(),
        line: line_at(pos),
        message,
    };
    let mut section = String::new();
    let mut target: Option<Target> = None;
    let mut arrays: Vec<(Target, Vec<f64>)> = Vec::new();
    loop {
        let pos = reader.buffer_position();
        let event = reader
            .read_event()
            .map_err(|e| syntax(reader.error_position(), format!("malformed XML: {e}")))?;
        match event {
            Event::Start(e) if e.name().as_ref() == "DataArray" => {
                target = Some(data_array_target(&e, &section).map_err(|m| syntax(pos, m))?);
            }
            Event::Start(e) => {
                let name = e.name().as_ref().to_owned();
                if name == "VTKFile" {
                    check_file_type(&e).map_err(|m| syntax(pos, m))?;
                }
                section = name;
            }
            Event::Text(content) => {
                if let Some(t) = target.take() {
                    let body = content.xml10_content();
                    let mut tokens = Tokens::from_line(file, &body, line_at(pos));
                    let mut values = Vec::new();
                    while let Ok(token) = tokens.next("a number") {
                        let value: f64 = token.parse().map_err(|_| {
                            tokens.error(format!("expected a number, found '{token}'"))
                        })?;
                        values.push(value);
                    }
                    arrays.push((t, values));
                }
            }
            Event::End(e) if e.name().as_ref() == "DataArray" => target = None,
            Event::Eof => break,
            _ => {}
        }
    }
    assemble(file, arrays)
}

fn attribute(e: &BytesStart, name: &str) -> Option<String> {
    e.try_get_attribute(name).ok().flatten().and_then(|a| {
        a.normalized_value(quick_xml::XmlVersion::Implicit1_0)
            .ok()
            .map(|v| v.into_owned())
    })
}

fn check_file_type(e: &BytesStart) -> Result<(), String> {
    match attribute(e, "type").as_deref() {
        Some("UnstructuredGrid") => Ok(()),
        other => Err(format!(
            "expected an UnstructuredGrid VTKFile, found type {other:?}"
        )),
    }
}

fn data_array_target(e: &BytesStart, section: &str) -> Result<Target, String> {
    let format = attribute(e, "format").unwrap_or_else(|| "ascii".into());
    if format != "ascii" {
        return Err(format!(
            "DataArray format '{format}' is not read; save the .vtu with ASCII data (ParaView: Save Data, Data Mode: Ascii)"
        ));
    }
    let name = attribute(e, "Name").unwrap_or_default();
    Ok(match (section, name.as_str()) {
        ("Points", _) => Target::Points,
        ("Cells", "connectivity") => Target::Connectivity,
        ("Cells", "offsets") => Target::Offsets,
        ("Cells", "types") => Target::Types,
        ("PointData", n) if n.starts_with(REGION_PREFIX) => {
            Target::Region(n[REGION_PREFIX.len()..].to_owned())
        }
        _ => Target::Ignored,
    })
}

fn assemble(file: &str, arrays: Vec<(Target, Vec<f64>)>) -> Result<RawMesh, ImportError> {
    let find = |wanted: &Target| {
        arrays
            .iter()
            .find(|(t, _)| t == wanted)
            .map(|(_, v)| v.as_slice())
            .ok_or_else(|| ImportError::Unsupported {
                file: file.to_owned(),
                message: format!("no {wanted:?} data array"),
            })
    };
    let points = find(&Target::Points)?;
    if points.len() % 3 != 0 || points.iter().any(|c| !c.is_finite()) {
        return Err(ImportError::Unsupported {
            file: file.to_owned(),
            message: "the Points array must hold finite x y z triples".into(),
        });
    }
    let mut mesh = RawMesh {
        nodes: points
            .chunks_exact(3)
            .map(|c| Point3::new(c[0], c[1], c[2]))
            .collect(),
        ..RawMesh::default()
    };
    let (connectivity, offsets, types) = (
        find(&Target::Connectivity)?,
        find(&Target::Offsets)?,
        find(&Target::Types)?,
    );
    let mut start = 0;
    for (cell, (&end, &kind)) in offsets.iter().zip(types).enumerate() {
        let end = end as usize;
        let ids = connectivity
            .get(start..end)
            .ok_or_else(|| ImportError::Unsupported {
                file: file.to_owned(),
                message: format!("cell {cell}: offset {end} is beyond the connectivity array"),
            })?;
        if kind as usize == VTK_TETRA {
            if ids.len() != 4 {
                return Err(ImportError::Unsupported {
                    file: file.to_owned(),
                    message: format!("cell {cell} is a tetrahedron with {} points", ids.len()),
                });
            }
            mesh.tets.push([0, 1, 2, 3].map(|i| ids[i] as usize));
        }
        start = end;
    }
    for (target, values) in &arrays {
        if let Target::Region(name) = target {
            let nodes = values
                .iter()
                .enumerate()
                .filter(|(_, v)| **v != 0.0)
                .map(|(n, _)| n)
                .collect();
            mesh.node_sets.insert(name.clone(), nodes);
        }
    }
    Ok(mesh)
}

/// Writes a mesh as ASCII `.vtu`: its node sets as `region:<name>` point arrays, plus any
/// extra point vectors (three components per node, e.g. a displacement in metres).
pub fn write_vtu(path: &Path, mesh: &TetMesh, vectors: &[(&str, &[f64])]) -> std::io::Result<()> {
    let mut out = String::new();
    let (n, m) = (mesh.node_count(), mesh.tet_count());
    let _ = writeln!(out, r#"<?xml version="1.0"?>"#);
    let _ = writeln!(
        out,
        r#"<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian">"#
    );
    let _ = writeln!(
        out,
        "<UnstructuredGrid>\n<Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{m}\">"
    );
    out.push_str(
        "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n",
    );
    for p in mesh.nodes() {
        let _ = writeln!(out, "{:e} {:e} {:e}", p.x, p.y, p.z);
    }
    out.push_str("</DataArray>\n</Points>\n<Cells>\n");
    out.push_str("<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for t in mesh.tets() {
        let _ = writeln!(out, "{} {} {} {}", t[0], t[1], t[2], t[3]);
    }
    out.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for i in 1..=m {
        let _ = write!(out, "{} ", 4 * i);
    }
    out.push_str("\n</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    out.push_str(&format!("{VTK_TETRA} ").repeat(m));
    out.push_str("\n</DataArray>\n</Cells>\n<PointData>\n");
    for (name, nodes) in region_nodes(mesh) {
        let mut flags = vec![0u8; n];
        for node in nodes {
            flags[node] = 1;
        }
        let _ = writeln!(
            out,
            "<DataArray type=\"UInt8\" Name=\"{REGION_PREFIX}{}\" format=\"ascii\">",
            xml_escape(name)
        );
        for f in flags {
            let _ = write!(out, "{f} ");
        }
        out.push_str("\n</DataArray>\n");
    }
    for (name, values) in vectors {
        let _ = writeln!(
            out,
            "<DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"3\" format=\"ascii\">",
            xml_escape(name)
        );
        for v in values.chunks(3) {
            let _ = writeln!(out, "{:e} {:e} {:e}", v[0], v[1], v[2]);
        }
        out.push_str("</DataArray>\n");
    }
    out.push_str("</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    std::fs::write(path, out)
}

/// Every region as the nodes it holds: the node sets, and each face set without a node set of
/// its name as its faces' corners (read back, these give the surface faces again).
fn region_nodes(mesh: &TetMesh) -> Vec<(&String, Vec<usize>)> {
    let regions = mesh.regions();
    let mut sets: Vec<(&String, Vec<usize>)> = regions
        .node_sets
        .iter()
        .map(|(name, nodes)| (name, nodes.clone()))
        .collect();
    for (name, faces) in &regions.face_sets {
        if !regions.node_sets.contains_key(name) {
            sets.push((name, super::face_nodes(faces)));
        }
    }
    sets
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
