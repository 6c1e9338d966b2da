//! Fuzzing a file reader with proptest: each case is a valid seed file with a few random edits
//! (bits flipped, bytes set, tokens that break parsers inserted — huge counts, NaN, negative
//! numbers —, spans deleted, the file cut short). For the project's binary files the edits go
//! into the header or the payload and the checksum is made anew, so that the reader gets past
//! it to the sizes and values behind. A reader passes a case if it returns (an error or a
//! value) without panicking, within a time a person would wait, and without any single
//! allocation larger than the stated bound for the file's length: a file claiming 10¹² modes
//! must be refused before anything that size is allocated. A failure shrinks to its smallest
//! edit list. Deterministic: CI runs the same cases every time; `PGD_FUZZ_CASES` runs more.

use std::time::{Duration, Instant};

use proptest::prelude::*;
use proptest::sample::Index;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};

use crate::counting;

/// One edit of a seed.
#[derive(Clone, Debug)]
pub enum Edit {
    Flip(Index, u8),
    Set(Index, u8),
    Insert(Index, &'static [u8]),
    Delete(Index, usize),
    Truncate(Index),
}

/// Tokens that break readers: counts and lengths far past any file, numbers that are not.
const TOKENS: &[&[u8]] = &[
    b"1000000000000",
    b"18446744073709551615",
    b"-1",
    b"NaN",
    b"inf",
    b"-inf",
    b"1e308",
    b"0",
    b"\n",
    b" ",
    b",",
    b"\"",
    b"(",
    b")",
    b"[",
    b"]",
    b"<",
    b">",
    b"\xff\xff\xff\xff\xff\xff\xff\x7f",
    b"\x00\x10\xa5\xd4\xe8\x00\x00\x00",
    b"\x00\x00\xc0\x7f",
];

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (any::<Index>(), 0u8..8).prop_map(|(at, bit)| Edit::Flip(at, bit)),
        (any::<Index>(), any::<u8>()).prop_map(|(at, byte)| Edit::Set(at, byte)),
        (any::<Index>(), proptest::sample::select(TOKENS)).prop_map(|(at, t)| Edit::Insert(at, t)),
        (any::<Index>(), 1usize..64).prop_map(|(at, n)| Edit::Delete(at, n)),
        any::<Index>().prop_map(Edit::Truncate),
    ]
}

/// Which part of a binary file the edits go into.
#[derive(Clone, Copy, Debug)]
pub enum Part {
    Whole,
    Header,
    Payload,
}

/// A case: which seed, which part, what edits.
#[derive(Clone, Debug)]
pub struct Mutation {
    seed: Index,
    part: Part,
    edits: Vec<Edit>,
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let part = prop_oneof![Just(Part::Whole), Just(Part::Header), Just(Part::Payload)];
    (
        any::<Index>(),
        part,
        proptest::collection::vec(edit(), 1..6),
    )
        .prop_map(|(seed, part, edits)| Mutation { seed, part, edits })
}

fn apply(bytes: &mut Vec<u8>, edits: &[Edit]) {
    for edit in edits {
        let at = |index: &Index, len: usize| index.index(len.max(1)).min(len);
        match edit {
            Edit::Flip(i, bit) if !bytes.is_empty() => {
                let k = at(i, bytes.len() - 1);
                bytes[k] ^= 1 << bit;
            }
            Edit::Set(i, byte) if !bytes.is_empty() => {
                let k = at(i, bytes.len() - 1);
                bytes[k] = *byte;
            }
            Edit::Insert(i, token) => {
                let k = at(i, bytes.len());
                bytes.splice(k..k, token.iter().copied());
            }
            Edit::Delete(i, n) => {
                let k = at(i, bytes.len());
                bytes.drain(k..(k + n).min(bytes.len()));
            }
            Edit::Truncate(i) => bytes.truncate(at(i, bytes.len())),
            _ => {}
        }
    }
}

/// The project's binary container: prefix (magic, version, lengths), header, payload, checksum.
const PREFIX_BYTES: usize = 28;
const CHECKSUM_BYTES: usize = 32;

/// `file` (a valid container) with `edits` in its `part`, its lengths and checksum made anew.
fn edited_container(file: &[u8], part: Part, edits: &[Edit]) -> Vec<u8> {
    match part {
        Part::Header => rebuilt(file, |header| apply(header, edits), |_| {}),
        Part::Payload => rebuilt(file, |_| {}, |payload| apply(payload, edits)),
        Part::Whole => {
            let mut whole = file.to_vec();
            apply(&mut whole, edits);
            whole
        }
    }
}

/// `file` (a valid container) with its header and payload changed by `header` and `payload`,
/// its lengths and checksum made anew: a file that gets past the checksum to what it claims.
pub fn rebuilt(
    file: &[u8],
    header: impl FnOnce(&mut Vec<u8>),
    payload: impl FnOnce(&mut Vec<u8>),
) -> Vec<u8> {
    let length = |at: usize| u64::from_le_bytes(file[at..at + 8].try_into().unwrap()) as usize;
    let (header_len, payload_len) = (length(12), length(20));
    let mut new_header = file[PREFIX_BYTES..PREFIX_BYTES + header_len].to_vec();
    let body_end = PREFIX_BYTES + header_len + payload_len;
    let mut new_payload = file[PREFIX_BYTES + header_len..body_end].to_vec();
    header(&mut new_header);
    payload(&mut new_payload);
    let mut out = file[..12].to_vec();
    out.extend((new_header.len() as u64).to_le_bytes());
    out.extend((new_payload.len() as u64).to_le_bytes());
    out.extend(&new_header);
    out.extend(&new_payload);
    let checksum = blake3::hash(&out);
    assert_eq!(checksum.as_bytes().len(), CHECKSUM_BYTES);
    out.extend(checksum.as_bytes());
    out
}

/// `read`'s largest single allocation for `bytes`, which must stay within `bound` of their
/// length.
pub fn assert_refused_within(
    name: &str,
    bytes: &[u8],
    bound: fn(usize) -> usize,
    read: impl FnOnce(&[u8]),
) {
    let ((), allocated) = counting::measure(|| read(bytes));
    eprintln!(
        "{name}: largest allocation {} bytes for a {} byte file",
        allocated.largest_bytes,
        bytes.len()
    );
    assert!(
        allocated.largest_bytes <= bound(bytes.len()),
        "{name}: a {} byte allocation for a {} byte file",
        allocated.largest_bytes,
        bytes.len()
    );
}

/// A reader under fuzzing.
pub struct Format<'a> {
    pub name: &'a str,
    /// Valid files to start from.
    pub seeds: Vec<Vec<u8>>,
    /// Whether the files are the project's binary container (edits go behind the checksum).
    pub container: bool,
    /// The largest single allocation (bytes) allowed for a file of this length.
    pub allocation_bound: fn(usize) -> usize,
    /// Reads the bytes; any `Err` is a refusal, which passes.
    pub read: &'a dyn Fn(&[u8]),
}

/// The longest a read may take: far past any real file's, so a loaded machine does not fail
/// it; a hang never returns at all.
const SLOWEST_READ: Duration = Duration::from_secs(20);

/// Fuzzes `format` for `cases` cases (or `PGD_FUZZ_CASES`); panics with the smallest failing
/// case, and prints the cases run, the largest allocation for the file's length and the
/// slowest read.
pub fn fuzz(format: &Format<'_>, cases: u32) {
    let cases = std::env::var("PGD_FUZZ_CASES")
        .ok()
        .and_then(|n| n.parse().ok())
        .unwrap_or(cases);
    let config = Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    };
    let rng = TestRng::deterministic_rng(RngAlgorithm::ChaCha);
    let mut runner = TestRunner::new_with_rng(config, rng);
    let largest = std::cell::Cell::new(0.0f64);
    let slowest = std::cell::Cell::new(Duration::ZERO);
    let result = runner.run(&mutation(), |m| {
        let seed = &format.seeds[m.seed.index(format.seeds.len())];
        let bytes = match format.container {
            true => edited_container(seed, m.part, &m.edits),
            false => {
                let mut bytes = seed.clone();
                apply(&mut bytes, &m.edits);
                bytes
            }
        };
        let started = Instant::now();
        let ((), allocated) = counting::measure(|| (format.read)(&bytes));
        let took = started.elapsed();
        let bound = (format.allocation_bound)(bytes.len());
        largest.set(
            largest
                .get()
                .max(allocated.largest_bytes as f64 / bytes.len().max(1) as f64),
        );
        slowest.set(slowest.get().max(took));
        if allocated.largest_bytes > bound {
            return Err(TestCaseError::fail(format!(
                "{}: a {} byte allocation for a {} byte file (bound {bound})",
                format.name,
                allocated.largest_bytes,
                bytes.len()
            )));
        }
        if took > SLOWEST_READ {
            return Err(TestCaseError::fail(format!(
                "{}: took {took:?}",
                format.name
            )));
        }
        Ok(())
    });
    if let Err(e) = result {
        panic!("{}: {e}", format.name);
    }
    eprintln!(
        "fuzz {}: {cases} cases; largest allocation {:.2} bytes a byte of file; slowest read {:?}",
        format.name,
        largest.get(),
        slowest.get()
    );
}

/// The bound for readers that hold what they read: 32 bytes of allocation for each byte of
/// file (text numbers become doubles and vectors; arrays of four-byte words become
/// eight-byte ones and their derived tables), and 4 MiB for what a reader builds whatever
/// the file's length (a scenario's ports and laparoscope are checked against the generated
/// abdomen, 1.2 MB).
pub fn in_proportion(len: usize) -> usize {
    32 * len + (4 << 20)
}
