//! The binary encodings of a `.vtu` file's data arrays: `binary` (base64 inside the
//! `DataArray`) and `appended` (raw bytes or base64 in the `AppendedData` element, at the
//! array's offset). Each array is a header of `header_type` words and its bytes, which VTK's
//! zlib compressor splits into blocks: the header then says how many, how long each is
//! before and after compression. Base64 writers encode the header and the data either as one
//! stream or as two, each padded; both are read.

use base64::Engine as _;
use base64::engine::general_purpose::STANDARD;

/// How a file's binary arrays are written, from its `VTKFile` element.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layout {
    pub little_endian: bool,
    /// `UInt32` or `UInt64` header words.
    pub header_bytes: usize,
    /// Blocks compressed by `vtkZLibDataCompressor`.
    pub compressed: bool,
}

impl Layout {
    /// From the `VTKFile` element's `byte_order`, `header_type` and `compressor`.
    pub fn of(
        byte_order: Option<&str>,
        header_type: Option<&str>,
        compressor: Option<&str>,
    ) -> Result<Self, String> {
        let little_endian = match byte_order.unwrap_or("LittleEndian") {
            "LittleEndian" => true,
            "BigEndian" => false,
            other => {
                return Err(format!(
                    "byte_order '{other}' is not LittleEndian or BigEndian"
                ));
            }
        };
        let header_bytes = match header_type.unwrap_or("UInt32") {
            "UInt32" => 4,
            "UInt64" => 8,
            other => return Err(format!("header_type '{other}' is not UInt32 or UInt64")),
        };
        let compressed = match compressor {
            None | Some("") => false,
            Some("vtkZLibDataCompressor") => true,
            Some(other) => {
                return Err(format!(
                    "the compressor '{other}' is not read; save with zlib or without compression"
                ));
            }
        };
        Ok(Self {
            little_endian,
            header_bytes,
            compressed,
        })
    }

    /// The `k`th header word of `bytes`.
    fn word(&self, bytes: &[u8], k: usize) -> Result<usize, String> {
        let at = k * self.header_bytes;
        let Some(word) = bytes.get(at..at + self.header_bytes) else {
            return Err(format!("the array's header ends before its word {k}"));
        };
        let mut word = word.to_vec();
        if !self.little_endian {
            word.reverse();
        }
        word.resize(8, 0);
        let value = u64::from_le_bytes(word.try_into().expect("8 bytes"));
        usize::try_from(value).map_err(|_| format!("a header word {value} is too large"))
    }

    /// The header's length in bytes, given its first word (the block count, if compressed).
    fn header_len(&self, first: usize) -> Result<usize, String> {
        match self.compressed {
            true => (first.checked_add(3))
                .and_then(|words| words.checked_mul(self.header_bytes))
                .ok_or_else(|| format!("{first} compressed blocks")),
            false => Ok(self.header_bytes),
        }
    }
}

/// A data array's element type.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl Scalar {
    pub fn of(name: &str) -> Result<Self, String> {
        Ok(match name {
            "Int8" | "Char" => Self::I8,
            "UInt8" | "UChar" => Self::U8,
            "Int16" => Self::I16,
            "UInt16" => Self::U16,
            "Int32" => Self::I32,
            "UInt32" => Self::U32,
            "Int64" | "IdType" => Self::I64,
            "UInt64" => Self::U64,
            "Float32" => Self::F32,
            "Float64" => Self::F64,
            other => return Err(format!("the data type '{other}' is not read")),
        })
    }

    fn width(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::I64 | Self::U64 | Self::F64 => 8,
        }
    }

    /// The value of one element's little-endian bytes.
    fn value(self, b: &[u8]) -> f64 {
        let array = |n: usize| {
            let mut a = [0u8; 8];
            a[..n].copy_from_slice(&b[..n]);
            a
        };
        match self {
            Self::I8 => f64::from(b[0] as i8),
            Self::U8 => f64::from(b[0]),
            Self::I16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
            Self::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
            Self::I32 => f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Self::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Self::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Self::I64 => i64::from_le_bytes(array(8)) as f64,
            Self::U64 => u64::from_le_bytes(array(8)) as f64,
            Self::F64 => f64::from_le_bytes(array(8)),
        }
    }
}

/// The values of an array's bytes (after any inflation).
fn values(bytes: &[u8], scalar: Scalar, layout: &Layout) -> Result<Vec<f64>, String> {
    let width = scalar.width();
    if !bytes.len().is_multiple_of(width) {
        return Err(format!(
            "{} bytes are no whole number of {width}-byte values",
            bytes.len()
        ));
    }
    Ok(bytes
        .chunks_exact(width)
        .map(|chunk| {
            let mut b = chunk.to_vec();
            if !layout.little_endian {
                b.reverse();
            }
            scalar.value(&b)
        })
        .collect())
}

/// An array written as raw bytes (appended, `encoding="raw"`) from its header on; returns its
/// values.
pub fn decode_raw(bytes: &[u8], scalar: Scalar, layout: &Layout) -> Result<Vec<f64>, String> {
    let header_len = layout.header_len(layout.word(bytes, 0)?)?;
    let header = bytes
        .get(..header_len)
        .ok_or("the file ends in the array's header")?;
    let data = &bytes[header_len..];
    values(&payload(header, data, layout)?, scalar, layout)
}

/// An array written in base64 (`format="binary"`, or appended with `encoding="base64"` from its
/// offset on); returns its values.
pub fn decode_base64(text: &str, scalar: Scalar, layout: &Layout) -> Result<Vec<f64>, String> {
    let text: String = text.chars().filter(|c| !c.is_ascii_whitespace()).collect();
    let decode = |part: &str| STANDARD.decode(part).map_err(|e| format!("base64: {e}"));
    let first_chars = base64_chars(layout.header_bytes);
    let first = decode(
        text.get(..first_chars)
            .ok_or("the array is shorter than its header")?,
    )?;
    let header_len = layout.header_len(layout.word(&first, 0)?)?;
    // One stream: the header and the data decode together.
    if let Ok(all) = decode(&text)
        && let Ok(data) = payload(
            &all[..header_len.min(all.len())],
            &all[header_len.min(all.len())..],
            layout,
        )
    {
        return values(&data, scalar, layout);
    }
    // Two streams, each padded: the header's characters, then the data's.
    let header_chars = base64_chars(header_len);
    let header = decode(
        text.get(..header_chars)
            .ok_or("the array is shorter than its header")?,
    )?;
    let data = decode(&text[header_chars..])?;
    values(&payload(&header, &data, layout)?, scalar, layout)
}

/// How many base64 characters encode `bytes` bytes, padded.
fn base64_chars(bytes: usize) -> usize {
    bytes.div_ceil(3) * 4
}

/// The array's bytes: `data` cut to the header's length, or its blocks inflated.
fn payload(header: &[u8], data: &[u8], layout: &Layout) -> Result<Vec<u8>, String> {
    if !layout.compressed {
        let length = layout.word(header, 0)?;
        return (data.get(..length))
            .map(<[u8]>::to_vec)
            .ok_or_else(|| format!("the array holds {} of its {length} bytes", data.len()));
    }
    let blocks = layout.word(header, 0)?;
    // No block inflates past the block size the header gives.
    let block_bytes = layout.word(header, 1)?;
    let mut out = Vec::new();
    let mut start = 0usize;
    for k in 0..blocks {
        let length = layout.word(header, 3 + k)?;
        let block = (start.checked_add(length))
            .and_then(|end| data.get(start..end))
            .ok_or_else(|| format!("compressed block {k} runs past the array"))?;
        let inflated = miniz_oxide::inflate::decompress_to_vec_zlib_with_limit(block, block_bytes)
            .map_err(|e| format!("compressed block {k} does not inflate: {e:?}"))?;
        out.extend(inflated);
        start += length;
    }
    Ok(out)
}
