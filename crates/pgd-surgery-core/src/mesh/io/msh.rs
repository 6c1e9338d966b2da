//! Gmsh `.msh`, ASCII versions 1, 2.2 and 4.1. Tetrahedra (type 4) make the mesh; triangles
//! (type 2) in physical groups become face sets named after the group (version 1 names none:
//! `physical_<number>`).

use std::collections::{BTreeMap, HashMap};

use nalgebra::Point3;

use super::tokens::Tokens;
use super::{ImportError, RawMesh};

const TRIANGLE: usize = 2;
const TETRAHEDRON: usize = 4;

pub(super) fn read(file: &str, text: &str) -> Result<RawMesh, ImportError> {
    let mut t = Tokens::new(file, text);
    if text.trim_start().starts_with("$NOD") {
        return read_v1(t);
    }
    t.expect("$MeshFormat")?;
    let version: f64 = t.parse("a format version")?;
    let binary: u8 = t.parse("the file type (0 = ASCII)")?;
    let _size: usize = t.parse("the data size")?;
    if binary != 0 {
        return Err(t.error(
            "binary .msh files are not read; save the mesh as ASCII (Gmsh: Mesh.Binary = 0)",
        ));
    }
    t.expect("$EndMeshFormat")?;
    let major = version.floor() as u32;
    if major != 2 && major != 4 {
        return Err(t.error(format!(
            "Gmsh format version {version} is not read; save as version 2.2 or 4.1"
        )));
    }
    let mut reader = Reader::default();
    while let Ok(section) = t.next("a section") {
        match (section, major) {
            ("$PhysicalNames", _) => reader.physical_names(&mut t)?,
            ("$Entities", 4) => reader.entities(&mut t)?,
            ("$Nodes", 2) => reader.nodes_v2(&mut t)?,
            ("$Nodes", _) => reader.nodes_v4(&mut t)?,
            ("$Elements", 2) => reader.elements_v2(&mut t)?,
            ("$Elements", _) => reader.elements_v4(&mut t)?,
            (other, _) if other.starts_with("$") && !other.starts_with("$End") => {
                let end = format!("$End{}", &other[1..]);
                t.skip_past(&end)?;
            }
            (other, _) => {
                return Err(t.error(format!(
                    "expected a section such as $Nodes, found '{other}'"
                )));
            }
        }
    }
    Ok(reader.finish())
}

/// Version 1: `$NOD` (count, then `tag x y z`) and `$ELM` (count, then `tag type physical
/// elementary node-count nodes…`).
fn read_v1(mut t: Tokens) -> Result<RawMesh, ImportError> {
    let mut reader = Reader::default();
    t.expect("$NOD")?;
    let count: usize = t.parse("the number of nodes")?;
    for _ in 0..count {
        let tag: usize = t.parse("a node tag")?;
        let p = Reader::point(&mut t)?;
        reader.add_node(&t, tag, p)?;
    }
    t.expect("$ENDNOD")?;
    t.expect("$ELM")?;
    let count: usize = t.parse("the number of elements")?;
    for _ in 0..count {
        let _tag: usize = t.parse("an element tag")?;
        let kind: usize = t.parse("an element type")?;
        let physical: usize = t.parse("a physical group")?;
        let _elementary: usize = t.parse("an elementary entity")?;
        let nodes: usize = t.parse("the number of nodes")?;
        let expected = match kind {
            TRIANGLE => Some(3),
            TETRAHEDRON => Some(4),
            _ => None,
        };
        if expected.is_some_and(|n| n != nodes) {
            return Err(t.error(format!("an element of type {kind} with {nodes} nodes")));
        }
        reader.element(&mut t, kind, (physical != 0).then_some(physical))?;
    }
    t.expect("$ENDELM")?;
    Ok(reader.finish())
}

#[derive(Default)]
struct Reader {
    names: HashMap<usize, String>,
    /// Physical tags of each surface entity (v4).
    surface_physicals: HashMap<usize, Vec<usize>>,
    node_index: HashMap<usize, usize>,
    mesh: RawMesh,
    faces: BTreeMap<usize, Vec<[usize; 3]>>,
}

impl Reader {
    fn physical_names(&mut self, t: &mut Tokens) -> Result<(), ImportError> {
        let count: usize = t.parse("the number of physical names")?;
        for _ in 0..count {
            let _dim: usize = t.parse("a dimension")?;
            let tag: usize = t.parse("a physical tag")?;
            let name = t.rest_of_line();
            self.names.insert(tag, name.trim_matches('"').to_owned());
        }
        t.expect("$EndPhysicalNames")
    }

    fn entities(&mut self, t: &mut Tokens) -> Result<(), ImportError> {
        let counts: [usize; 4] = [
            t.parse("the number of points")?,
            t.parse("the number of curves")?,
            t.parse("the number of surfaces")?,
            t.parse("the number of volumes")?,
        ];
        for (dim, &count) in counts.iter().enumerate() {
            for _ in 0..count {
                let tag: usize = t.parse("an entity tag")?;
                let coordinates = if dim == 0 { 3 } else { 6 };
                for _ in 0..coordinates {
                    t.parse::<f64>("a coordinate")?;
                }
                let physical_count: usize = t.parse("the number of physical tags")?;
                // Not reserved from the file's count: a damaged one would claim anything.
                let mut physicals = Vec::new();
                for _ in 0..physical_count {
                    physicals.push(t.parse::<i64>("a physical tag")?.unsigned_abs() as usize);
                }
                if dim > 0 {
                    let bounding: usize = t.parse("the number of bounding entities")?;
                    for _ in 0..bounding {
                        t.parse::<i64>("a bounding entity tag")?;
                    }
                }
                if dim == 2 {
                    self.surface_physicals.insert(tag, physicals);
                }
            }
        }
        t.expect("$EndEntities")
    }

    fn add_node(&mut self, t: &Tokens, tag: usize, p: [f64; 3]) -> Result<(), ImportError> {
        if !p.iter().all(|c| c.is_finite()) {
            return Err(t.error(format!("node {tag} has a non-finite coordinate")));
        }
        if self.node_index.insert(tag, self.mesh.nodes.len()).is_some() {
            return Err(t.error(format!("node {tag} is defined twice")));
        }
        self.mesh.nodes.push(Point3::from(p));
        Ok(())
    }

    fn point(t: &mut Tokens) -> Result<[f64; 3], ImportError> {
        Ok([t.parse("x")?, t.parse("y")?, t.parse("z")?])
    }

    fn nodes_v2(&mut self, t: &mut Tokens) -> Result<(), ImportError> {
        let count: usize = t.parse("the number of nodes")?;
        for _ in 0..count {
            let tag: usize = t.parse("a node tag")?;
            let p = Self::point(t)?;
            self.add_node(t, tag, p)?;
        }
        t.expect("$EndNodes")
    }

    fn nodes_v4(&mut self, t: &mut Tokens) -> Result<(), ImportError> {
        let blocks: usize = t.parse("the number of node blocks")?;
        let _total: usize = t.parse("the number of nodes")?;
        let _min: usize = t.parse("the smallest node tag")?;
        let _max: usize = t.parse("the largest node tag")?;
        for _ in 0..blocks {
            let _dim: usize = t.parse("an entity dimension")?;
            let _entity: usize = t.parse("an entity tag")?;
            let parametric: usize = t.parse("the parametric flag")?;
            if parametric != 0 {
                return Err(t.error("parametric node coordinates are not read; save without them"));
            }
            let count: usize = t.parse("the number of nodes in the block")?;
            let tags: Vec<usize> = (0..count)
                .map(|_| t.parse("a node tag"))
                .collect::<Result<_, _>>()?;
            for tag in tags {
                let p = Self::point(t)?;
                self.add_node(t, tag, p)?;
            }
        }
        t.expect("$EndNodes")
    }

    fn node(&self, t: &Tokens, tag: usize) -> Result<usize, ImportError> {
        self.node_index.get(&tag).copied().ok_or_else(|| {
            t.error(format!(
                "element refers to node {tag}, which is not defined"
            ))
        })
    }

    fn element(
        &mut self,
        t: &mut Tokens,
        kind: usize,
        physical: Option<usize>,
    ) -> Result<(), ImportError> {
        let nodes = match kind {
            TRIANGLE => 3,
            TETRAHEDRON => 4,
            1 => 2,
            15 => 1,
            3 => 4,
            _ => {
                return Err(t.error(format!(
                    "element type {kind} is not read; use linear tetrahedra (type 4) and triangles (type 2)"
                )));
            }
        };
        let tags: Vec<usize> = (0..nodes)
            .map(|_| t.parse("a node tag"))
            .collect::<Result<_, _>>()?;
        let ids: Vec<usize> = tags
            .iter()
            .map(|&tag| self.node(t, tag))
            .collect::<Result<_, _>>()?;
        match kind {
            TETRAHEDRON => self.mesh.tets.push([ids[0], ids[1], ids[2], ids[3]]),
            TRIANGLE => {
                if let Some(p) = physical {
                    self.faces
                        .entry(p)
                        .or_default()
                        .push([ids[0], ids[1], ids[2]]);
                }
            }
            _ => {}
        }
        Ok(())
    }

    fn elements_v2(&mut self, t: &mut Tokens) -> Result<(), ImportError> {
        let count: usize = t.parse("the number of elements")?;
        for _ in 0..count {
            let _tag: usize = t.parse("an element tag")?;
            let kind: usize = t.parse("an element type")?;
            let tag_count: usize = t.parse("the number of tags")?;
            let tags: Vec<i64> = (0..tag_count)
                .map(|_| t.parse("an element tag"))
                .collect::<Result<_, _>>()?;
            let physical = tags
                .first()
                .map(|&p| p.unsigned_abs() as usize)
                .filter(|&p| p != 0);
            self.element(t, kind, physical)?;
        }
        t.expect("$EndElements")
    }

    fn elements_v4(&mut self, t: &mut Tokens) -> Result<(), ImportError> {
        let blocks: usize = t.parse("the number of element blocks")?;
        let _total: usize = t.parse("the number of elements")?;
        let _min: usize = t.parse("the smallest element tag")?;
        let _max: usize = t.parse("the largest element tag")?;
        for _ in 0..blocks {
            let dim: usize = t.parse("an entity dimension")?;
            let entity: usize = t.parse("an entity tag")?;
            let kind: usize = t.parse("an element type")?;
            let count: usize = t.parse("the number of elements in the block")?;
            let physical = if dim == 2 {
                self.surface_physicals
                    .get(&entity)
                    .and_then(|p| p.first().copied())
            } else {
                None
            };
            for _ in 0..count {
                let _tag: usize = t.parse("an element tag")?;
                self.element(t, kind, physical)?;
            }
        }
        t.expect("$EndElements")
    }

    fn finish(mut self) -> RawMesh {
        for (physical, faces) in self.faces {
            let name = self
                .names
                .get(&physical)
                .cloned()
                .unwrap_or_else(|| format!("physical_{physical}"));
            self.mesh.face_sets.insert(name, faces);
        }
        self.mesh
    }
}
