//! Reading real meshes (Gmsh `.msh` v1, and v2/v4 ASCII and binary, VTK legacy `.vtk` grids
//! ASCII and binary, `.vtu`, and surfaces as segmentation tools write them, OBJ, STL, PLY and
//! VTK polydata, which are mended and tetrahedralized) and writing `.vtu` for ParaView.
//!
//! Every error names the file, and for text formats the line. A mesh that parses but cannot be
//! simulated (inverted or flat elements, a surface with holes) is refused with its quality
//! report's reason.

mod cursor;
pub mod intersections;
mod mend;
mod msh;
mod ply;
mod remesh;
mod surface;
mod tokens;
mod vtk;
mod vtu;
mod vtu_data;

use std::collections::{BTreeMap, HashSet};
use std::path::{Path, PathBuf};

use nalgebra::Point3;
use thiserror::Error;

use super::{MeshDensity, MeshError, QualityReport, RegionSelectors, Regions, Surface, TetMesh};
pub use intersections::{Crossing, Faces, self_crossing};
pub use mend::{MAX_HOLE_EDGES, Mended, mend};
pub use ply::read_ply;
pub use surface::{SurfaceMesh, read_obj, read_stl, tetrahedralize};
pub use vtu::write_vtu;

#[derive(Debug, Error)]
pub enum ImportError {
    #[error("{file}: {source}")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },
    #[error("{file}:{line}: {message}")]
    Syntax {
        file: String,
        line: usize,
        message: String,
    },
    #[error("{file}: byte {byte}: {message}")]
    Binary {
        file: String,
        byte: usize,
        message: String,
    },
    #[error("{file}: {message}")]
    Unsupported { file: String, message: String },
    #[error("{file}: the mesh cannot be simulated: {reason}")]
    Unusable { file: String, reason: String },
    #[error("{file}: {message}")]
    Selection { file: String, message: String },
    #[error(transparent)]
    Mesh(#[from] MeshError),
}

/// What a volume-mesh reader produces before validation.
#[derive(Default)]
struct RawMesh {
    nodes: Vec<Point3<f64>>,
    tets: Vec<[usize; 4]>,
    face_sets: BTreeMap<String, Vec<[usize; 3]>>,
    node_sets: BTreeMap<String, Vec<usize>>,
}

impl RawMesh {
    /// Checks indices, measures quality, meshes anew from its boundary (at about
    /// `remesh_nodes` nodes) what is too poorly shaped to solve, and refuses what cannot be
    /// simulated.
    fn into_mesh(self, file: &str, density: MeshDensity) -> Result<TetMesh, ImportError> {
        if let Some((t, _)) = self
            .tets
            .iter()
            .enumerate()
            .find(|(_, tet)| tet.iter().any(|&n| n >= self.nodes.len()))
        {
            return Err(ImportError::Unusable {
                file: file.to_owned(),
                reason: format!("tetrahedron {t} refers to a node that does not exist"),
            });
        }
        if self.tets.is_empty() {
            return Err(ImportError::Unusable {
                file: file.to_owned(),
                reason: "it has no tetrahedra (is it a surface mesh? OBJ and STL surfaces are tetrahedralized; other formats must hold a volume mesh)".into(),
            });
        }
        let report = QualityReport::measure(&self.nodes, &self.tets);
        // Slivers and needles, or flat elements, in a closed mesh: meshed anew from its
        // boundary; inverted elements (a tangle, or nodes in the wrong order) are refused.
        let mendable = report.inverted == 0
            && report.watertight()
            && (report.poorly_shaped() || report.degenerate > 0);
        if mendable {
            let (remeshed, said) = remesh::remesh(file, self, &report, density)?;
            eprintln!("{file}: mended: {said}");
            return remeshed.into_checked_mesh(file);
        }
        self.refused_or_regioned(file, &report)
    }

    /// [`Self::refused_or_regioned`] after measuring the quality.
    fn into_checked_mesh(self, file: &str) -> Result<TetMesh, ImportError> {
        let report = QualityReport::measure(&self.nodes, &self.tets);
        self.refused_or_regioned(file, &report)
    }

    /// Refused for the reason `report` gives, or the mesh with its regions completed.
    fn refused_or_regioned(
        self,
        file: &str,
        report: &QualityReport,
    ) -> Result<TetMesh, ImportError> {
        if let Some(reason) = report.refusal() {
            return Err(ImportError::Unusable {
                file: file.to_owned(),
                reason,
            });
        }
        // Formats that carry regions as node sets (VTK point data) give no faces.
        let faces_from_nodes = self.face_sets.is_empty();
        let mut node_sets = self.node_sets;
        for (name, faces) in &self.face_sets {
            node_sets
                .entry(name.clone())
                .or_insert_with(|| face_nodes(faces));
        }
        let regions = Regions {
            node_sets,
            face_sets: self.face_sets,
        };
        let mut mesh = TetMesh::new(file, self.nodes, self.tets, regions)?;
        if faces_from_nodes {
            add_surface_faces_of_node_sets(&mut mesh)?;
        }
        Ok(mesh)
    }
}

/// The nodes of `faces`, ascending, each once.
fn face_nodes(faces: &[[usize; 3]]) -> Vec<usize> {
    let mut nodes: Vec<usize> = faces.iter().flatten().copied().collect();
    nodes.sort_unstable();
    nodes.dedup();
    nodes
}

/// Gives each node set the face set of the boundary triangles whose corners all lie in it, if
/// there are any: a region given by its nodes (as VTK files give them) can then name where the
/// tool may load the surface (`accessible`), which a vademecum build takes as faces.
fn add_surface_faces_of_node_sets(mesh: &mut TetMesh) -> Result<(), MeshError> {
    let surface = Surface::extract(mesh);
    let derived: Vec<(String, Vec<[usize; 3]>)> = mesh
        .regions()
        .node_sets
        .iter()
        .map(|(name, nodes)| {
            let set: HashSet<usize> = nodes.iter().copied().collect();
            let faces = surface
                .triangles
                .iter()
                .filter(|face| face.iter().all(|n| set.contains(n)))
                .copied()
                .collect();
            (name.clone(), faces)
        })
        .filter(|(_, faces): &(String, Vec<[usize; 3]>)| !faces.is_empty())
        .collect();
    for (name, faces) in derived {
        mesh.set_face_set(&name, faces)?;
    }
    Ok(())
}

/// A mesh file and how its regions are found.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshFile {
    pub path: PathBuf,
    /// The clamped nodes and the accessible surface picked by where they are; none: the
    /// file's own `clamped` node set and `accessible` surface.
    pub regions: RegionSelectors,
}

impl MeshFile {
    /// A file that names its own regions.
    pub fn with_regions(path: PathBuf) -> Self {
        Self {
            path,
            regions: RegionSelectors::default(),
        }
    }
}

/// Options for reading a mesh file.
#[derive(Clone, Debug)]
pub struct ImportOptions {
    /// Multiplies coordinates: 0.001 for files in millimetres.
    pub scale: f64,
    /// How finely a surface is tetrahedralized, or a volume meshed anew from its boundary
    /// (its elements too poorly shaped to solve): about a node count, or an element size.
    pub density: MeshDensity,
    /// The clamped nodes and the accessible surface, picked by where they are (after
    /// `scale`); none: the file's own `clamped` and `accessible` regions.
    pub regions: RegionSelectors,
    /// The patient frame the file's coordinates are in; `None`: the one the file states
    /// (3D Slicer writes `SPACE=RAS` or `SPACE=LPS` in its header), else RAS.
    pub frame: Option<Frame>,
}

/// The patient frames 3D Slicer writes surfaces in. The trainer keeps meshes in RAS (x to the
/// patient's right, y anterior, z superior); LPS files are turned half a turn about z.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Frame {
    Ras,
    Lps,
}

impl std::str::FromStr for Frame {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "ras" => Ok(Self::Ras),
            "lps" => Ok(Self::Lps),
            _ => Err(format!(
                "`{s}` is no patient frame: ras (3D Slicer's own) or lps (DICOM's, and Slicer's \
                 files since 4.11)"
            )),
        }
    }
}

impl Frame {
    /// The frame a file states in its first kilobyte (`SPACE=RAS` or `SPACE=LPS`), if it
    /// states one.
    pub fn stated(bytes: &[u8]) -> Option<Self> {
        let head = String::from_utf8_lossy(&bytes[..bytes.len().min(1024)]).to_ascii_uppercase();
        match (head.contains("SPACE=LPS"), head.contains("SPACE=RAS")) {
            (true, false) => Some(Self::Lps),
            (false, true) => Some(Self::Ras),
            _ => None,
        }
    }
}

impl Default for ImportOptions {
    fn default() -> Self {
        Self {
            scale: 1.0,
            density: MeshDensity::Nodes(4_000),
            regions: RegionSelectors::default(),
            frame: None,
        }
    }
}

/// Reads a mesh file, choosing the format by extension.
pub fn load(path: &Path, options: &ImportOptions) -> Result<TetMesh, ImportError> {
    let bytes = std::fs::read(path).map_err(|source| ImportError::Io {
        file: path.display().to_string(),
        source,
    })?;
    parse(path, bytes, options)
}

/// Reads the `bytes` of the mesh file `path` (which names it in errors and gives the format
/// by its extension), its regions picked by `options.regions` when it gives any.
pub fn parse(path: &Path, bytes: Vec<u8>, options: &ImportOptions) -> Result<TetMesh, ImportError> {
    let mut mesh = read_mesh(path, bytes, options)?;
    if !options.regions.is_empty() {
        options
            .regions
            .apply(&mut mesh)
            .map_err(|message| ImportError::Selection {
                file: path.display().to_string(),
                message,
            })?;
    }
    Ok(mesh)
}

/// `surface` mended ([`mend`]: what was mended is said on the error stream) and
/// tetrahedralized.
fn mended_and_meshed(
    file: &str,
    surface: SurfaceMesh,
    options: &ImportOptions,
) -> Result<TetMesh, ImportError> {
    let (surface, mended) = mend(surface).map_err(|reason| ImportError::Unusable {
        file: file.to_owned(),
        reason,
    })?;
    if !mended.is_nothing() {
        eprintln!("{file}: mended: {mended}");
    }
    tetrahedralize(file, surface, options.density)
}

/// The mesh in the `bytes` of `path`, scaled and turned into RAS, with the regions it names.
fn read_mesh(path: &Path, bytes: Vec<u8>, options: &ImportOptions) -> Result<TetMesh, ImportError> {
    let file = path.display().to_string();
    let frame = (options.frame)
        .or_else(|| Frame::stated(&bytes))
        .unwrap_or(Frame::Ras);
    // Scaled, and from LPS half a turn about z (x and y reversed): a rotation, so the
    // surface keeps its orientation.
    let placed = |surface: SurfaceMesh| match frame {
        Frame::Ras => surface.scaled(options.scale),
        Frame::Lps => surface.scaled(options.scale).turned_about_z(),
    };
    let meshed = |surface: SurfaceMesh| mended_and_meshed(&file, placed(surface), options);
    let text = |bytes: Vec<u8>| {
        String::from_utf8(bytes).map_err(|e| ImportError::Unsupported {
            file: file.clone(),
            message: format!(
                "not UTF-8 text (byte {}); only ASCII files are read",
                e.utf8_error().valid_up_to()
            ),
        })
    };
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    let mut raw = match extension.as_str() {
        "msh" => msh::read(&file, &bytes)?,
        "vtk" => match vtk::read(&file, &bytes)? {
            vtk::Dataset::Grid(raw) => raw,
            vtk::Dataset::Surface(surface) => {
                return meshed(surface);
            }
        },
        "vtu" => vtu::read(&file, &bytes)?,
        "obj" => {
            let surface = read_obj(&file, &text(bytes)?)?;
            return meshed(surface);
        }
        "stl" => {
            let surface = read_stl(&file, &bytes)?;
            return meshed(surface);
        }
        "ply" => {
            let surface = read_ply(&file, &bytes)?;
            return meshed(surface);
        }
        _ => {
            return Err(ImportError::Unsupported {
                file,
                message: format!(
                    "unknown mesh format '.{extension}'; expected .msh, .vtk, .vtu, .obj, .stl or .ply"
                ),
            });
        }
    };
    let turn = match frame {
        Frame::Ras => 1.0,
        Frame::Lps => -1.0,
    };
    for p in &mut raw.nodes {
        let c = p.coords * options.scale;
        *p = Point3::new(turn * c.x, turn * c.y, c.z);
    }
    raw.into_mesh(&file, options.density)
}
