//! Picking an organ's regions by where they are: the nodes a clamp holds and the surface a tool
//! may touch, for a mesh whose file names no regions (a patient's organ from a segmentation).
//! A selector is a box, a sphere, the side of a plane, the faces turned towards a direction,
//! or a region the file names; several add up, and one written `Not` takes its part away.
//! Positions are in millimetres, in the mesh's frame after its import scale.

use std::collections::HashSet;
use std::str::FromStr;

use nalgebra::{Point3, Vector3};
use serde::{Deserialize, Serialize};

use super::TetMesh;
use super::boundary::{Surface, area_vector};
use super::organs::region;

/// One part of an organ, picked by where it is (millimetres).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Selector {
    /// Inside the box between two opposite corners: `x0, y0, z0, x1, y1, z1`.
    Box(f64, f64, f64, f64, f64, f64),
    /// Inside the sphere about a centre: `x, y, z, radius`.
    Sphere(f64, f64, f64, f64),
    /// On the side of the plane through a point that its normal points to:
    /// `x, y, z, nx, ny, nz`.
    Plane(f64, f64, f64, f64, f64, f64),
    /// The surface faces whose outward normal lies within an angle (degrees) of a
    /// direction, and their nodes: `nx, ny, nz, degrees`.
    Facing(f64, f64, f64, f64),
    /// A node or face set the mesh file names.
    Region(String),
    /// Takes its part away from what the others pick.
    Not(Box<Selector>),
}

/// The forms the command line takes, for messages.
pub const SELECTOR_FORMS: &str = "box:X0,Y0,Z0,X1,Y1,Z1, sphere:X,Y,Z,R, plane:X,Y,Z,NX,NY,NZ, \
    facing:NX,NY,NZ,DEG, region:NAME, or not:… before any of them (millimetres)";

impl FromStr for Selector {
    type Err = String;

    /// `box:…`, `sphere:…`, `plane:…`, `facing:…`, `region:NAME` or `not:…`.
    fn from_str(text: &str) -> Result<Self, String> {
        let refused = |why: &str| format!("`{text}`: {why}; a selector is {SELECTOR_FORMS}");
        let (kind, values) = text.split_once(':').ok_or_else(|| refused("no `:`"))?;
        if kind == "not" {
            let inner: Selector = values.parse().map_err(|e: String| refused(&e))?;
            let not = Self::Not(Box::new(inner));
            not.check().map_err(|e| refused(&e))?;
            return Ok(not);
        }
        if kind == "region" {
            return match values.is_empty() {
                true => Err(refused("a region needs its name")),
                false => Ok(Self::Region(values.to_owned())),
            };
        }
        let numbers: Vec<f64> = values
            .split(',')
            .map(|v| v.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
            .collect::<Option<_>>()
            .ok_or_else(|| refused("the values are numbers separated by commas"))?;
        let selector = match (kind, numbers.as_slice()) {
            ("box", &[x0, y0, z0, x1, y1, z1]) => Self::Box(x0, y0, z0, x1, y1, z1),
            ("sphere", &[x, y, z, r]) => Self::Sphere(x, y, z, r),
            ("plane", &[x, y, z, nx, ny, nz]) => Self::Plane(x, y, z, nx, ny, nz),
            ("facing", &[nx, ny, nz, deg]) => Self::Facing(nx, ny, nz, deg),
            ("box" | "sphere" | "plane" | "facing", _) => {
                return Err(refused("the wrong count of values"));
            }
            _ => return Err(refused(&format!("`{kind}` is no selector"))),
        };
        selector.check().map_err(|e| refused(&e))?;
        Ok(selector)
    }
}

impl std::fmt::Display for Selector {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Box(x0, y0, z0, x1, y1, z1) => write!(f, "box:{x0},{y0},{z0},{x1},{y1},{z1}"),
            Self::Sphere(x, y, z, r) => write!(f, "sphere:{x},{y},{z},{r}"),
            Self::Plane(x, y, z, nx, ny, nz) => write!(f, "plane:{x},{y},{z},{nx},{ny},{nz}"),
            Self::Facing(nx, ny, nz, deg) => write!(f, "facing:{nx},{ny},{nz},{deg}"),
            Self::Region(name) => write!(f, "region:{name}"),
            Self::Not(inner) => write!(f, "not:{inner}"),
        }
    }
}

/// Millimetres to the mesh's metres.
const MM: f64 = 1e-3;

impl Selector {
    /// Whether the selector's numbers make sense: a sphere's radius and a facing angle above
    /// zero, a plane's and a facing's direction not zero.
    pub fn check(&self) -> Result<(), String> {
        match self {
            Self::Sphere(.., r) if *r <= 0.0 => {
                Err(format!("a sphere's radius ({r} mm) is above 0"))
            }
            Self::Plane(_, _, _, nx, ny, nz) | Self::Facing(nx, ny, nz, _)
                if Vector3::new(*nx, *ny, *nz).norm() == 0.0 =>
            {
                Err("a direction is not (0, 0, 0)".into())
            }
            Self::Facing(.., deg) if !(*deg > 0.0 && *deg <= 180.0) => Err(format!(
                "a facing angle ({deg}°) is above 0 and at most 180"
            )),
            Self::Not(inner) if matches!(**inner, Self::Not(_)) => {
                Err("`not:not:…` takes nothing away".into())
            }
            Self::Not(inner) => inner.check(),
            _ => Ok(()),
        }
    }

    /// Whether the point `p` (m) lies in the selector's volume; `None` for a selector that
    /// is no volume (facing, region).
    fn holds(&self, p: &Point3<f64>) -> Option<bool> {
        let mm = p.coords / MM;
        Some(match self {
            Self::Box(x0, y0, z0, x1, y1, z1) => {
                let within = |v: f64, a: f64, b: f64| v >= a.min(b) && v <= a.max(b);
                within(mm.x, *x0, *x1) && within(mm.y, *y0, *y1) && within(mm.z, *z0, *z1)
            }
            Self::Sphere(x, y, z, r) => (mm - Vector3::new(*x, *y, *z)).norm() <= *r,
            Self::Plane(x, y, z, nx, ny, nz) => {
                (mm - Vector3::new(*x, *y, *z)).dot(&Vector3::new(*nx, *ny, *nz)) >= 0.0
            }
            _ => return None,
        })
    }
}

/// The selectors of an organ's two regions.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RegionSelectors {
    /// The nodes a clamp holds.
    #[serde(default)]
    pub clamp: Vec<Selector>,
    /// The surface the tool may touch; without any, every surface face none of whose nodes is
    /// clamped.
    #[serde(default)]
    pub accessible: Vec<Selector>,
}

/// What each selector picked, and what was set.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SelectionReport {
    /// Each clamp selector with the nodes it picked (before `Not`s took theirs away).
    pub clamp: Vec<(String, usize)>,
    /// Each accessible selector with the surface faces it picked.
    pub accessible: Vec<(String, usize)>,
    pub clamped_nodes: usize,
    pub accessible_faces: usize,
}

impl std::fmt::Display for SelectionReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "clamped: {} nodes", self.clamped_nodes)?;
        for (selector, nodes) in &self.clamp {
            writeln!(f, "  {selector}: {nodes} nodes")?;
        }
        writeln!(f, "accessible: {} surface faces", self.accessible_faces)?;
        for (selector, faces) in &self.accessible {
            writeln!(f, "  {selector}: {faces} faces")?;
        }
        Ok(())
    }
}

impl RegionSelectors {
    /// Whether any selector is given.
    pub fn is_empty(&self) -> bool {
        self.clamp.is_empty() && self.accessible.is_empty()
    }

    /// Sets the mesh's `clamped` node set and `accessible` face set from the selectors. A
    /// selector that picks nothing, a clamp that holds nothing (the organ would float) and an
    /// accessible surface with no face are refused, with what was picked and the organ's
    /// extent.
    pub fn apply(&self, mesh: &mut TetMesh) -> Result<SelectionReport, String> {
        for selector in self.clamp.iter().chain(&self.accessible) {
            selector.check().map_err(|e| format!("`{selector}`: {e}"))?;
        }
        let surface = Surface::extract(mesh);
        let faces = SurfaceFaces::of(mesh, &surface);
        let (clamped, clamp) = pick(&self.clamp, |s| faces.nodes_of(mesh, s))
            .map_err(|e| format!("clamp {e}; {}", extent(mesh)))?;
        if clamped.is_empty() {
            return Err(format!(
                "the clamp selectors hold no node: the organ would float; {}",
                extent(mesh)
            ));
        }
        let (accessible, picked) = match self.accessible.is_empty() {
            true => (faces.free_of(&clamped), Vec::new()),
            false => pick(&self.accessible, |s| faces.faces_of(mesh, s))
                .map_err(|e| format!("accessible {e}; {}", extent(mesh)))?,
        };
        if accessible.is_empty() {
            return Err(format!(
                "no surface face is accessible: the tool could touch nothing; {}",
                extent(mesh)
            ));
        }
        let report = SelectionReport {
            clamp,
            accessible: picked,
            clamped_nodes: clamped.len(),
            accessible_faces: accessible.len(),
        };
        let mut nodes: Vec<usize> = clamped.into_iter().collect();
        nodes.sort_unstable();
        let mut triangles: Vec<[usize; 3]> = accessible
            .into_iter()
            .map(|f| surface.triangles[f])
            .collect();
        triangles.sort_unstable();
        // What the file called by these names is replaced whole, its nodes and its faces.
        mesh.remove_region(region::CLAMPED);
        mesh.remove_region(region::ACCESSIBLE);
        mesh.set_node_set(region::CLAMPED, nodes)
            .map_err(|e| e.to_string())?;
        mesh.set_face_set(region::ACCESSIBLE, triangles)
            .map_err(|e| e.to_string())?;
        Ok(report)
    }
}

/// What selectors picked (node or surface-face numbers), with each selector's count.
type Picked = (HashSet<usize>, Vec<(String, usize)>);

/// The union of what the positive selectors pick less what the `Not`s pick, with each
/// selector's count; a selector that picks nothing is refused.
fn pick(
    selectors: &[Selector],
    mut picked_by: impl FnMut(&Selector) -> Result<HashSet<usize>, String>,
) -> Result<Picked, String> {
    let (mut chosen, mut removed, mut counts) = (HashSet::new(), HashSet::new(), Vec::new());
    for selector in selectors {
        let (inner, into) = match selector {
            Selector::Not(inner) => (&**inner, &mut removed),
            positive => (positive, &mut chosen),
        };
        let set = picked_by(inner)?;
        if set.is_empty() {
            return Err(format!("`{selector}` picks nothing"));
        }
        counts.push((selector.to_string(), set.len()));
        into.extend(set);
    }
    chosen.retain(|k| !removed.contains(k));
    Ok((chosen, counts))
}

/// The mesh's surface faces with their outward unit normals.
struct SurfaceFaces<'a> {
    surface: &'a Surface,
    normals: Vec<Vector3<f64>>,
}

impl<'a> SurfaceFaces<'a> {
    fn of(mesh: &TetMesh, surface: &'a Surface) -> Self {
        let normals = (surface.triangles.iter())
            .map(|f| area_vector(mesh.nodes(), f).normalize())
            .collect();
        Self { surface, normals }
    }

    /// The surface faces (their places in the surface's list) turned within `degrees` of
    /// the direction `n`.
    fn facing(&self, n: Vector3<f64>, degrees: f64) -> HashSet<usize> {
        let cos = degrees.to_radians().cos();
        let n = n.normalize();
        (0..self.normals.len())
            .filter(|&f| self.normals[f].dot(&n) >= cos - 1e-12)
            .collect()
    }

    /// The nodes `selector` picks.
    fn nodes_of(&self, mesh: &TetMesh, selector: &Selector) -> Result<HashSet<usize>, String> {
        if let Some(nodes) = volume_nodes(mesh, selector) {
            return Ok(nodes);
        }
        match selector {
            Selector::Facing(nx, ny, nz, deg) => Ok((self
                .facing(Vector3::new(*nx, *ny, *nz), *deg))
            .into_iter()
            .flat_map(|f| self.surface.triangles[f])
            .collect()),
            Selector::Region(name) => region_nodes(mesh, name),
            _ => unreachable!("volumes are picked above, `Not`s by the caller"),
        }
    }

    /// The surface faces `selector` picks: those all of whose corners it picks, or those
    /// facing its direction.
    fn faces_of(&self, mesh: &TetMesh, selector: &Selector) -> Result<HashSet<usize>, String> {
        let corners_in = |nodes: &HashSet<usize>| -> HashSet<usize> {
            (0..self.surface.triangles.len())
                .filter(|&f| self.surface.triangles[f].iter().all(|n| nodes.contains(n)))
                .collect()
        };
        if let Some(nodes) = volume_nodes(mesh, selector) {
            return Ok(corners_in(&nodes));
        }
        match selector {
            Selector::Facing(nx, ny, nz, deg) => Ok(self.facing(Vector3::new(*nx, *ny, *nz), *deg)),
            Selector::Region(name) => match mesh.regions().face_sets.get(name) {
                Some(set) => {
                    let wanted: HashSet<[usize; 3]> = set.iter().map(|f| sorted(*f)).collect();
                    Ok((0..self.surface.triangles.len())
                        .filter(|&f| wanted.contains(&sorted(self.surface.triangles[f])))
                        .collect())
                }
                None => Ok(corners_in(&region_nodes(mesh, name)?)),
            },
            _ => unreachable!("volumes are picked above, `Not`s by the caller"),
        }
    }

    /// The surface faces none of whose corners is in `clamped`.
    fn free_of(&self, clamped: &HashSet<usize>) -> HashSet<usize> {
        (0..self.surface.triangles.len())
            .filter(|&f| {
                !self.surface.triangles[f]
                    .iter()
                    .any(|n| clamped.contains(n))
            })
            .collect()
    }
}

/// The nodes inside a volume selector (box, sphere, plane); `None` for another kind.
fn volume_nodes(mesh: &TetMesh, selector: &Selector) -> Option<HashSet<usize>> {
    selector.holds(&Point3::origin())?;
    Some(
        (0..mesh.node_count())
            .filter(|&n| selector.holds(&mesh.nodes()[n]) == Some(true))
            .collect(),
    )
}

/// The nodes of the region `name`: a node set, else the corners of a face set.
fn region_nodes(mesh: &TetMesh, name: &str) -> Result<HashSet<usize>, String> {
    let regions = mesh.regions();
    if let Some(nodes) = regions.node_sets.get(name) {
        return Ok(nodes.iter().copied().collect());
    }
    match regions.face_sets.get(name) {
        Some(faces) => Ok(faces.iter().flatten().copied().collect()),
        None => {
            let known: Vec<&String> = regions
                .node_sets
                .keys()
                .chain(regions.face_sets.keys())
                .collect();
            Err(format!(
                "`region:{name}`: the mesh has no region `{name}` (it has: {})",
                match known.is_empty() {
                    true => "none".to_owned(),
                    false => known
                        .iter()
                        .map(|k| k.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                }
            ))
        }
    }
}

fn sorted(mut face: [usize; 3]) -> [usize; 3] {
    face.sort_unstable();
    face
}

/// The organ's extent in millimetres, for the hints of refusals.
fn extent(mesh: &TetMesh) -> String {
    let (mut lo, mut hi) = (
        Vector3::repeat(f64::INFINITY),
        Vector3::repeat(f64::NEG_INFINITY),
    );
    for p in mesh.nodes() {
        lo = lo.inf(&p.coords);
        hi = hi.sup(&p.coords);
    }
    let (lo, hi) = (lo / MM, hi / MM);
    format!(
        "the organ spans x {:.1} to {:.1}, y {:.1} to {:.1}, z {:.1} to {:.1} mm",
        lo.x, hi.x, lo.y, hi.y, lo.z, hi.z
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::box_mesh;

    /// A 40 × 20 × 10 mm box in 10 mm cubes: 5 × 3 × 2 nodes.
    fn block() -> TetMesh {
        box_mesh([0.040, 0.020, 0.010], [4, 2, 1]).unwrap()
    }

    fn nodes(mesh: &TetMesh, text: &str) -> Vec<usize> {
        let surface = Surface::extract(mesh);
        let faces = SurfaceFaces::of(mesh, &surface);
        let selector: Selector = text.parse().unwrap();
        let mut picked: Vec<usize> = faces
            .nodes_of(mesh, &selector)
            .unwrap()
            .into_iter()
            .collect();
        picked.sort_unstable();
        picked
    }

    fn set(mesh: &TetMesh, name: &str) -> Vec<usize> {
        mesh.node_set(name).unwrap().to_vec()
    }

    #[test]
    fn each_selector_picks_exactly_its_nodes() {
        let mesh = block();
        assert_eq!(nodes(&mesh, "box:-1,-1,-1,1,21,11"), set(&mesh, "x0"));
        assert_eq!(nodes(&mesh, "box:41,21,11,39,-1,-1"), set(&mesh, "x1"));
        assert_eq!(nodes(&mesh, "plane:35,0,0,1,0,0"), set(&mesh, "x1"));
        assert_eq!(nodes(&mesh, "plane:0,0,5,0,0,-1"), set(&mesh, "z0"));
        assert_eq!(nodes(&mesh, "facing:0,0,1,10"), set(&mesh, "z1"));
        assert_eq!(nodes(&mesh, "region:y1"), set(&mesh, "y1"));
        // Within 10.5 mm of the corner: the corner and its three neighbours along the edges.
        assert_eq!(nodes(&mesh, "sphere:0,0,0,10.5").len(), 4);
    }

    #[test]
    fn selectors_add_up_and_not_takes_away() {
        let mut mesh = block();
        let selectors = RegionSelectors {
            clamp: ["region:x0", "region:x1", "not:facing:0,0,1,1"]
                .map(|s| s.parse().unwrap())
                .to_vec(),
            accessible: ["facing:0,0,1,1", "not:box:-1,-1,-1,10.5,21,11"]
                .map(|s| s.parse().unwrap())
                .to_vec(),
        };
        let report = selectors.apply(&mut mesh).unwrap();
        // Both ends, less their top edges: 2 × 3 nodes at z = 0.
        let clamped = mesh.node_set(region::CLAMPED).unwrap();
        assert_eq!(clamped.len(), 6);
        assert!(clamped.iter().all(|&n| mesh.nodes()[n].z == 0.0));
        // The top's 16 triangles less the 4 over the first 10 mm cell column.
        assert_eq!(report.accessible_faces, 12);
        let z1: HashSet<[usize; 3]> = mesh
            .face_set("z1")
            .unwrap()
            .iter()
            .map(|f| sorted(*f))
            .collect();
        let accessible = mesh.face_set(region::ACCESSIBLE).unwrap();
        assert!(accessible.iter().all(|f| z1.contains(&sorted(*f))));
        assert_eq!(report.clamp[0], ("region:x0".to_owned(), 6));
    }

    #[test]
    fn without_accessible_selectors_the_free_surface_is_accessible() {
        let mut mesh = block();
        let selectors = RegionSelectors {
            clamp: vec!["region:z0".parse().unwrap()],
            accessible: Vec::new(),
        };
        selectors.apply(&mut mesh).unwrap();
        let clamped: HashSet<usize> = mesh
            .node_set(region::CLAMPED)
            .unwrap()
            .iter()
            .copied()
            .collect();
        let surface = Surface::extract(&mesh);
        let free = surface
            .triangles
            .iter()
            .filter(|f| !f.iter().any(|n| clamped.contains(n)));
        assert_eq!(
            mesh.face_set(region::ACCESSIBLE).unwrap().len(),
            free.count()
        );
    }

    #[test]
    fn an_empty_or_floating_selection_is_refused_with_the_extent() {
        let mut mesh = block();
        let far = RegionSelectors {
            clamp: vec!["box:100,100,100,200,200,200".parse().unwrap()],
            accessible: Vec::new(),
        };
        let error = far.apply(&mut mesh).unwrap_err();
        assert!(
            error.contains("box:100,100,100,200,200,200` picks nothing"),
            "{error}"
        );
        assert!(error.contains("x 0.0 to 40.0"), "{error}");
        let floating = RegionSelectors {
            clamp: ["region:x0", "not:region:x0"]
                .map(|s| s.parse().unwrap())
                .to_vec(),
            accessible: Vec::new(),
        };
        let error = floating.apply(&mut mesh).unwrap_err();
        assert!(error.contains("would float"), "{error}");
        let unknown = RegionSelectors {
            clamp: vec!["region:base".parse().unwrap()],
            accessible: Vec::new(),
        };
        let error = unknown.apply(&mut mesh).unwrap_err();
        assert!(
            error.contains("no region `base`") && error.contains("x0"),
            "{error}"
        );
    }

    #[test]
    fn selectors_are_read_from_text_or_refused() {
        let read = |s: &str| s.parse::<Selector>();
        assert_eq!(
            read("sphere:1,2,3,4"),
            Ok(Selector::Sphere(1.0, 2.0, 3.0, 4.0))
        );
        assert_eq!(
            read("not:region:vena cava"),
            Ok(Selector::Not(Box::new(Selector::Region(
                "vena cava".into()
            ))))
        );
        assert_eq!(
            read("facing:0,0,1,30").unwrap().to_string(),
            "facing:0,0,1,30"
        );
        for bad in [
            "box:1,2,3",
            "sphere:0,0,0,-1",
            "facing:0,0,0,30",
            "facing:0,0,1,0",
            "cube:1,2,3,4,5,6",
            "box:a,b,c,d,e,f",
            "region:",
            "not:not:region:x",
            "x0",
        ] {
            let error = read(bad).unwrap_err();
            assert!(error.contains(bad) && error.contains("box:X0"), "{error}");
        }
    }
}
