//! The scalpel: the tissue parts only above its threshold, the cut follows the blade's edge,
//! and the cut state grown on the worker thread makes the tool feel, and the window draw,
//! what full X-FEM gives.

use std::sync::Arc;

use nalgebra::{Point3, Unit, Vector3};
use pgd_surgery_core::cutting::{
    Blade, BladeContact, CutError, CutStep, CutView, CutWorker, Enrichment, Front,
    LIVER_TOUGHNESS_J_PER_M2, Scalpel, xfem,
};
use pgd_surgery_core::fem::{FemModel, Loads};

use super::{MM, block_to_cut, full_compliance, full_cross_compliance, top_patch};

/// The blade on the block's top at `x` mm along a line at `y = 20 mm`, wobbling 0.4 mm across
/// it, pressing `pressing_n` at `depth_mm`, its edge along `edge`.
fn on_top(x: f64, pressing_n: f64, depth_mm: f64, edge: Vector3<f64>) -> BladeContact {
    let wobble = 0.4 * (x * 1.7).sin();
    BladeContact {
        point_m: Point3::new(x * MM, (20.0 + wobble) * MM, 10.0 * MM),
        inward: Unit::new_normalize(-Vector3::z()),
        edge,
        depth_m: depth_mm * MM,
        pressing_n,
    }
}

/// A stroke from 10 to 30 mm along x in 0.05 mm steps; the steps the scalpel takes.
fn stroke(scalpel: &mut Scalpel, pressing_n: f64, edge: Vector3<f64>) -> Vec<CutStep> {
    let mut steps = Vec::new();
    for k in 0..=400 {
        let x = 10.0 + 0.05 * f64::from(k);
        steps.extend(scalpel.tick(Some(&on_top(x, pressing_n, 4.0, edge))));
    }
    steps.extend(scalpel.tick(None));
    steps
}

/// Pressed below the tissue's threshold the blade only presses: nothing is cut, however far
/// it moves. Above it, the tissue parts where the blade is, and the cut follows the edge
/// (the hand's wobble across it is not cut) in steps of the blade's length, to within a step
/// of where the blade stops.
#[test]
fn the_scalpel_cuts_only_above_the_threshold_and_along_its_edge() {
    let blade = Blade::default();
    let threshold = blade.threshold_n(LIVER_TOUGHNESS_J_PER_M2);
    assert!((threshold - 187.0 * 0.005).abs() < 1e-12);

    let mut scalpel = Scalpel::new(blade, LIVER_TOUGHNESS_J_PER_M2);
    assert!(stroke(&mut scalpel, 0.95 * threshold, Vector3::x()).is_empty());
    assert!(scalpel.strokes().is_empty());

    let steps = stroke(&mut scalpel, 1.05 * threshold, Vector3::x());
    let Some(CutStep::Start { at, depth_m, .. }) = steps.first() else {
        panic!("the tissue did not part: {steps:?}");
    };
    assert!((at.x - 10.0 * MM).abs() < 1e-12 && (depth_m - 4.0 * MM).abs() < 1e-12);
    let fronts: Vec<Point3<f64>> = steps[1..]
        .iter()
        .map(|step| match step {
            CutStep::Advance { to } => *to,
            other => panic!("expected an advance, got {other:?}"),
        })
        .collect();
    for pair in fronts.windows(2) {
        assert!((pair[1].x - pair[0].x) >= blade.step_m - 1e-12);
    }
    for front in &fronts {
        assert!(
            (front.y - at.y).abs() < 1e-12,
            "the cut left the edge's line"
        );
    }
    let last = fronts.last().expect("the cut advanced");
    assert!(
        30.0 * MM - last.x < blade.step_m,
        "stopped short at {} mm",
        last.x / MM
    );
    let made = scalpel.strokes();
    assert_eq!(made.len(), 1);
    assert!((made[0].length_m - (last.x - at.x)).abs() < 1e-12);
    assert!(!scalpel.cutting(), "lifting the blade ends the stroke");

    // The edge across the motion: the tissue parts, but moving across the edge cuts nothing.
    let mut across = Scalpel::new(blade, LIVER_TOUGHNESS_J_PER_M2);
    let steps = stroke(&mut across, 1.05 * threshold, Vector3::y());
    assert!(matches!(steps[..], [CutStep::Start { .. }]), "{steps:?}");
}

/// A blade pressed deeper than its incision by more than the blade's share deepens it; a
/// turn of the edge starts a new face from where the cut reached.
#[test]
fn pressing_deeper_deepens_and_turning_turns() {
    let blade = Blade::default();
    let mut scalpel = Scalpel::new(blade, LIVER_TOUGHNESS_J_PER_M2);
    let hard = 2.0 * blade.threshold_n(LIVER_TOUGHNESS_J_PER_M2);
    let start = scalpel.tick(Some(&on_top(10.0, hard, 4.0, Vector3::x())));
    assert!(matches!(start, Some(CutStep::Start { .. })));
    let deeper = scalpel.tick(Some(&on_top(10.0, hard, 5.0, Vector3::x())));
    assert_eq!(deeper, Some(CutStep::Deepen { depth_m: 5.0 * MM }));
    let slightly = scalpel.tick(Some(&on_top(10.0, hard, 5.2, Vector3::x())));
    assert_eq!(slightly, None, "within the blade's share: no deepening");
    let advance = scalpel.tick(Some(&on_top(13.0, hard, 5.0, Vector3::x())));
    assert!(matches!(advance, Some(CutStep::Advance { .. })));
    // Turned 45°, the edge cuts on from where the cut reached (13 mm along the first line),
    // along its new direction.
    let y0 = on_top(10.0, hard, 4.0, Vector3::x()).point_m.y;
    let mut turned = on_top(13.0, hard, 5.0, Vector3::new(1.0, 1.0, 0.0));
    turned.point_m = Point3::new(15.5 * MM, y0 + 2.5 * MM, 10.0 * MM);
    let Some(CutStep::Advance { to }) = scalpel.tick(Some(&turned)) else {
        panic!("the turned blade did not cut on");
    };
    assert!((to - turned.point_m).norm() < 1e-12, "cut on to {to:?}");
    assert_eq!(scalpel.strokes()[0].max_depth_m, 5.0 * MM);
}

/// Over a curved surface (a sphere of the cornea's 8 mm radius, cut 0.4 mm deep along a
/// meridian) the cut follows the surface: every point it advances to lies within the blade's
/// follow share of the depth of the sphere, where one straight face would have left the
/// surface by its sag (0.7 mm over 3.4 mm).
#[test]
fn the_cut_follows_a_curved_surface() {
    let blade = Blade {
        step_m: 0.5 * MM,
        edge_m: 0.005 * MM,
        ..Blade::default()
    };
    let mut scalpel = Scalpel::new(blade, LIVER_TOUGHNESS_J_PER_M2);
    let radius = 8.0 * MM;
    let depth = 0.4 * MM;
    let at = |angle: f64| {
        let outward = Vector3::new(angle.sin(), 0.0, angle.cos());
        BladeContact {
            point_m: Point3::from(outward * radius),
            inward: Unit::new_normalize(-outward),
            edge: Vector3::x(),
            depth_m: depth,
            pressing_n: 1.0,
        }
    };
    let mut fronts = Vec::new();
    for k in 0..=500 {
        let angle = (0.1 + 0.4 * f64::from(k) / 500.0).to_radians() * 60.0;
        if let Some(CutStep::Advance { to }) = scalpel.tick(Some(&at(angle))) {
            fronts.push(to);
        }
    }
    let reach = fronts.last().expect("the cut advanced").x;
    assert!(reach > 3.0 * MM, "the cut reached only {} mm", reach / MM);
    for to in &fronts {
        let off = (to.coords.norm() - radius).abs();
        assert!(
            off <= blade.follow_share * depth + 1e-9,
            "{:.3} mm off the surface at x = {:.2} mm",
            off / MM,
            to.x / MM
        );
    }
}

/// The block on a worker, handed a stroke along `y = 20 mm` on its top, 6 mm deep, from
/// `x = 14 mm` on to each of `to_x_mm` in turn.
fn stroke_on_block(to_x_mm: &[f64]) -> (Arc<FemModel>, CutWorker) {
    let (model, _) = block_to_cut();
    let model = Arc::new(model);
    let mut worker = CutWorker::spawn(model.clone(), "block", Default::default()).unwrap();
    worker.submit(CutStep::Start {
        at: on_block_top(14.0),
        blade: -Vector3::z(),
        depth_m: 6.0 * MM,
    });
    for &x in to_x_mm {
        worker.submit(CutStep::Advance {
            to: on_block_top(x),
        });
    }
    (model, worker)
}

/// The point on the block's top `x_mm` along the stroke's line.
fn on_block_top(x_mm: f64) -> Point3<f64> {
    Point3::new(x_mm * MM, 20.0 * MM, 10.0 * MM)
}

/// The cut state on its worker thread, fed a stroke's steps, gives the tick the patch
/// compliance that full X-FEM solves of the same faces (the front snapped to the nearest
/// element faces) give, to round-off; a step the cut state refuses is reported and changes
/// nothing.
#[test]
fn the_worker_serves_the_felt_compliance_of_full_xfem() {
    let (model, mut worker) = stroke_on_block(&[18.0, 22.0, 26.0, 30.0]);
    let view = worker.settle().clone();
    assert_eq!(worker.pending(), 0);
    assert!(view.unknowns > 0, "the stroke enriched nothing");
    assert_eq!(view.faces.len(), 1, "a straight stroke is one face");

    let patch = top_patch(
        &model,
        Point3::new(24.0 * MM, 21.5 * MM, 10.0 * MM),
        4.0 * MM,
    );
    let uncut = full_compliance(&model, (&[], Front::Nearest), &patch);
    let cut = full_compliance(&model, (&view.faces, Front::Nearest), &patch);
    let mut y = Default::default();
    let served = uncut + view.added_compliance(&patch, &mut y);
    let error = (served - cut).norm() / cut.norm();
    eprintln!(
        "{} unknowns; felt compliance {:.4e} m/N served, {:.4e} full X-FEM, {:.4e} uncut; relative difference {error:.1e}",
        view.unknowns,
        served.norm(),
        cut.norm(),
        uncut.norm()
    );
    assert!(error < 1e-9);
    assert!(
        cut.norm() > 1.01 * uncut.norm(),
        "the cut does not soften the patch"
    );

    worker.submit(CutStep::Advance {
        to: on_block_top(30.0),
    });
    let after = worker.settle().clone();
    assert!(matches!(worker.refused(), [CutError::Degenerate(_)]));
    assert_eq!(after.unknowns, view.unknowns);
}

/// Two hands on the cut block, a patch each side of the stroke: what the worker adds to the
/// displacement of the pressed patch under both loads, its own answered by its own added
/// compliance and the other's by the cross term, equals the difference full X-FEM solves make
/// between the cut and the uncut block, to round-off; and the cut does change how one lip
/// moves the other.
#[test]
fn the_worker_serves_one_patch_s_move_under_the_other_s_load_as_full_xfem_does() {
    let (model, mut worker) = stroke_on_block(&[30.0]);
    let view = worker.settle().clone();
    let pressed = top_force(&model, 21.0, [0.0, 0.5, -1.0]);
    let pulled = top_force(&model, 17.0, [0.0, -0.5, 0.5]);
    worker.clear_loads();
    for load in [&pressed, &pulled] {
        worker.add_load(&load.patch, &load.force_n);
    }
    let served = worker.patch_response(&pressed.patch);
    let added = |loaded: &[(usize, f64)]| {
        let full =
            |faces| full_cross_compliance(&model, (faces, Front::Nearest), loaded, &pressed.patch);
        full(&view.faces) - full(&[])
    };
    let own = added(&pressed.patch);
    let across = added(&pulled.patch);
    let full = own * pressed.force_n + across * pulled.force_n;
    let error = (served.moved_m - full).norm() / full.norm();
    eprintln!(
        "the cut adds {:.4} mm under both loads ({:.4} mm of it the pull's); served off by {error:.1e}",
        full.norm() / MM,
        (across * pulled.force_n).norm() / MM
    );
    assert!(error < 1e-9);
    assert!((served.added_m_per_n - own).norm() < 1e-9 * own.norm());
    assert!(
        (across * pulled.force_n).norm() > 1e-3 * MM,
        "the cut does not change how the pull moves the other lip"
    );
}

/// What the window draws of a cut organ under the tool's load, from the worker's view alone:
/// every enriched surface node's displacement on its own side (the uncut one plus `−Ẑ y`),
/// and seen from across its face (plus the opening `−2 H q`), equal the full X-FEM solve of
/// the same cut under the same load, both sides, to round-off; and the lips do open.
#[test]
fn the_view_opens_the_lips_as_full_xfem_does() {
    let (model, mut worker) = stroke_on_block(&[30.0]);
    let view = worker.settle().clone();
    assert!(!view.functions.is_empty(), "the stroke enriched nothing");
    // The tool pressing down and across the cut beside it, 1 N.
    let pressed = top_force(&model, 21.0, [0.0, 0.5, -1.0]);
    let widest = view_against_xfem(&model, &view, &[pressed]);
    eprintln!("the lips open by up to {:.3} mm", widest / MM);
    assert!(widest > 1e-3 * MM, "the lips did not open");
}

/// Two hands on the cut organ: the same press beside the cut and a grasp pulling the tissue
/// across it on the other side, 0.5 N up and away. The view's answer to both loads at once
/// (as the window draws it) equals full X-FEM under both, to round-off, and the pull opens the
/// lips wider than the press alone.
#[test]
fn the_view_answers_two_hands_at_once_as_full_xfem_does() {
    let (model, mut worker) = stroke_on_block(&[30.0]);
    let view = worker.settle().clone();
    let pressed = top_force(&model, 21.0, [0.0, 0.5, -1.0]);
    let pulled = top_force(&model, 9.0, [0.0, -0.5, 0.5]);
    let alone = view_against_xfem(&model, &view, std::slice::from_ref(&pressed));
    let both = view_against_xfem(&model, &view, &[pressed, pulled]);
    eprintln!(
        "the lips open by up to {:.3} mm under the press, {:.3} mm with the pull",
        alone / MM,
        both / MM
    );
    assert!(both > alone, "the pull did not open the cut further");
}

/// A force spread over a patch of the block's top by the patch's shares.
struct PatchForce {
    patch: Vec<(usize, f64)>,
    force_n: Vector3<f64>,
}

/// `force_n` (N) on the 4 mm patch of the block's top at `y_mm` across the stroke (which runs
/// along y = 20 mm), 22 mm along it: beside the cut, or across it on the other side.
fn top_force(model: &FemModel, y_mm: f64, force_n: [f64; 3]) -> PatchForce {
    let at = Point3::new(22.0 * MM, y_mm * MM, 10.0 * MM);
    PatchForce {
        patch: top_patch(model, at, 4.0 * MM),
        force_n: Vector3::from(force_n),
    }
}

/// The view's answer to `patches` against the full X-FEM solve of the same cut under the same
/// loads: every enriched top node, on its own side and across its face, to 1e-9 relative.
/// Returns the widest opening (m).
fn view_against_xfem(model: &FemModel, view: &CutView, patches: &[PatchForce]) -> f64 {
    let mesh = model.mesh();
    let mut loads = Loads::new(mesh.node_count());
    let mut load = Vec::new();
    for PatchForce { patch, force_n } in patches {
        for &(n, share) in patch {
            let f = force_n * share;
            loads.add_nodal_force(n, [f.x, f.y, f.z]).unwrap();
            load.extend((0..3).map(|c| (3 * n + c, f[c])));
        }
    }
    let uncut = xfem::solve(model, &Enrichment::new(mesh, &[]), &loads).unwrap();
    let enrichment = Enrichment::with_front(mesh, &view.faces, Front::Nearest);
    let full = xfem::solve(model, &enrichment, &loads).unwrap();
    let answer = view.answer(&load);
    let top = mesh.node_set("z1").unwrap();
    let mut widest: f64 = 0.0;
    for (j, f) in view.functions.iter().enumerate() {
        if !top.contains(&f.node) {
            continue;
        }
        let own = Vector3::from_column_slice(&uncut.nodes_m[3 * f.node..3 * f.node + 3])
            + view.added_displacement(f.node, &answer);
        let across = own + view.opening(j, &answer);
        let full_own = full.at_node(&enrichment, f.node, &[f.node_side]);
        let full_across = full.at_node(&enrichment, f.node, &[-f.node_side]);
        let scale = full_own.norm().max(1e-12);
        assert!((own - full_own).norm() < 1e-9 * scale, "node {}", f.node);
        assert!(
            (across - full_across).norm() < 1e-9 * scale,
            "node {}",
            f.node
        );
        widest = widest.max((across - own).norm());
    }
    widest
}
