//! VTK legacy `.vtk`, ASCII: unstructured grids, whose tetrahedra (cell type 10) make the
//! mesh (other cells skipped), and polydata surfaces, whose polygons and triangle strips make
//! a surface to tetrahedralize; cells in the classic `CELLS n size` layout or the
//! `OFFSETS`/`CONNECTIVITY` layout of format 5.

use nalgebra::Point3;

use super::surface::SurfaceMesh;
use super::tokens::Tokens;
use super::{ImportError, RawMesh};

/// What a legacy file holds.
pub(super) enum Dataset {
    Grid(RawMesh),
    Surface(SurfaceMesh),
}

const VTK_TETRA: usize = 10;

pub(super) fn read(file: &str, text: &str) -> Result<Dataset, ImportError> {
    let header = text.lines().next().unwrap_or_default();
    if !header.starts_with("# vtk DataFile") {
        return Err(ImportError::Syntax {
            file: file.to_owned(),
            line: 1,
            message: format!("expected '# vtk DataFile Version …', found '{header}'"),
        });
    }
    // The title (line 2) is free text; tokens start at line 3.
    let body_start = text
        .match_indices('\n')
        .nth(1)
        .map_or(text.len(), |(i, _)| i + 1);
    let body = &text[body_start..];
    let mut t = Tokens::from_line(file, body, 3);
    let format = t.next("ASCII or BINARY")?;
    if format != "ASCII" {
        return Err(t.error(format!(
            "only ASCII legacy files are read, found '{format}'"
        )));
    }
    t.expect("DATASET")?;
    match t.next("a dataset type")? {
        "UNSTRUCTURED_GRID" => grid(t).map(Dataset::Grid),
        "POLYDATA" => polydata(t).map(Dataset::Surface),
        other => Err(t.error(format!(
            "expected an UNSTRUCTURED_GRID or a POLYDATA surface, found '{other}'"
        ))),
    }
}

/// The points of a `POINTS n type` section.
fn points(t: &mut Tokens) -> Result<Vec<Point3<f64>>, ImportError> {
    let count: usize = t.parse("the number of points")?;
    let _kind = t.next("a data type")?;
    (0..count)
        .map(|_| {
            let p: [f64; 3] = [t.parse("x")?, t.parse("y")?, t.parse("z")?];
            match p.iter().all(|c| c.is_finite()) {
                true => Ok(Point3::from(p)),
                false => Err(t.error("a point has a non-finite coordinate")),
            }
        })
        .collect()
}

/// A polydata surface: its polygons fanned and its strips split into triangles; vertices and
/// lines are skipped.
fn polydata(mut t: Tokens) -> Result<SurfaceMesh, ImportError> {
    let mut surface = SurfaceMesh::default();
    while let Ok(keyword) = t.next("a section") {
        match keyword {
            "POINTS" => surface.vertices = points(&mut t)?,
            "POLYGONS" => {
                for polygon in read_cells(&mut t)? {
                    if polygon.len() < 3 {
                        return Err(t.error(format!("a polygon of {} points", polygon.len())));
                    }
                    for k in 1..polygon.len() - 1 {
                        surface
                            .triangles
                            .push([polygon[0], polygon[k], polygon[k + 1]]);
                    }
                }
            }
            "TRIANGLE_STRIPS" => {
                for strip in read_cells(&mut t)? {
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
                read_cells(&mut t)?;
            }
            "POINT_DATA" | "CELL_DATA" | "FIELD" | "METADATA" => break,
            other => return Err(t.error(format!("unexpected '{other}'"))),
        }
    }
    let count = surface.vertices.len();
    if let Some(f) = surface
        .triangles
        .iter()
        .find(|f| f.iter().any(|&v| v >= count))
    {
        return Err(t.error(format!("a polygon {f:?} names a point past the {count}")));
    }
    Ok(surface)
}

/// An unstructured grid's tetrahedra.
fn grid(mut t: Tokens) -> Result<RawMesh, ImportError> {
    let mut mesh = RawMesh::default();
    let mut cells: Vec<Vec<usize>> = Vec::new();
    let mut types: Vec<usize> = Vec::new();
    while let Ok(keyword) = t.next("a section") {
        match keyword {
            "POINTS" => mesh.nodes = points(&mut t)?,
            "CELLS" => cells = read_cells(&mut t)?,
            "CELL_TYPES" => {
                let count: usize = t.parse("the number of cell types")?;
                types = (0..count)
                    .map(|_| t.parse("a cell type"))
                    .collect::<Result<_, _>>()?;
            }
            // Point and cell data are not needed to simulate; stop reading there.
            "POINT_DATA" | "CELL_DATA" | "FIELD" | "METADATA" => break,
            other => return Err(t.error(format!("unexpected '{other}'"))),
        }
    }
    if types.len() != cells.len() {
        return Err(t.error(format!(
            "{} cells but {} cell types",
            cells.len(),
            types.len()
        )));
    }
    for (cell, kind) in cells.iter().zip(&types) {
        if *kind == VTK_TETRA {
            if cell.len() != 4 {
                return Err(t.error(format!("a tetrahedron with {} points", cell.len())));
            }
            mesh.tets.push([cell[0], cell[1], cell[2], cell[3]]);
        }
    }
    Ok(mesh)
}

/// Cells in either layout, as point-index lists.
fn read_cells(t: &mut Tokens) -> Result<Vec<Vec<usize>>, ImportError> {
    let first: usize = t.parse("the number of cells")?;
    let size: usize = t.parse("the size of the cell list")?;
    let next = t.next("cell data or OFFSETS")?;
    if next == "OFFSETS" {
        // Format 5: `first` counts offsets (cells + 1), `size` the connectivity length.
        let _type = t.next("an offsets data type")?;
        let offsets: Vec<usize> = (0..first)
            .map(|_| t.parse("an offset"))
            .collect::<Result<_, _>>()?;
        t.expect("CONNECTIVITY")?;
        let _type = t.next("a connectivity data type")?;
        let ids: Vec<usize> = (0..size)
            .map(|_| t.parse("a point index"))
            .collect::<Result<_, _>>()?;
        return offsets
            .windows(2)
            .map(|w| {
                ids.get(w[0]..w[1])
                    .map(<[usize]>::to_vec)
                    .ok_or_else(|| t.error(format!("offset {} beyond the connectivity list", w[1])))
            })
            .collect();
    }
    // Not reserved from the file's count: a damaged one would claim anything.
    let mut cells = Vec::new();
    let mut count: usize = next
        .parse()
        .map_err(|_| t.error(format!("expected a point count, found '{next}'")))?;
    for c in 0..first {
        if c > 0 {
            count = t.parse("a point count")?;
        }
        cells.push(
            (0..count)
                .map(|_| t.parse("a point index"))
                .collect::<Result<_, _>>()?,
        );
    }
    Ok(cells)
}
