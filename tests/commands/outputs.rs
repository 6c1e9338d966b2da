//! What `pgd indent` and `pgd validate` draw and refuse.

use pgd_surgery::cli::plot_force_depth;
use pgd_surgery::fem::Law;
use pgd_surgery::pgd::{Silent, ValidationSettings, validate};

use crate::common::{block_mesh, block_model, build_block, temp_dir};

/// `pgd indent` on a block with `clamped` and `accessible` regions: one curve per law, rising
/// with depth, the linear law's per-element volumes stiffer than the neo-Hookean nodal ones at
/// ν = 0.48, and the curves drawn as a PNG; a request without steps is refused.
#[test]
fn pgd_indent_gives_a_force_depth_curve_per_law() {
    use pgd_surgery::cli::{IndentRequest, LoadedMesh, indent_organ, plot_indentation};
    use pgd_surgery::fem::Material;
    use pgd_surgery::mesh::organs::region;

    let mut mesh = block_mesh([6, 4, 3]);
    let clamped = mesh.node_set("z0").unwrap().to_vec();
    let accessible = mesh.face_set("z1").unwrap().to_vec();
    mesh.set_node_set(region::CLAMPED, clamped).unwrap();
    mesh.set_face_set(region::ACCESSIBLE, accessible).unwrap();
    let materials = [Law::Linear, Law::NeoHookean].map(Material::liver);
    let request = IndentRequest {
        source: "block",
        at_mm: Some([30.0, 20.0, 30.0]),
        depth_mm: Some(2.0),
        steps: 4,
    };
    let silent = pgd_surgery::pgd::Silent;
    let report = indent_organ(
        LoadedMesh {
            organ: None,
            mesh: mesh.clone(),
            selection: None,
        },
        &materials,
        &request,
        &silent,
    )
    .unwrap();
    assert_eq!(report.point_m, [0.03, 0.02, 0.03]);
    let [linear, neo_hookean] = [&report.curves[0], &report.curves[1]];
    for curve in [linear, neo_hookean] {
        assert_eq!(curve.stopped_at_m, None, "{:?}", curve.stop_reason);
        assert_eq!(curve.force_n.len(), 4);
        assert!(
            curve.force_n.windows(2).all(|w| w[1] > w[0] && w[0] > 0.0),
            "{} forces {:?} N do not rise with depth",
            curve.law,
            curve.force_n
        );
    }
    assert!(linear.force_n[0] > neo_hookean.force_n[0]);
    let png = temp_dir("indent").join("block-indentation.png");
    plot_indentation(&report, &png).unwrap();
    assert_eq!(&std::fs::read(png).unwrap()[..8], b"\x89PNG\r\n\x1a\n");

    let no_steps = IndentRequest {
        steps: 0,
        ..request
    };
    let refused = indent_organ(
        LoadedMesh {
            organ: None,
            mesh,
            selection: None,
        },
        &materials,
        &no_steps,
        &silent,
    )
    .unwrap_err();
    assert!(refused.contains("--steps"), "{refused}");
}

/// `pgd validate` draws its force–depth curves beside the vademecum as a PNG; asked for none
/// (`--curves 0`), it draws nothing rather than an empty chart.
#[test]
fn the_force_depth_plot_is_drawn_only_when_there_are_curves() {
    let model = block_model(block_mesh([4, 3, 2]));
    let vademecum = build_block(&model, 5);
    let file = temp_dir("force-depth").join("block.vdm");
    let checked = |curves: usize| {
        let settings = ValidationSettings {
            samples: 1,
            curves,
            indentation_range_m: (1e-3, 3e-3),
            ..ValidationSettings::default()
        };
        validate(&model, &vademecum, &settings, &Silent).unwrap()
    };
    assert_eq!(plot_force_depth(&checked(0), &file), Ok(None));
    let png = plot_force_depth(&checked(1), &file).unwrap().unwrap();
    assert!(std::fs::read(png).unwrap().starts_with(b"\x89PNG"));
}

/// `pgd mesh FILE --clamp … --accessible … --preview`: what each selector picked, counted, the
/// regions set, the picture drawn; a selector that picks nothing refused with the organ's
/// extent, and exit status 1.
#[test]
fn pgd_mesh_picks_regions_by_selectors_and_draws_them() {
    let folder = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("pgd-mesh-selectors");
    std::fs::create_dir_all(&folder).unwrap();
    let block = pgd_surgery::mesh::box_mesh([0.040, 0.020, 0.010], [4, 2, 1]).unwrap();
    let file = folder.join("block.vtu");
    pgd_surgery::mesh::io::write_vtu(&file, &block, &[]).unwrap();
    let preview = folder.join("regions.png");
    let _ = std::fs::remove_file(&preview);
    let pgd = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_pgd"))
            .arg("mesh")
            .arg(&file)
            .args(args)
            .output()
            .unwrap()
    };
    let out = pgd(&[
        "--clamp",
        "region:x0",
        "--clamp",
        "not:facing:0,0,1,1",
        "--accessible",
        "facing:0,0,1,1",
        "--preview",
        preview.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for line in [
        "region:x0: 6 nodes",
        "not:facing:0,0,1,1: 15 nodes",
        "clamped: 3 nodes",
        "facing:0,0,1,1: 16 faces",
        "node set clamped: 3 nodes",
        "face set accessible: 16 faces",
    ] {
        assert!(stdout.contains(line), "`{line}` in:\n{stdout}");
    }
    assert!(std::fs::metadata(&preview).unwrap().len() > 1000);
    let out = pgd(&["--clamp", "sphere:100,100,100,5"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("picks nothing") && stderr.contains("spans x 0.0 to 40.0"),
        "{stderr}"
    );
}
