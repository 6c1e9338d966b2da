//! The mesh files a scenario may name, fuzzed (`tests/support/fuzz.rs`) from the import tests'
//! own files: Gmsh v2 and v4, legacy VTK in both cell layouts, VTU (a written box), each ASCII
//! and binary (VTU compressed in raw appended data, and in base64), OBJ and
//! STL (ASCII and binary; their readers, not the tetrahedralizing behind them). No panic, no
//! read past a person's patience, no allocation past the stated bound for the file's length.

use std::path::Path;

use pgd_surgery_core::mesh::io::{ImportOptions, parse, read_obj, read_stl, write_vtu};
use pgd_surgery_core::mesh::{TetMesh, box_mesh};

use crate::fuzz::{Format, assert_refused_within, fuzz, in_proportion};
use crate::import::{CUBE_OBJ, MSH2, MSH4, VTK_CLASSIC, VTK_V5, file, tetra_stl};
use crate::msh_binary::{msh2, msh4};
use crate::vtk_binary::{classic, offsets};
use crate::vtu_binary::compressed_and_inline;

/// Cases per format in `cargo test`: each reads in microseconds.
const CASES: u32 = 2048;

/// Fuzzes the volume-mesh reader for files named `name` from `seeds`.
fn fuzz_volume(name: &'static str, seeds: Vec<Vec<u8>>) {
    let read = |bytes: &[u8]| {
        let _ = parse(Path::new(name), bytes.to_vec(), &ImportOptions::default());
    };
    fuzz(
        &Format {
            name,
            seeds,
            container: false,
            allocation_bound: in_proportion,
            read: &read,
        },
        CASES,
    );
}

/// A small box, whose binary files seed the fuzzer.
fn seed_box() -> TetMesh {
    box_mesh([0.04, 0.03, 0.02], [2, 2, 1]).unwrap()
}

#[test]
fn gmsh_files_are_fuzzed() {
    let mesh = seed_box();
    let binary = [msh4(&mesh, "z0"), msh2(&mesh, "z0")];
    fuzz_volume(
        "fuzz.msh",
        [MSH2.into(), MSH4.into()]
            .into_iter()
            .chain(binary)
            .collect(),
    );
}

#[test]
fn legacy_vtk_files_are_fuzzed() {
    let mesh = seed_box();
    let binary = [classic(&mesh), offsets(&mesh)];
    fuzz_volume(
        "fuzz.vtk",
        [VTK_CLASSIC.into(), VTK_V5.into()]
            .into_iter()
            .chain(binary)
            .collect(),
    );
}

#[test]
fn vtu_files_are_fuzzed() {
    let mesh = seed_box();
    let path = file("fuzz-seed.vtu", b"");
    write_vtu(&path, &mesh, &[]).unwrap();
    let ascii = std::fs::read(&path).unwrap();
    // The binary seeds carry the regions as the ASCII file does.
    let read = parse(&path, ascii.clone(), &ImportOptions::default()).unwrap();
    let seeds = [ascii]
        .into_iter()
        .chain(compressed_and_inline(&read))
        .collect();
    fuzz_volume("fuzz.vtu", seeds);
}

#[test]
fn surface_files_are_fuzzed() {
    let (ascii, binary) = tetra_stl();
    let read_stl_bytes = |bytes: &[u8]| {
        let _ = read_stl("fuzz.stl", bytes);
    };
    fuzz(
        &Format {
            name: "fuzz.stl",
            seeds: vec![ascii.into_bytes(), binary],
            container: false,
            allocation_bound: in_proportion,
            read: &read_stl_bytes,
        },
        CASES,
    );
    let read_obj_text = |bytes: &[u8]| {
        let _ = read_obj("fuzz.obj", &String::from_utf8_lossy(bytes));
    };
    fuzz(
        &Format {
            name: "fuzz.obj",
            seeds: vec![CUBE_OBJ.into()],
            container: false,
            allocation_bound: in_proportion,
            read: &read_obj_text,
        },
        CASES,
    );
}

/// Files whose counts claim 10¹² cells or tags are refused before anything that size is
/// allocated.
#[test]
fn claimed_counts_are_not_allocated() {
    let claims = [
        (
            "fuzz.vtk",
            VTK_CLASSIC,
            "CELLS 2 10",
            "CELLS 1000000000000 10",
        ),
        ("fuzz.vtk", VTK_CLASSIC, "POINTS 5", "POINTS 1000000000000"),
        ("fuzz.msh", MSH4, "0 1 7 0", "0 1000000000000 7 0"),
        ("fuzz.msh", MSH2, "$Nodes\n5", "$Nodes\n1000000000000"),
    ];
    for (name, seed, count, claim) in claims {
        assert!(seed.contains(count), "{count}");
        let text = seed.replace(count, claim);
        assert_refused_within(name, text.as_bytes(), in_proportion, |bytes| {
            let refused = parse(Path::new(name), bytes.to_vec(), &ImportOptions::default());
            assert!(refused.is_err(), "{name}: read a file claiming 10^12");
        });
    }
}
