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
        LoadedMesh { organ: None, mesh },
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
