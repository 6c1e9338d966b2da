//! Gmsh `.msh`: versions 1 (ASCII), 2.2 and 4.1, ASCII and binary. Tetrahedra (type 4) make
//! the mesh; triangles (type 2) in physical groups become face sets named after the group
//! (version 1 names none: `physical_<number>`).
//!
//! One reader serves both encodings through [`Fields`]: a binary file is the ASCII layout
//! with its numbers written as bytes (an `int` in 4, a `size_t` in the header's data size, a
//! `double` in 8), its section names and a few counts still as text.

use std::collections::{BTreeMap, HashMap};

use nalgebra::Point3;

use super::cursor::Cursor;
use super::tokens::Tokens;
use super::{ImportError, RawMesh};

const TRIANGLE: usize = 2;
const TETRAHEDRON: usize = 4;

pub(super) fn read(file: &str, bytes: &[u8]) -> Result<RawMesh, ImportError> {
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(64)]);
    if head.trim_start().starts_with("$NOD") {
        return read_v1(Tokens::new(file, &text(file, bytes)?));
    }
    let mut header = Binary::new(file, bytes);
    header.expect("$MeshFormat")?;
    let version: f64 = header.ascii("a format version")?;
    let binary: u8 = header.ascii("the file type (0 = ASCII, 1 = binary)")?;
    let size_bytes: usize = header.ascii("the data size")?;
    let major = version.floor() as u32;
    if major != 2 && major != 4 {
        return Err(header.error(format!(
            "Gmsh format version {version} is not read; save as version 2.2 or 4.1"
        )));
    }
    if binary == 0 {
        let text = text(file, bytes)?;
        let mut t = Tokens::new(file, &text);
        t.expect("$MeshFormat")?;
        for what in ["a format version", "the file type", "the data size"] {
            t.next(what)?;
        }
        return read_sections(&mut t, major, false);
    }
    if size_bytes != 4 && size_bytes != 8 {
        return Err(header.error(format!("a data size of {size_bytes} bytes is not read")));
    }
    header.endianness(size_bytes)?;
    read_sections(&mut header, major, true)
}

/// The file as text, or an error saying it is not.
fn text(file: &str, bytes: &[u8]) -> Result<String, ImportError> {
    String::from_utf8(bytes.to_vec()).map_err(|e| ImportError::Unsupported {
        file: file.to_owned(),
        message: format!(
            "not UTF-8 text (byte {}), and not a binary .msh file",
            e.utf8_error().valid_up_to()
        ),
    })
}

/// The sections after the format's (whose end `f` has not yet passed).
fn read_sections(f: &mut impl Fields, major: u32, binary: bool) -> Result<RawMesh, ImportError> {
    f.expect("$EndMeshFormat")?;
    let mut reader = Reader::default();
    while let Some(section) = f.section()? {
        match (section.as_str(), major) {
            ("$PhysicalNames", _) => reader.physical_names(f)?,
            ("$Entities", 4) => reader.entities(f)?,
            ("$Nodes", 2) => reader.nodes_v2(f)?,
            ("$Nodes", _) => reader.nodes_v4(f)?,
            ("$Elements", 2) if binary => reader.elements_v2_binary(f)?,
            ("$Elements", 2) => reader.elements_v2(f)?,
            ("$Elements", _) => reader.elements_v4(f)?,
            (other, _) if other.starts_with("$") && !other.starts_with("$End") => {
                let end = format!("$End{}", &other[1..]);
                f.skip_past(&end)?;
            }
            (other, _) => {
                return Err(f.error(format!(
                    "expected a section such as $Nodes, found '{other}'"
                )));
            }
        }
    }
    Ok(reader.finish())
}

/// Where the reader takes a file's fields from, each named by what it is in errors.
trait Fields {
    /// An `int` (4 bytes in a binary file).
    fn int(&mut self, what: &str) -> Result<i64, ImportError>;
    /// A `size_t` (the header's data size in a binary file).
    fn size(&mut self, what: &str) -> Result<usize, ImportError>;
    /// A `double` (8 bytes in a binary file).
    fn real(&mut self, what: &str) -> Result<f64, ImportError>;
    /// A field written as text in either encoding.
    fn ascii<T: std::str::FromStr>(&mut self, what: &str) -> Result<T, ImportError>;
    /// The rest of the line as text.
    fn rest_of_line(&mut self) -> String;
    fn expect(&mut self, keyword: &str) -> Result<(), ImportError>;
    fn skip_past(&mut self, keyword: &str) -> Result<(), ImportError>;
    /// The next section's name; `None` at the end of the file.
    fn section(&mut self) -> Result<Option<String>, ImportError>;
    fn error(&self, message: String) -> ImportError;
}

impl Fields for Tokens<'_> {
    fn int(&mut self, what: &str) -> Result<i64, ImportError> {
        self.parse(what)
    }

    fn size(&mut self, what: &str) -> Result<usize, ImportError> {
        self.parse(what)
    }

    fn real(&mut self, what: &str) -> Result<f64, ImportError> {
        self.parse(what)
    }

    fn ascii<T: std::str::FromStr>(&mut self, what: &str) -> Result<T, ImportError> {
        self.parse(what)
    }

    fn rest_of_line(&mut self) -> String {
        Tokens::rest_of_line(self)
    }

    fn expect(&mut self, keyword: &str) -> Result<(), ImportError> {
        Tokens::expect(self, keyword)
    }

    fn skip_past(&mut self, keyword: &str) -> Result<(), ImportError> {
        Tokens::skip_past(self, keyword)
    }

    fn section(&mut self) -> Result<Option<String>, ImportError> {
        Ok(self.next("a section").ok().map(str::to_owned))
    }

    fn error(&self, message: String) -> ImportError {
        Tokens::error(self, message)
    }
}

/// A binary `.msh` file: numbers in the header's byte order and `size_t` width.
struct Binary<'a> {
    cursor: Cursor<'a>,
    size_bytes: usize,
}

impl<'a> Binary<'a> {
    fn new(file: &'a str, bytes: &'a [u8]) -> Self {
        Self {
            cursor: Cursor::new(file, bytes, true),
            size_bytes: 8,
        }
    }

    /// Reads the header's `int` 1, whose bytes say the file's byte order.
    fn endianness(&mut self, size_bytes: usize) -> Result<(), ImportError> {
        self.size_bytes = size_bytes;
        let one: [u8; 4] = self.cursor.take("the byte-order mark (an int 1)")?;
        let little_endian = match one {
            [1, 0, 0, 0] => true,
            [0, 0, 0, 1] => false,
            _ => return Err(self.error(format!("the byte-order mark reads {one:?}, not 1"))),
        };
        self.cursor.set_little_endian(little_endian);
        Ok(())
    }
}

impl Fields for Binary<'_> {
    fn int(&mut self, what: &str) -> Result<i64, ImportError> {
        Ok(i32::from_le_bytes(self.cursor.take(what)?).into())
    }

    fn size(&mut self, what: &str) -> Result<usize, ImportError> {
        let value = match self.size_bytes {
            4 => u64::from(u32::from_le_bytes(self.cursor.take(what)?)),
            _ => u64::from_le_bytes(self.cursor.take(what)?),
        };
        usize::try_from(value).map_err(|_| self.error(format!("{what} {value} is too large")))
    }

    fn real(&mut self, what: &str) -> Result<f64, ImportError> {
        Ok(f64::from_le_bytes(self.cursor.take(what)?))
    }

    fn ascii<T: std::str::FromStr>(&mut self, what: &str) -> Result<T, ImportError> {
        self.cursor.parse(what)
    }

    fn rest_of_line(&mut self) -> String {
        self.cursor.rest_of_line()
    }

    fn expect(&mut self, keyword: &str) -> Result<(), ImportError> {
        let word = self.cursor.word(keyword)?;
        match word == keyword {
            true => Ok(()),
            false => Err(self.error(format!("expected '{keyword}', found '{word}'"))),
        }
    }

    fn skip_past(&mut self, keyword: &str) -> Result<(), ImportError> {
        self.cursor.skip_past(keyword)
    }

    fn section(&mut self) -> Result<Option<String>, ImportError> {
        if self.cursor.at_end() {
            return Ok(None);
        }
        self.cursor.word("a section").map(|w| Some(w.to_owned()))
    }

    fn error(&self, message: String) -> ImportError {
        self.cursor.error(message)
    }
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
        if nodes_of(kind).is_some_and(|n| n != nodes) {
            return Err(t.error(format!("an element of type {kind} with {nodes} nodes")));
        }
        let tags = Reader::int_tags(&mut t, kind)?;
        reader.element(&t, kind, (physical != 0).then_some(physical), &tags)?;
    }
    t.expect("$ENDELM")?;
    Ok(reader.finish())
}

/// The nodes of an element of type `kind`, for the types read (points, lines, triangles,
/// quadrangles, tetrahedra).
fn nodes_of(kind: usize) -> Option<usize> {
    match kind {
        15 => Some(1),
        1 => Some(2),
        TRIANGLE => Some(3),
        3 | TETRAHEDRON => Some(4),
        _ => None,
    }
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
    fn physical_names(&mut self, f: &mut impl Fields) -> Result<(), ImportError> {
        let count: usize = f.ascii("the number of physical names")?;
        for _ in 0..count {
            let _dim: usize = f.ascii("a dimension")?;
            let tag: usize = f.ascii("a physical tag")?;
            let name = f.rest_of_line();
            self.names.insert(tag, name.trim_matches('"').to_owned());
        }
        f.expect("$EndPhysicalNames")
    }

    fn entities(&mut self, f: &mut impl Fields) -> Result<(), ImportError> {
        let counts: [usize; 4] = [
            f.size("the number of points")?,
            f.size("the number of curves")?,
            f.size("the number of surfaces")?,
            f.size("the number of volumes")?,
        ];
        for (dim, &count) in counts.iter().enumerate() {
            for _ in 0..count {
                let tag = f.int("an entity tag")?.unsigned_abs() as usize;
                let coordinates = if dim == 0 { 3 } else { 6 };
                for _ in 0..coordinates {
                    f.real("a coordinate")?;
                }
                let physical_count = f.size("the number of physical tags")?;
                // Not reserved from the file's count: a damaged one would claim anything.
                let mut physicals = Vec::new();
                for _ in 0..physical_count {
                    physicals.push(f.int("a physical tag")?.unsigned_abs() as usize);
                }
                if dim > 0 {
                    let bounding = f.size("the number of bounding entities")?;
                    for _ in 0..bounding {
                        f.int("a bounding entity tag")?;
                    }
                }
                if dim == 2 {
                    self.surface_physicals.insert(tag, physicals);
                }
            }
        }
        f.expect("$EndEntities")
    }

    fn add_node(&mut self, f: &impl Fields, tag: usize, p: [f64; 3]) -> Result<(), ImportError> {
        if !p.iter().all(|c| c.is_finite()) {
            return Err(f.error(format!("node {tag} has a non-finite coordinate")));
        }
        if self.node_index.insert(tag, self.mesh.nodes.len()).is_some() {
            return Err(f.error(format!("node {tag} is defined twice")));
        }
        self.mesh.nodes.push(Point3::from(p));
        Ok(())
    }

    fn point(f: &mut impl Fields) -> Result<[f64; 3], ImportError> {
        Ok([f.real("x")?, f.real("y")?, f.real("z")?])
    }

    /// A tag written as an `int`, which must not be negative.
    fn int_tag(f: &mut impl Fields, what: &str) -> Result<usize, ImportError> {
        let tag = f.int(what)?;
        usize::try_from(tag).map_err(|_| f.error(format!("{what} is negative ({tag})")))
    }

    /// The node tags of an element of type `kind`, written as `int`s (versions 1 and 2).
    fn int_tags(f: &mut impl Fields, kind: usize) -> Result<Vec<usize>, ImportError> {
        let count = Self::node_count(f, kind)?;
        (0..count).map(|_| Self::int_tag(f, "a node tag")).collect()
    }

    fn node_count(f: &impl Fields, kind: usize) -> Result<usize, ImportError> {
        nodes_of(kind).ok_or_else(|| {
            f.error(format!(
                "element type {kind} is not read; use linear tetrahedra (type 4) and triangles (type 2)"
            ))
        })
    }

    fn nodes_v2(&mut self, f: &mut impl Fields) -> Result<(), ImportError> {
        let count: usize = f.ascii("the number of nodes")?;
        for _ in 0..count {
            let tag = Self::int_tag(f, "a node tag")?;
            let p = Self::point(f)?;
            self.add_node(f, tag, p)?;
        }
        f.expect("$EndNodes")
    }

    fn nodes_v4(&mut self, f: &mut impl Fields) -> Result<(), ImportError> {
        let blocks = f.size("the number of node blocks")?;
        let _total = f.size("the number of nodes")?;
        let _min = f.size("the smallest node tag")?;
        let _max = f.size("the largest node tag")?;
        for _ in 0..blocks {
            let _dim = f.int("an entity dimension")?;
            let _entity = f.int("an entity tag")?;
            let parametric = f.int("the parametric flag")?;
            if parametric != 0 {
                return Err(
                    f.error("parametric node coordinates are not read; save without them".into())
                );
            }
            let count = f.size("the number of nodes in the block")?;
            let tags: Vec<usize> = (0..count)
                .map(|_| f.size("a node tag"))
                .collect::<Result<_, _>>()?;
            for tag in tags {
                let p = Self::point(f)?;
                self.add_node(f, tag, p)?;
            }
        }
        f.expect("$EndNodes")
    }

    fn node(&self, f: &impl Fields, tag: usize) -> Result<usize, ImportError> {
        self.node_index.get(&tag).copied().ok_or_else(|| {
            f.error(format!(
                "element refers to node {tag}, which is not defined"
            ))
        })
    }

    /// An element of type `kind` on the nodes tagged `tags`, in physical group `physical`.
    fn element(
        &mut self,
        f: &impl Fields,
        kind: usize,
        physical: Option<usize>,
        tags: &[usize],
    ) -> Result<(), ImportError> {
        let ids: Vec<usize> = tags
            .iter()
            .map(|&tag| self.node(f, tag))
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

    /// Version 2's element of type `kind` from its `tag_count` tags on: the tags (the first
    /// its physical group) and its nodes, as `int`s.
    fn tagged_element(
        &mut self,
        f: &mut impl Fields,
        kind: usize,
        tag_count: usize,
    ) -> Result<(), ImportError> {
        let tags: Vec<i64> = (0..tag_count)
            .map(|_| f.int("an element tag"))
            .collect::<Result<_, _>>()?;
        let nodes = Self::int_tags(f, kind)?;
        self.element(f, kind, Self::physical_of(&tags), &nodes)
    }

    /// The first of an element's tags, its physical group, unless 0.
    fn physical_of(tags: &[i64]) -> Option<usize> {
        tags.first()
            .map(|&p| p.unsigned_abs() as usize)
            .filter(|&p| p != 0)
    }

    fn elements_v2(&mut self, f: &mut impl Fields) -> Result<(), ImportError> {
        let count: usize = f.ascii("the number of elements")?;
        for _ in 0..count {
            let _tag = f.int("an element tag")?;
            let kind = Self::int_tag(f, "an element type")?;
            let tag_count = Self::int_tag(f, "the number of tags")?;
            self.tagged_element(f, kind, tag_count)?;
        }
        f.expect("$EndElements")
    }

    /// Version 2's binary elements: blocks of one type, each with a header (type, count,
    /// tags per element), then each element's number, tags and nodes.
    fn elements_v2_binary(&mut self, f: &mut impl Fields) -> Result<(), ImportError> {
        let count: usize = f.ascii("the number of elements")?;
        let mut read = 0;
        while read < count {
            let kind = Self::int_tag(f, "an element type")?;
            let in_block = Self::int_tag(f, "the number of elements in the block")?;
            let tag_count = Self::int_tag(f, "the number of tags")?;
            for _ in 0..in_block {
                let _number = f.int("an element number")?;
                self.tagged_element(f, kind, tag_count)?;
            }
            read += in_block.max(1);
        }
        f.expect("$EndElements")
    }

    fn elements_v4(&mut self, f: &mut impl Fields) -> Result<(), ImportError> {
        let blocks = f.size("the number of element blocks")?;
        let _total = f.size("the number of elements")?;
        let _min = f.size("the smallest element tag")?;
        let _max = f.size("the largest element tag")?;
        for _ in 0..blocks {
            let dim = f.int("an entity dimension")?;
            let entity = f.int("an entity tag")?.unsigned_abs() as usize;
            let kind = Self::int_tag(f, "an element type")?;
            let count = f.size("the number of elements in the block")?;
            let physical = (dim == 2)
                .then(|| self.surface_physicals.get(&entity))
                .flatten()
                .and_then(|p| p.first().copied());
            let nodes = Self::node_count(f, kind)?;
            for _ in 0..count {
                let _tag = f.size("an element tag")?;
                let tags: Vec<usize> = (0..nodes)
                    .map(|_| f.size("a node tag"))
                    .collect::<Result<_, _>>()?;
                self.element(f, kind, physical, &tags)?;
            }
        }
        f.expect("$EndElements")
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
