//! VTK XML unstructured grids (`.vtu`): read with ASCII, binary (base64) and appended (raw or
//! base64) data arrays, zlib-compressed or not (`vtu_data`); written with ASCII arrays for
//! ParaView.
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
use super::vtu_data::{Layout, Scalar, decode_base64, decode_raw};
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

/// How a data array's values are written.
#[derive(Clone, Debug, PartialEq)]
enum Format {
    Ascii,
    /// Base64 inside the element.
    Binary,
    /// In the appended data, from this offset.
    Appended(usize),
}

/// A data array as its element declares it.
#[derive(Clone, Debug)]
struct Declared {
    target: Target,
    format: Format,
    scalar: Scalar,
}

/// A file's appended data: raw bytes or base64 text, after the `_` that starts it.
struct Appended<'a> {
    raw: bool,
    bytes: &'a [u8],
}

pub(super) fn read(file: &str, bytes: &[u8]) -> Result<RawMesh, ImportError> {
    // Raw appended data is no text: the XML is read up to it.
    let (xml, appended) = split_appended(bytes);
    let text = std::str::from_utf8(xml).map_err(|e| ImportError::Unsupported {
        file: file.to_owned(),
        message: format!(
            "not UTF-8 text (byte {}) before any appended data",
            e.valid_up_to()
        ),
    })?;
    let mut reader = Reader::from_str(text);
    let line_at = |pos: u64| 1 + text[..pos as usize].bytes().filter(|&b| b == b'\n').count();
    let syntax = |pos: u64, message: String| ImportError::Syntax {
        file: file.to_owned(),
        line: line_at(pos),
        message,
    };
    let mut section = String::new();
    let mut layout = Layout::of(None, None, None).expect("the defaults");
    let mut open: Option<Declared> = None;
    let mut arrays: Vec<(Target, Vec<f64>)> = Vec::new();
    let mut later: Vec<Declared> = Vec::new();
    loop {
        let pos = reader.buffer_position();
        let event = reader
            .read_event()
            .map_err(|e| syntax(reader.error_position(), format!("malformed XML: {e}")))?;
        match event {
            Event::Start(e) | Event::Empty(e) if e.name().as_ref() == "DataArray" => {
                let declared = declare(&e, &section).map_err(|m| syntax(pos, m))?;
                match declared.format {
                    Format::Appended(_) => later.push(declared),
                    _ => open = Some(declared),
                }
            }
            Event::Start(e) => {
                let name = e.name().as_ref().to_owned();
                if name == "VTKFile" {
                    layout = file_layout(&e).map_err(|m| syntax(pos, m))?;
                }
                section = name;
            }
            Event::Text(content) => {
                if let Some(declared) = open.take() {
                    let body = content.xml10_content();
                    let values = match declared.format {
                        Format::Binary => decode_base64(&body, declared.scalar, &layout)
                            .map_err(|m| syntax(pos, format!("a binary data array: {m}")))?,
                        _ => ascii_values(file, &body, line_at(pos))?,
                    };
                    arrays.push((declared.target, values));
                }
            }
            Event::End(e) if e.name().as_ref() == "DataArray" => open = None,
            Event::Eof => break,
            _ => {}
        }
    }
    let mut offsets: Vec<usize> = (later.iter())
        .filter_map(|d| match d.format {
            Format::Appended(offset) => Some(offset),
            _ => None,
        })
        .collect();
    offsets.sort_unstable();
    for declared in later {
        let next = |offset: usize| offsets.iter().copied().find(|&o| o > offset);
        let values = appended_values(&declared, appended.as_ref(), &layout, next).map_err(|m| {
            ImportError::Unsupported {
                file: file.to_owned(),
                message: format!("appended data array {:?}: {m}", declared.target),
            }
        })?;
        arrays.push((declared.target, values));
    }
    assemble(file, arrays)
}

/// The file before its `AppendedData` element, and that element's data if it has one.
fn split_appended(bytes: &[u8]) -> (&[u8], Option<Appended<'_>>) {
    let find = |what: &[u8], from: usize| {
        (bytes[from..].windows(what.len()))
            .position(|w| w == what)
            .map(|k| from + k)
    };
    let Some(start) = find(b"<AppendedData", 0) else {
        return (bytes, None);
    };
    let Some(underscore) = find(b"_", start) else {
        return (&bytes[..start], None);
    };
    let tag = String::from_utf8_lossy(&bytes[start..underscore]);
    let appended = Appended {
        raw: !tag.contains("\"base64\""),
        bytes: &bytes[underscore + 1..],
    };
    (&bytes[..start], Some(appended))
}

/// The values of an appended array, from its offset in the appended data; `next` gives the
/// offset of the array after one at an offset, if there is one.
fn appended_values(
    declared: &Declared,
    appended: Option<&Appended>,
    layout: &Layout,
    next: impl Fn(usize) -> Option<usize>,
) -> Result<Vec<f64>, String> {
    let Format::Appended(offset) = declared.format else {
        return Err("not appended".into());
    };
    let appended = appended.ok_or("the file has no AppendedData element")?;
    let from = (appended.bytes.get(offset..)).ok_or("its offset is past the appended data")?;
    if appended.raw {
        return decode_raw(from, declared.scalar, layout);
    }
    // Base64 runs on into the next array's characters: up to them, or to white space or the
    // element's end after the last.
    let end = next(offset).map(|n| n - offset).unwrap_or_else(|| {
        (from.iter())
            .position(|b| b.is_ascii_whitespace() || *b == b'<')
            .unwrap_or(from.len())
    });
    let text = std::str::from_utf8(&from[..end]).map_err(|_| "base64 that is not text")?;
    decode_base64(text, declared.scalar, layout)
}

/// The numbers of an ASCII data array's text, which starts at `first_line`.
fn ascii_values(file: &str, body: &str, first_line: usize) -> Result<Vec<f64>, ImportError> {
    let mut tokens = Tokens::from_line(file, body, first_line);
    let mut values = Vec::new();
    while let Ok(token) = tokens.next("a number") {
        let value: f64 = token
            .parse()
            .map_err(|_| tokens.error(format!("expected a number, found '{token}'")))?;
        values.push(value);
    }
    Ok(values)
}

fn attribute(e: &BytesStart, name: &str) -> Option<String> {
    e.try_get_attribute(name).ok().flatten().and_then(|a| {
        a.normalized_value(quick_xml::XmlVersion::Implicit1_0)
            .ok()
            .map(|v| v.into_owned())
    })
}

/// An unstructured grid's layout of binary data.
fn file_layout(e: &BytesStart) -> Result<Layout, String> {
    match attribute(e, "type").as_deref() {
        Some("UnstructuredGrid") => {}
        other => {
            return Err(format!(
                "expected an UnstructuredGrid VTKFile, found type {other:?}"
            ));
        }
    }
    Layout::of(
        attribute(e, "byte_order").as_deref(),
        attribute(e, "header_type").as_deref(),
        attribute(e, "compressor").as_deref(),
    )
}

fn declare(e: &BytesStart, section: &str) -> Result<Declared, String> {
    let format = match attribute(e, "format").as_deref().unwrap_or("ascii") {
        "ascii" => Format::Ascii,
        "binary" => Format::Binary,
        "appended" => {
            let offset = attribute(e, "offset").ok_or("an appended DataArray has no offset")?;
            Format::Appended(
                offset
                    .parse()
                    .map_err(|_| format!("the offset '{offset}' is no byte count"))?,
            )
        }
        other => {
            return Err(format!(
                "DataArray format '{other}' is not ascii, binary or appended"
            ));
        }
    };
    let scalar = Scalar::of(&attribute(e, "type").unwrap_or_else(|| "Float64".into()))?;
    let name = attribute(e, "Name").unwrap_or_default();
    let target = match (section, name.as_str()) {
        ("Points", _) => Target::Points,
        ("Cells", "connectivity") => Target::Connectivity,
        ("Cells", "offsets") => Target::Offsets,
        ("Cells", "types") => Target::Types,
        ("PointData", n) if n.starts_with(REGION_PREFIX) => {
            Target::Region(n[REGION_PREFIX.len()..].to_owned())
        }
        _ => Target::Ignored,
    };
    Ok(Declared {
        target,
        format,
        scalar,
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
