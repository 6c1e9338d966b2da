//! VTK legacy `.vtk`, ASCII and binary: unstructured grids, whose tetrahedra (cell type 10)
//! make the mesh (other cells skipped), and polydata surfaces, whose polygons and triangle
//! strips make a surface to tetrahedralize; cells in the classic `CELLS n size` layout or the
//! `OFFSETS`/`CONNECTIVITY` layout of format 5. A binary file is the ASCII layout with each
//! section's numbers as big-endian bytes of the section's data type; one reader serves both
//! through [`Source`].

use std::str::FromStr;

use nalgebra::Point3;

use super::cursor::Cursor;
use super::surface::SurfaceMesh;
use super::tokens::Tokens;
use super::{ImportError, RawMesh};

/// What a legacy file holds.
pub(super) enum Dataset {
    Grid(RawMesh),
    Surface(SurfaceMesh),
}

const VTK_TETRA: usize = 10;

pub(super) fn read(file: &str, bytes: &[u8]) -> Result<Dataset, ImportError> {
    let header_end = bytes
        .iter()
        .position(|&b| b == b'\n')
        .unwrap_or(bytes.len());
    let header = String::from_utf8_lossy(&bytes[..header_end]);
    if !header.starts_with("# vtk DataFile") {
        return Err(ImportError::Syntax {
            file: file.to_owned(),
            line: 1,
            message: format!("expected '# vtk DataFile Version …', found '{header}'"),
        });
    }
    // The title (line 2) is free text; the body starts at line 3 with ASCII or BINARY.
    let body_start = (bytes.iter().enumerate())
        .filter(|(_, b)| **b == b'\n')
        .nth(1)
        .map_or(bytes.len(), |(i, _)| i + 1);
    let body = &bytes[body_start..];
    if body.trim_ascii_start().starts_with(b"BINARY") {
        let mut cursor = Cursor::new(file, bytes, false).moved_to(body_start);
        cursor.word("BINARY")?;
        return dataset(&mut cursor);
    }
    let text = String::from_utf8(body.to_vec()).map_err(|e| ImportError::Unsupported {
        file: file.to_owned(),
        message: format!(
            "an ASCII legacy file that is not UTF-8 text (byte {} of its body)",
            body_start + e.utf8_error().valid_up_to()
        ),
    })?;
    let mut t = Tokens::from_line(file, &text, 3);
    let format = t.next("ASCII or BINARY")?;
    if format != "ASCII" {
        return Err(t.error(format!("expected ASCII or BINARY, found '{format}'")));
    }
    dataset(&mut t)
}

fn dataset(f: &mut impl Source) -> Result<Dataset, ImportError> {
    f.expect("DATASET")?;
    match f.text::<String>("a dataset type")?.as_str() {
        "UNSTRUCTURED_GRID" => grid(f).map(Dataset::Grid),
        "POLYDATA" => polydata(f).map(Dataset::Surface),
        other => Err(f.error(format!(
            "expected an UNSTRUCTURED_GRID or a POLYDATA surface, found '{other}'"
        ))),
    }
}

/// Where the reader takes a legacy file's words and numbers from.
trait Source {
    /// A word or number written as text.
    fn text<T: FromStr>(&mut self, what: &str) -> Result<T, ImportError>;
    /// A number of the VTK data type `kind` (as text in an ASCII file).
    fn value(&mut self, kind: &str, what: &str) -> Result<f64, ImportError>;
    /// The next section's keyword; `None` at the end of the file.
    fn keyword(&mut self) -> Option<String>;
    /// Whether the next word is `keyword`; if so, it is passed.
    fn passes(&mut self, keyword: &str) -> bool;
    fn error(&self, message: String) -> ImportError;

    fn expect(&mut self, keyword: &str) -> Result<(), ImportError> {
        let word: String = self.text(keyword)?;
        match word == keyword {
            true => Ok(()),
            false => Err(self.error(format!("expected '{keyword}', found '{word}'"))),
        }
    }

    /// An index or a count of the data type `kind`.
    fn index(&mut self, kind: &str, what: &str) -> Result<usize, ImportError> {
        let value = self.value(kind, what)?;
        match value >= 0.0 && value.fract() == 0.0 && value < usize::MAX as f64 {
            true => Ok(value as usize),
            false => Err(self.error(format!("expected {what}, found {value}"))),
        }
    }
}

impl Source for Tokens<'_> {
    fn text<T: FromStr>(&mut self, what: &str) -> Result<T, ImportError> {
        self.parse(what)
    }

    fn value(&mut self, _kind: &str, what: &str) -> Result<f64, ImportError> {
        self.parse(what)
    }

    fn index(&mut self, _kind: &str, what: &str) -> Result<usize, ImportError> {
        self.parse(what)
    }

    fn keyword(&mut self) -> Option<String> {
        self.next("a section").ok().map(str::to_owned)
    }

    fn passes(&mut self, keyword: &str) -> bool {
        let found = self.peek() == Some(keyword);
        if found {
            let _ = self.next(keyword);
        }
        found
    }

    fn error(&self, message: String) -> ImportError {
        Tokens::error(self, message)
    }
}

impl Source for Cursor<'_> {
    fn text<T: FromStr>(&mut self, what: &str) -> Result<T, ImportError> {
        self.parse(what)
    }

    fn value(&mut self, kind: &str, what: &str) -> Result<f64, ImportError> {
        Ok(match kind {
            "float" => f32::from_le_bytes(self.take(what)?).into(),
            "double" => f64::from_le_bytes(self.take(what)?),
            "char" => i8::from_le_bytes(self.take(what)?).into(),
            "unsigned_char" => u8::from_le_bytes(self.take(what)?).into(),
            "short" => i16::from_le_bytes(self.take(what)?).into(),
            "unsigned_short" => u16::from_le_bytes(self.take(what)?).into(),
            "int" | "vtktypeint32" => i32::from_le_bytes(self.take(what)?).into(),
            "unsigned_int" | "vtktypeuint32" => u32::from_le_bytes(self.take(what)?).into(),
            "long" | "vtktypeint64" => i64::from_le_bytes(self.take(what)?) as f64,
            "unsigned_long" | "vtktypeuint64" => u64::from_le_bytes(self.take(what)?) as f64,
            other => return Err(self.error(format!("the data type '{other}' is not read"))),
        })
    }

    fn keyword(&mut self) -> Option<String> {
        (!self.at_end())
            .then(|| self.word("a section").ok().map(str::to_owned))
            .flatten()
    }

    fn passes(&mut self, keyword: &str) -> bool {
        Cursor::passes(self, keyword)
    }

    fn error(&self, message: String) -> ImportError {
        Cursor::error(self, message)
    }
}

/// The points of a `POINTS n type` section.
fn points(f: &mut impl Source) -> Result<Vec<Point3<f64>>, ImportError> {
    let count: usize = f.text("the number of points")?;
    let kind: String = f.text("a data type")?;
    (0..count)
        .map(|_| {
            let p: [f64; 3] = [
                f.value(&kind, "x")?,
                f.value(&kind, "y")?,
                f.value(&kind, "z")?,
            ];
            match p.iter().all(|c| c.is_finite()) {
                true => Ok(Point3::from(p)),
                false => Err(f.error("a point has a non-finite coordinate".into())),
            }
        })
        .collect()
}

/// A polydata surface: its polygons fanned and its strips split into triangles; vertices and
/// lines are skipped.
fn polydata(f: &mut impl Source) -> Result<SurfaceMesh, ImportError> {
    let mut surface = SurfaceMesh::default();
    while let Some(keyword) = f.keyword() {
        match keyword.as_str() {
            "POINTS" => surface.vertices = points(f)?,
            "POLYGONS" => {
                for polygon in read_cells(f)? {
                    if polygon.len() < 3 {
                        return Err(f.error(format!("a polygon of {} points", polygon.len())));
                    }
                    for k in 1..polygon.len() - 1 {
                        surface
                            .triangles
                            .push([polygon[0], polygon[k], polygon[k + 1]]);
                    }
                }
            }
            "TRIANGLE_STRIPS" => {
                for strip in read_cells(f)? {
                    for k in 0..strip.len().saturating_sub(2) {
                        let (a, b, c) = (strip[k], strip[k + 1], strip[k + 2]);
                        // Every other triangle of a strip runs the other way.
                        surface.triangles.push(match k % 2 {
                            0 => [a, b, c],
                            _ => [b, a, c],
                        });
                    }
                }
            }
            "VERTICES" | "LINES" => {
                read_cells(f)?;
            }
            "POINT_DATA" | "CELL_DATA" | "FIELD" | "METADATA" => break,
            other => return Err(f.error(format!("unexpected '{other}'"))),
        }
    }
    let count = surface.vertices.len();
    if let Some(bad) = surface
        .triangles
        .iter()
        .find(|t| t.iter().any(|&v| v >= count))
    {
        return Err(f.error(format!("a polygon {bad:?} names a point past the {count}")));
    }
    Ok(surface)
}

/// An unstructured grid's tetrahedra.
fn grid(f: &mut impl Source) -> Result<RawMesh, ImportError> {
    let mut mesh = RawMesh::default();
    let mut cells: Vec<Vec<usize>> = Vec::new();
    let mut types: Vec<usize> = Vec::new();
    while let Some(keyword) = f.keyword() {
        match keyword.as_str() {
            "POINTS" => mesh.nodes = points(f)?,
            "CELLS" => cells = read_cells(f)?,
            "CELL_TYPES" => {
                let count: usize = f.text("the number of cell types")?;
                types = (0..count)
                    .map(|_| f.index("int", "a cell type"))
                    .collect::<Result<_, _>>()?;
            }
            // Point and cell data are not needed to simulate; stop reading there.
            "POINT_DATA" | "CELL_DATA" | "FIELD" | "METADATA" => break,
            other => return Err(f.error(format!("unexpected '{other}'"))),
        }
    }
    if types.len() != cells.len() {
        return Err(f.error(format!(
            "{} cells but {} cell types",
            cells.len(),
            types.len()
        )));
    }
    for (cell, kind) in cells.iter().zip(&types) {
        if *kind == VTK_TETRA {
            if cell.len() != 4 {
                return Err(f.error(format!("a tetrahedron with {} points", cell.len())));
            }
            mesh.tets.push([cell[0], cell[1], cell[2], cell[3]]);
        }
    }
    Ok(mesh)
}

/// Cells in either layout, as point-index lists.
fn read_cells(f: &mut impl Source) -> Result<Vec<Vec<usize>>, ImportError> {
    let first: usize = f.text("the number of cells")?;
    let size: usize = f.text("the size of the cell list")?;
    if f.passes("OFFSETS") {
        // Format 5: `first` counts offsets (cells + 1), `size` the connectivity length.
        let kind: String = f.text("an offsets data type")?;
        let offsets: Vec<usize> = (0..first)
            .map(|_| f.index(&kind, "an offset"))
            .collect::<Result<_, _>>()?;
        f.expect("CONNECTIVITY")?;
        let kind: String = f.text("a connectivity data type")?;
        let ids: Vec<usize> = (0..size)
            .map(|_| f.index(&kind, "a point index"))
            .collect::<Result<_, _>>()?;
        return offsets
            .windows(2)
            .map(|w| {
                ids.get(w[0]..w[1])
                    .map(<[usize]>::to_vec)
                    .ok_or_else(|| f.error(format!("offset {} beyond the connectivity list", w[1])))
            })
            .collect();
    }
    // The classic layout: each cell's point count, then its points, as `int`s. Not reserved
    // from the file's count: a damaged one would claim anything.
    let mut cells = Vec::new();
    for _ in 0..first {
        let count = f.index("int", "a point count")?;
        cells.push(
            (0..count)
                .map(|_| f.index("int", "a point index"))
                .collect::<Result<_, _>>()?,
        );
    }
    Ok(cells)
}
