//! Stanford PLY surfaces, ASCII or binary (either byte order), as segmentation tools write
//! them: an element `vertex` with `x`, `y`, `z` (other properties skipped) and an element
//! `face` with a list of vertex indices (`vertex_indices` or `vertex_index`; polygons fanned).

use nalgebra::Point3;

use super::ImportError;
use super::surface::SurfaceMesh;

/// How the body is written.
#[derive(Clone, Copy, PartialEq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

/// A scalar property's type, by its size in bytes and whether it is a float.
#[derive(Clone, Copy)]
struct Scalar {
    bytes: usize,
    float: bool,
    signed: bool,
}

fn scalar(name: &str) -> Option<Scalar> {
    let (bytes, float, signed) = match name {
        "char" | "int8" => (1, false, true),
        "uchar" | "uint8" => (1, false, false),
        "short" | "int16" => (2, false, true),
        "ushort" | "uint16" => (2, false, false),
        "int" | "int32" => (4, false, true),
        "uint" | "uint32" => (4, false, false),
        "float" | "float32" => (4, true, true),
        "double" | "float64" => (8, true, true),
        _ => return None,
    };
    Some(Scalar {
        bytes,
        float,
        signed,
    })
}

/// A property of an element: a scalar, or a list with its count's and items' types.
#[derive(Clone)]
enum Property {
    Scalar(String, Scalar),
    List(String, Scalar, Scalar),
}

struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

/// Reads the PLY file `file` from its `bytes`.
pub fn read_ply(file: &str, bytes: &[u8]) -> Result<SurfaceMesh, ImportError> {
    let syntax = |line: usize, message: String| ImportError::Syntax {
        file: file.to_owned(),
        line,
        message,
    };
    let end = find(bytes, b"end_header")
        .ok_or_else(|| syntax(1, "no `end_header`: not a PLY file".into()))?;
    let body_at = end
        + bytes[end..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len() - end, |k| k + 1);
    let header = std::str::from_utf8(&bytes[..end])
        .map_err(|_| syntax(1, "the header is not text".into()))?;
    let (encoding, elements) = read_header(header).map_err(|(line, m)| syntax(line, m))?;
    let body = &bytes[body_at..];
    let header_lines = header.lines().count() + 1;
    let mut values = match encoding {
        Encoding::Ascii => Values::Text(
            std::str::from_utf8(body)
                .map_err(|_| syntax(header_lines, "an ASCII body must be text".into()))?
                .split_ascii_whitespace(),
        ),
        binary => Values::Binary {
            bytes: body,
            at: 0,
            little: binary == Encoding::Little,
        },
    };
    let mut surface = SurfaceMesh::default();
    for element in &elements {
        for k in 0..element.count {
            read_item(element, &mut values, &mut surface)
                .map_err(|m| syntax(header_lines, format!("{} {k}: {m}", element.name)))?;
        }
    }
    if let Some((t, f)) = (surface.triangles.iter().enumerate())
        .find(|(_, f)| f.iter().any(|&v| v >= surface.vertices.len()))
    {
        return Err(syntax(
            header_lines,
            format!(
                "face {t} {f:?} names a vertex past the {}",
                surface.vertices.len()
            ),
        ));
    }
    Ok(surface)
}

fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}

/// The header's encoding and elements, or the line and the problem.
fn read_header(header: &str) -> Result<(Encoding, Vec<Element>), (usize, String)> {
    let mut lines = header.lines().enumerate().map(|(k, l)| (k + 1, l.trim()));
    match lines.next() {
        Some((_, "ply")) => {}
        _ => return Err((1, "a PLY file starts with `ply`".into())),
    }
    let (mut encoding, mut elements) = (None, Vec::<Element>::new());
    for (line, text) in lines {
        let words: Vec<&str> = text.split_whitespace().collect();
        match words.as_slice() {
            ["format", kind, _version] => {
                encoding = Some(match *kind {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::Little,
                    "binary_big_endian" => Encoding::Big,
                    other => return Err((line, format!("unknown format `{other}`"))),
                });
            }
            ["element", name, count] => elements.push(Element {
                name: (*name).to_owned(),
                count: count
                    .parse()
                    .map_err(|_| (line, format!("`{count}` is no count")))?,
                properties: Vec::new(),
            }),
            ["property", "list", count, item, name] => {
                let element = elements
                    .last_mut()
                    .ok_or((line, "a property before any element".into()))?;
                let (count, item) = (scalar(count), scalar(item));
                let (Some(count), Some(item)) = (count, item) else {
                    return Err((line, format!("unknown list types in `{text}`")));
                };
                element
                    .properties
                    .push(Property::List((*name).to_owned(), count, item));
            }
            ["property", kind, name] => {
                let element = elements
                    .last_mut()
                    .ok_or((line, "a property before any element".into()))?;
                let kind = scalar(kind).ok_or((line, format!("unknown type `{kind}`")))?;
                element
                    .properties
                    .push(Property::Scalar((*name).to_owned(), kind));
            }
            ["comment", ..] | ["obj_info", ..] | [] => {}
            _ => return Err((line, format!("unexpected header line `{text}`"))),
        }
    }
    Ok((encoding.ok_or((2, "no `format` line".into()))?, elements))
}

/// The body's numbers, as text or as bytes.
enum Values<'a> {
    Text(std::str::SplitAsciiWhitespace<'a>),
    Binary {
        bytes: &'a [u8],
        at: usize,
        little: bool,
    },
}

impl Values<'_> {
    fn next(&mut self, kind: Scalar) -> Result<f64, String> {
        match self {
            Values::Text(words) => {
                let word = words.next().ok_or("the file ends early")?;
                word.parse()
                    .map_err(|_| format!("`{word}` is not a number"))
            }
            Values::Binary { bytes, at, little } => {
                let raw = bytes
                    .get(*at..*at + kind.bytes)
                    .ok_or("the file ends early")?;
                *at += kind.bytes;
                let mut buffer = [0u8; 8];
                buffer[..kind.bytes].copy_from_slice(raw);
                if !*little {
                    buffer[..kind.bytes].reverse();
                }
                Ok(decode(buffer, kind))
            }
        }
    }
}

/// A little-endian scalar of `kind` in the first bytes of `b`.
fn decode(b: [u8; 8], kind: Scalar) -> f64 {
    match (kind.bytes, kind.float, kind.signed) {
        (4, true, _) => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        (8, true, _) => f64::from_le_bytes(b),
        (1, false, true) => b[0] as i8 as f64,
        (1, false, false) => b[0] as f64,
        (2, false, true) => i16::from_le_bytes([b[0], b[1]]) as f64,
        (2, false, false) => u16::from_le_bytes([b[0], b[1]]) as f64,
        (4, false, true) => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
    }
}

/// One item of `element`: a vertex's position or a face's triangles kept, anything else read
/// past.
fn read_item(
    element: &Element,
    values: &mut Values,
    surface: &mut SurfaceMesh,
) -> Result<(), String> {
    let mut position = [f64::NAN; 3];
    for property in &element.properties {
        match property {
            Property::Scalar(name, kind) => {
                let value = values.next(*kind)?;
                if let Some(axis) = ["x", "y", "z"].iter().position(|a| a == name) {
                    position[axis] = value;
                }
            }
            Property::List(name, count, item) => {
                let n = values.next(*count)?;
                if !(0.0..=1e6).contains(&n) {
                    return Err(format!("a list of {n} items"));
                }
                let corners: Vec<f64> = (0..n as usize)
                    .map(|_| values.next(*item))
                    .collect::<Result<_, _>>()?;
                let is_face =
                    element.name == "face" && (name == "vertex_indices" || name == "vertex_index");
                if is_face {
                    if corners.len() < 3 || corners.iter().any(|&c| c < 0.0) {
                        return Err(format!("a face of corners {corners:?}"));
                    }
                    for k in 1..corners.len() - 1 {
                        surface
                            .triangles
                            .push([corners[0], corners[k], corners[k + 1]].map(|c| c as usize));
                    }
                }
            }
        }
    }
    if element.name == "vertex" {
        if !position.iter().all(|c| c.is_finite()) {
            return Err("a vertex without a finite x, y and z".into());
        }
        surface.vertices.push(Point3::from(position));
    }
    Ok(())
}
