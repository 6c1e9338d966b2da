//! Binary `.vtu` files as VTK and ParaView write them: data arrays inline in base64 or in the
//! appended data (raw or base64), zlib-compressed in blocks or not, 32- or 64-bit headers,
//! either byte order. A generated liver written each way reads back as its ASCII `.vtu`
//! does: the same nodes, tetrahedra and regions.

use base64::Engine as _;
use base64::engine::general_purpose::STANDARD;
use pgd_surgery_core::mesh::TetMesh;
use pgd_surgery_core::mesh::io::{ImportOptions, load, write_vtu};
use pgd_surgery_core::mesh::organs::{self, Organ, OrganSettings};

use super::import::file;

/// How a file writes its arrays.
#[derive(Clone, Copy, Debug)]
struct Way {
    appended: Option<Encoding>,
    /// zlib blocks of this many bytes before compression.
    block_bytes: Option<usize>,
    header_bytes: usize,
    little_endian: bool,
    /// Base64 of the header and of the data each padded on its own, as VTK writes them.
    two_streams: bool,
}

/// Inline base64 of plain arrays, 32-bit headers, little-endian, header and data each padded.
const PLAIN: Way = Way {
    appended: None,
    block_bytes: None,
    header_bytes: 4,
    little_endian: true,
    two_streams: true,
};

#[derive(Clone, Copy, Debug, PartialEq)]
enum Encoding {
    Raw,
    Base64,
}

/// An array: its name, VTK type and the values' little-endian bytes.
struct Array {
    section: &'static str,
    name: String,
    kind: &'static str,
    components: usize,
    width: usize,
    bytes: Vec<u8>,
}

fn arrays(mesh: &TetMesh) -> Vec<Array> {
    let points = (mesh.nodes().iter())
        .flat_map(|p| {
            p.coords
                .iter()
                .flat_map(|c| c.to_le_bytes())
                .collect::<Vec<_>>()
        })
        .collect();
    let connectivity = (mesh.tets().iter())
        .flat_map(|t| {
            t.iter()
                .flat_map(|&n| (n as i64).to_le_bytes())
                .collect::<Vec<_>>()
        })
        .collect();
    let offsets = (1..=mesh.tet_count())
        .flat_map(|k| (4 * k as i64).to_le_bytes())
        .collect();
    let mut arrays = vec![
        array("Points", "", "Float64", 3, 8, points),
        array("Cells", "connectivity", "Int64", 1, 8, connectivity),
        array("Cells", "offsets", "Int64", 1, 8, offsets),
        array("Cells", "types", "UInt8", 1, 1, vec![10; mesh.tet_count()]),
    ];
    for (name, nodes) in &mesh.regions().node_sets {
        let mut flags = vec![0u8; mesh.node_count()];
        nodes.iter().for_each(|&n| flags[n] = 1);
        arrays.push(array(
            "PointData",
            &format!("region:{name}"),
            "UInt8",
            1,
            1,
            flags,
        ));
    }
    arrays
}

fn array(
    section: &'static str,
    name: &str,
    kind: &'static str,
    components: usize,
    width: usize,
    bytes: Vec<u8>,
) -> Array {
    Array {
        section,
        name: name.to_owned(),
        kind,
        components,
        width,
        bytes,
    }
}

impl Way {
    fn word(&self, value: usize) -> Vec<u8> {
        let mut bytes = (value as u64).to_le_bytes()[..self.header_bytes].to_vec();
        if !self.little_endian {
            bytes.reverse();
        }
        bytes
    }

    /// An array's header and data as the file holds them (before any base64).
    fn encoded(&self, array: &Array) -> (Vec<u8>, Vec<u8>) {
        let data: Vec<u8> = match self.little_endian {
            true => array.bytes.clone(),
            false => (array.bytes.chunks(array.width))
                .flat_map(|c| c.iter().rev().copied().collect::<Vec<_>>())
                .collect(),
        };
        let Some(block) = self.block_bytes else {
            return (self.word(data.len()), data);
        };
        let blocks: Vec<Vec<u8>> = (data.chunks(block))
            .map(|b| miniz_oxide::deflate::compress_to_vec_zlib(b, 6))
            .collect();
        let last = data.len() - block * (blocks.len() - 1);
        let mut header = [blocks.len(), block, last].map(|w| self.word(w)).concat();
        blocks
            .iter()
            .for_each(|b| header.extend(self.word(b.len())));
        (header, blocks.concat())
    }

    fn base64(&self, (header, data): (Vec<u8>, Vec<u8>)) -> String {
        match self.two_streams {
            true => STANDARD.encode(header) + &STANDARD.encode(data),
            false => STANDARD.encode([header, data].concat()),
        }
    }

    fn file(&self, mesh: &TetMesh) -> Vec<u8> {
        let order = ["BigEndian", "LittleEndian"][usize::from(self.little_endian)];
        let header = ["UInt32", "UInt64"][usize::from(self.header_bytes == 8)];
        let compressor = match self.block_bytes {
            Some(_) => r#" compressor="vtkZLibDataCompressor""#,
            None => "",
        };
        let mut xml = format!(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" \
             byte_order=\"{order}\" header_type=\"{header}\"{compressor}>\n<UnstructuredGrid>\n\
             <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n",
            mesh.node_count(),
            mesh.tet_count()
        );
        let mut appended: Vec<u8> = Vec::new();
        let mut section = "";
        for array in arrays(mesh) {
            if array.section != section {
                if !section.is_empty() {
                    xml += &format!("</{section}>\n");
                }
                section = array.section;
                xml += &format!("<{section}>\n");
            }
            let attributes = format!(
                "type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\"",
                array.kind, array.name, array.components
            );
            let encoded = self.encoded(&array);
            match self.appended {
                None => {
                    let text = self.base64(encoded);
                    xml += &format!(
                        "<DataArray {attributes} format=\"binary\">\n{text}\n</DataArray>\n"
                    );
                }
                Some(encoding) => {
                    let offset = appended.len();
                    xml += &format!(
                        "<DataArray {attributes} format=\"appended\" offset=\"{offset}\"/>\n"
                    );
                    match encoding {
                        Encoding::Raw => appended.extend(encoded.0.into_iter().chain(encoded.1)),
                        Encoding::Base64 => appended.extend(self.base64(encoded).bytes()),
                    }
                }
            }
        }
        xml += &format!("</{section}>\n</Piece>\n</UnstructuredGrid>\n");
        let mut bytes = xml.into_bytes();
        if let Some(encoding) = self.appended {
            let name = ["raw", "base64"][usize::from(encoding == Encoding::Base64)];
            bytes.extend(format!("<AppendedData encoding=\"{name}\">\n_").bytes());
            bytes.extend(appended);
            bytes.extend(b"\n</AppendedData>\n");
        }
        bytes.extend(b"</VTKFile>\n");
        bytes
    }
}

/// `mesh` with zlib-compressed arrays in raw appended data, and with plain arrays in base64,
/// for the fuzzer's seeds.
pub fn compressed_and_inline(mesh: &TetMesh) -> [Vec<u8>; 2] {
    let plain = PLAIN;
    let compressed = Way {
        appended: Some(Encoding::Raw),
        block_bytes: Some(64),
        ..plain
    };
    [compressed.file(mesh), plain.file(mesh)]
}

fn liver() -> TetMesh {
    let settings = OrganSettings {
        resolution: 0.25,
        ..OrganSettings::default()
    };
    organs::generate(Organ::Liver, &settings).unwrap()
}

#[test]
fn binary_vtu_files_read_back_as_the_ascii_one() {
    let mesh = liver();
    let ascii = file("ascii.vtu", b"");
    write_vtu(&ascii, &mesh, &[]).unwrap();
    let reference = load(&ascii, &ImportOptions::default()).unwrap();
    let plain = PLAIN;
    let ways = [
        plain,
        Way {
            two_streams: false,
            ..plain
        },
        Way {
            block_bytes: Some(4096),
            header_bytes: 8,
            ..plain
        },
        Way {
            appended: Some(Encoding::Raw),
            header_bytes: 8,
            ..plain
        },
        Way {
            appended: Some(Encoding::Raw),
            block_bytes: Some(1000),
            ..plain
        },
        Way {
            appended: Some(Encoding::Base64),
            little_endian: false,
            two_streams: false,
            ..plain
        },
    ];
    for (k, way) in ways.iter().enumerate() {
        let name = format!("way-{k}.vtu");
        // The regions as the ASCII file carries them: every one as its nodes.
        let back = load(
            &file(&name, &way.file(&reference)),
            &ImportOptions::default(),
        )
        .unwrap_or_else(|e| panic!("{way:?}: {e}"));
        assert_eq!(back.nodes(), reference.nodes(), "{way:?}");
        assert_eq!(back.tets(), reference.tets(), "{way:?}");
        assert_eq!(back.regions(), reference.regions(), "{way:?}");
    }
}
