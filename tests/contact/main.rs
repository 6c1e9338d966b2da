//! Organ against organ on the coarse abdominal scene: the gallbladder pressed into
//! the liver through the whole haptic schedule, the distance field against the exact distance
//! to the deformed gallbladder, and the attachments.

#[path = "../../crates/pgd-surgery-core/tests/support/cache.rs"]
mod cache;
mod clearance;
mod common;
mod deep_press;
mod dimples;
mod field_file;
mod moving;
mod near_field;

use common::*;
use nalgebra::{Point3, Vector3};
use pgd_surgery::app::haptic::{DeviceForce, HapticLoop, HapticScene};
use pgd_surgery::contact::{
    ContactSurface, DistanceField, DistanceSettings, LatticeCache, MasterShape, NearField,
    Pointshell, PointshellDensity,
};
use pgd_surgery::devices::Scripted;
use pgd_surgery::parry_interop::{from_parry, to_parry};
use pgd_surgery::pgd::SurfaceModes;

/// 12 mm up into the gallbladder's underside over 2 s, held for half a second.
const PUSH_S: f64 = 2.0;
const TICKS: u64 = 2500;

fn pushed() -> &'static Vec<Tick> {
    static RECORD: std::sync::OnceLock<Vec<Tick>> = std::sync::OnceLock::new();
    RECORD.get_or_init(|| {
        let target = facing("gallbladder", -Vector3::z());
        run(push(&target, 0.012, PUSH_S, 0.5), TICKS).1
    })
}

/// The same push where the tool touches the gallbladder alone, clear of the duodenum.
fn pushed_alone() -> &'static Vec<Tick> {
    static RECORD: std::sync::OnceLock<Vec<Tick>> = std::sync::OnceLock::new();
    RECORD.get_or_init(|| {
        let target = facing_clear_of("gallbladder", -Vector3::z(), "duodenum");
        run(push(&target, 0.012, PUSH_S, 0.5), TICKS).1
    })
}

fn liver_pair(tick: &Tick) -> &pgd_surgery::contact::PairReport {
    let (g, l) = (organ("gallbladder").0, organ("liver").0);
    &tick.pairs.iter().find(|p| (p.0, p.1) == (g, l)).unwrap().2
}

#[test]
fn pressing_the_gallbladder_into_the_liver_deforms_the_liver_and_stays_shallow() {
    let record = pushed();
    let last = record.last().unwrap();
    let report = liver_pair(last);
    let (l, liver) = organ("liver");
    let moved_m = largest_displacement_m(liver, &last.organs[l]);
    eprintln!("{report:?}; liver moved {:.3} mm", moved_m * 1e3);
    assert!(report.nodes_in_contact > 0, "{report:?}");
    assert!(report.force_on_shell_n.norm() > 1e-3, "{report:?}");
    // The liver is displaced by the contact alone (the tool never touches it).
    assert!(last.organs[l].loads.iter().all(|load| !load.is_active()));
    assert!(moved_m > 0.05e-3, "liver moved {moved_m} m");
    assert_shallow(record);
}

/// The liver's pointshell at `density` against a coarse field that holds the whole liver.
fn liver_shell(density: PointshellDensity) -> Pointshell {
    let (_, liver) = organ("liver");
    let (_, gallbladder) = organ("gallbladder");
    let surface = ContactSurface::new(gallbladder).unwrap();
    let everywhere = DistanceSettings {
        spacing_m: 0.02,
        margin_m: 0.3,
    };
    let field = DistanceField::build(gallbladder, &surface, &everywhere);
    Pointshell::new(liver, gallbladder, &surface, &field, density)
}

/// A dense pointshell samples the liver's surface at its nodes and its triangles' centres:
/// with a lattice that holds the whole liver, it has one point per node and per accessible
/// triangle, and its points' areas add up to the nodes' (the surface is covered once; f32
/// sums, 1e-5 relative), each positive.
#[test]
fn a_dense_pointshell_covers_the_surface_once() {
    let (_, liver) = organ("liver");
    let (nodes, dense) = (
        liver_shell(PointshellDensity::Nodes),
        liver_shell(PointshellDensity::Dense),
    );
    assert_eq!(nodes.len(), liver.positions.len());
    assert_eq!(dense.len(), liver.positions.len() + liver.triangles.len());
    let total = |p: &Pointshell| p.area_m2.iter().map(|&a| a as f64).sum::<f64>();
    let (a, b) = (total(&nodes), total(&dense));
    eprintln!(
        "area {:.2} cm² at the nodes, {:.2} cm² densely",
        a * 1e4,
        b * 1e4
    );
    assert!(((a - b) / a).abs() < 1e-5, "{a} m² against {b} m²");
    assert!(dense.area_m2.iter().all(|&a| a > 0.0));
}

/// Thinned to 15 mm, the liver's pointshell keeps fewer points, none two closer than that,
/// every node within 15 mm of one kept, and the nodes' whole area (f32 sums, 1e-5 relative).
#[test]
fn a_sparse_pointshell_keeps_its_points_apart_and_covers_the_surface_once() {
    let (nodes, sparse) = (
        liver_shell(PointshellDensity::Nodes),
        liver_shell(PointshellDensity::Sparse(15)),
    );
    let total = |p: &Pointshell| p.area_m2.iter().map(|&a| a as f64).sum::<f64>();
    let (a, b) = (total(&nodes), total(&sparse));
    eprintln!(
        "{} nodes, {} kept 15 mm apart; area {:.2} cm² against {:.2} cm²",
        nodes.len(),
        sparse.len(),
        a * 1e4,
        b * 1e4
    );
    assert!(sparse.len() < nodes.len());
    assert!(((a - b) / a).abs() < 1e-5, "{a} m² against {b} m²");
    let spacing_m = 0.015;
    for (k, p) in sparse.rest_m.iter().enumerate() {
        assert!(
            sparse.rest_m[..k]
                .iter()
                .all(|q| (p - q).norm() as f64 >= spacing_m - 1e-6)
        );
    }
    for p in &nodes.rest_m {
        let nearest = sparse
            .rest_m
            .iter()
            .map(|q| (p - q).norm())
            .fold(f32::INFINITY, f32::min);
        assert!(
            (nearest as f64) < spacing_m + 1e-6,
            "a node {nearest} m from every point kept"
        );
    }
}

/// The gallbladder pressed into the liver with a dense pointshell: more points push, none
/// deeper than one lattice cell, and the forces on the two organs balance. Measured: 9
/// points against 6 nodes (2 and 2 while contact loads moved the organs through their modes
/// alone, which cleared the intrusion with a few forces).
#[test]
fn pressing_with_a_dense_pointshell_pushes_more_points_and_stays_shallow() {
    let target = facing("gallbladder", -Vector3::z());
    let (_, record) = run_on(dense_scene(), push(&target, 0.012, PUSH_S, 0.5), TICKS);
    let (dense, nodes) = (
        liver_pair(record.last().unwrap()),
        liver_pair(pushed().last().unwrap()),
    );
    eprintln!(
        "{} points push densely, {} nodes otherwise",
        dense.nodes_in_contact, nodes.nodes_in_contact
    );
    assert!(dense.nodes_in_contact > nodes.nodes_in_contact);
    assert_shallow(&record);
    assert_master_balances_shells(&record);
}

/// The gallbladder pressed into the liver with a sparse pointshell: contact still forms and
/// pushes the liver, no point kept sinks deeper than one lattice cell, and the forces on the
/// two organs balance. The total contact force is the press's, set by the tool and the two
/// organs' compliance, whatever points carry it: within 10 % of the nodes' (measured: 4 of 30
/// points push with 6.43 mN, 6 of 74 nodes with 6.37 mN). The nodes left out are not
/// tested and may sink between the points kept.
#[test]
fn pressing_with_a_sparse_pointshell_still_pushes_and_stays_shallow() {
    let target = facing("gallbladder", -Vector3::z());
    let (_, record) = run_on(sparse_scene(), push(&target, 0.012, PUSH_S, 0.5), TICKS);
    let (sparse, nodes) = (
        liver_pair(record.last().unwrap()),
        liver_pair(pushed().last().unwrap()),
    );
    let (f_sparse, f_nodes) = (
        sparse.force_on_shell_n.norm(),
        nodes.force_on_shell_n.norm(),
    );
    eprintln!(
        "{} of {} points push sparsely, {:.2} mN; {} of {} nodes otherwise, {:.2} mN",
        sparse.nodes_in_contact,
        sparse_scene().coupling.as_ref().unwrap().pairs[0]
            .pointshell()
            .len(),
        f_sparse * 1e3,
        nodes.nodes_in_contact,
        scene().coupling.as_ref().unwrap().pairs[0]
            .pointshell()
            .len(),
        f_nodes * 1e3
    );
    assert!(sparse.nodes_in_contact > 0);
    assert!(sparse.nodes_in_contact <= nodes.nodes_in_contact);
    assert!((f_sparse - f_nodes).abs() < 0.1 * f_nodes);
    assert_shallow(&record);
    assert_master_balances_shells(&record);
}

/// On every tick the master's contact force is the opposite of the shells' (1e-12).
fn assert_master_balances_shells(record: &[Tick]) {
    let g = organ("gallbladder").0;
    for tick in record {
        let on_shells: Vector3<f64> = tick.pairs.iter().map(|p| p.2.force_on_shell_n).sum();
        let on_master = tick.organs[g].coupling_force_n;
        assert!((on_master + on_shells).norm() <= 1e-12 * on_shells.norm().max(1e-9));
    }
}

/// No liver node ever deeper in the gallbladder than one lattice cell.
fn assert_shallow(record: &[Tick]) {
    let spacing = scene().coupling.as_ref().unwrap().pairs[0]
        .field()
        .spacing_m();
    let deepest = record
        .iter()
        .map(|t| liver_pair(t).deepest_m)
        .fold(0.0, f64::max);
    eprintln!(
        "deepest {:.3} mm, lattice cell {:.1} mm",
        deepest * 1e3,
        spacing * 1e3
    );
    assert!(deepest < spacing, "a liver node {deepest} m deep");
}

#[test]
fn contact_forces_on_the_two_organs_are_equal_and_opposite() {
    let (l, p) = (organ("liver").0, organ("pancreas").0);
    assert_master_balances_shells(pushed());
    for tick in pushed() {
        let on_shells: Vector3<f64> = tick.pairs.iter().map(|p| p.2.force_on_shell_n).sum();
        let shells = tick.organs[l].coupling_force_n + tick.organs[p].coupling_force_n;
        assert!((shells - on_shells).norm() <= 1e-15);
    }
}

/// The liver pair's total contact force per tick, and its peak.
fn contact_force_series(record: &[Tick]) -> (Vec<f64>, f64) {
    let totals: Vec<f64> = record
        .iter()
        .map(|t| liver_pair(t).force_on_shell_n.norm())
        .collect();
    let peak = totals.iter().copied().fold(0.0, f64::max);
    (totals, peak)
}

/// Once the gallbladder touches the liver during the push, contact holds on every tick, and
/// the force rises without zig-zagging: a force that turns back more than a handful of times
/// over the 1,700 ticks of contact is chattering (one steepest-descent step per tick turned
/// back 280 times). A turn counts when the force moves by more than 1e-4 of its peak on both
/// sides (5 µN on the push alone, far below what a haptic device renders): once the tool
/// stops, the tool's near-field corrections, which answer the contact a tick late, dither the
/// force by about 1e-5 of its peak for some 30 ticks before it settles.
fn assert_no_flicker_or_zig_zag(record: &[Tick]) {
    let (totals, peak) = contact_force_series(record);
    let first = totals
        .iter()
        .position(|&f| f > 0.0)
        .expect("contact begins");
    let off = totals[first..].iter().filter(|&&f| f == 0.0).count();
    let noise = 1e-4 * peak;
    let reversals = totals[first..]
        .windows(3)
        .filter(|w| {
            let (a, b) = (w[1] - w[0], w[2] - w[1]);
            a * b < 0.0 && a.abs() > noise && b.abs() > noise
        })
        .count();
    eprintln!("contact from tick {first}: {off} ticks without, {reversals} reversals of the force");
    assert_eq!(off, 0, "contact flickered off on {off} ticks");
    assert!(reversals <= 10, "the force turned back {reversals} times");
}

/// The push ramps the overlap over 2000 ticks: a smooth response changes by about 1/2000 of
/// the peak per tick; the bound allows ten times that, 0.5 % of the peak.
fn assert_smooth(record: &[Tick]) {
    let (totals, peak) = contact_force_series(record);
    let largest_step = totals
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "peak {peak:.5} N, largest step {largest_step:.2e} N ({:.2} % of peak)",
        100.0 * largest_step / peak
    );
    assert!(
        largest_step <= 0.005 * peak,
        "a step of {largest_step} N against a peak of {peak} N"
    );
}

#[test]
fn a_slow_push_keeps_contact_without_flicker_or_zig_zag() {
    assert_no_flicker_or_zig_zag(pushed());
}

/// Where the tool touches the gallbladder alone, the organ contact alone sets the force's
/// course: measured, 2 turns and steps of at most 0.32 % of the peak (0 and 0.09 % before the
/// field read the tool's near-field corrections, with which the gallbladder's whole response
/// reaches the liver and the force rises more steeply at the end of the push).
#[test]
fn a_slow_push_on_the_gallbladder_alone_changes_the_contact_force_smoothly() {
    assert_no_flicker_or_zig_zag(pushed_alone());
    assert_smooth(pushed_alone());
}

/// The push that also presses the duodenum, where the tip meets a groove: two parts of its
/// surface nearly as close. Found afresh each tick, the tool's contact point jumped 4 mm
/// across it at one tick, its force there stepped from 0.8 to 1.9 mN, the duodenum's carry
/// moved the gallbladder 0.6 mm at once, and the contact force stepped by 2.6 % of its peak.
/// Tracked from tick to tick (`ContactSurface::tracked`), it slides along its side: measured,
/// steps of at most 0.14 % (bound 0.5 %).
#[test]
fn a_slow_push_changes_the_contact_force_smoothly() {
    assert_smooth(pushed());
}

/// The exact signed distance (m) to a closed-enough triangle surface: the closest point's
/// distance, negative behind its triangle.
fn exact_distance(mesh: &parry3d::shape::TriMesh, x: &Vector3<f64>) -> f64 {
    use parry3d::query::PointQueryWithLocation;
    let (projection, (triangle, _)) =
        mesh.project_local_point_and_get_location(to_parry(&Point3::from(*x)), false);
    let t = mesh.triangle(triangle);
    let normal = from_parry(t.b - t.a)
        .coords
        .cross(&from_parry(t.c - t.a).coords);
    let offset = x - from_parry(projection.point).coords;
    offset.norm() * offset.dot(&normal).signum()
}

/// The gallbladder's accessible surface at the end of the push: deformed by its whole field
/// (`modes_only == false`) or by its modes alone, carried by the duodenum either way. The
/// dimples the liver's contact forces make are left out: the field does not carry them, the
/// contact adds them to each distance it reads (`local_compliance`, checked against full FEM).
fn deformed_gallbladder(modes_only: bool) -> Vec<[f32; 3]> {
    let last = pushed().last().unwrap();
    let (g, gallbladder) = organ("gallbladder");
    let mut deformation = last.organs[g].clone();
    deformation.coupling_points.clear();
    let surface = SurfaceModes::new(gallbladder);
    let mut at_vertices = vec![0.0; 3 * gallbladder.positions.len()];
    let mut positions = Vec::new();
    deformation.deformed_surface(gallbladder, &surface, &mut at_vertices, &mut positions);
    if modes_only {
        let mut field = vec![0.0; gallbladder.dof_count()];
        for (step, coefficients) in deformation.coefficients.iter().enumerate() {
            gallbladder.add_modes(step, coefficients, &mut field);
        }
        for (m, p) in positions.iter_mut().enumerate() {
            let node = gallbladder.positions[m] as usize;
            let rest = Vector3::from(gallbladder.position_coords_m[m].map(f64::from));
            let moved = rest
                + Vector3::from_column_slice(&field[3 * node..3 * node + 3])
                + deformation.carry.at(&rest);
            *p = [0, 1, 2].map(|c| moved[c] as f32);
        }
    }
    positions
}

/// p95 of the distance field's error (m) against the exact distance to the gallbladder at the
/// end of the push (deformed by its modes alone or by its whole field), at points 1.5 mm
/// inside to 3 mm outside every vertex of the accessible surface (the field's zero level
/// set): beyond 25 mm from the tool and within.
fn distance_errors(modes_only: bool) -> (f64, f64) {
    let last = pushed().last().unwrap();
    let (g, gallbladder) = organ("gallbladder");
    let deformation = &last.organs[g];
    let positions = deformed_gallbladder(modes_only);
    let mesh = pgd_surgery::parry_interop::trimesh(&positions, &gallbladder.triangles).unwrap();
    let coupling = scene().coupling.as_ref().unwrap();
    let distance = coupling.pairs[0].field();
    let alpha: Vec<f32> = deformation
        .coefficients
        .iter()
        .flatten()
        .map(|&c| c as f32)
        .collect();
    let mut near = NearField::new(scene().organs[g].1.clone());
    near.set_loads(&deformation.loads);
    near.gather();
    let shape = MasterShape {
        alpha: &alpha,
        near: (!modes_only).then_some(&near),
    };
    let mut cache = LatticeCache::default();
    cache.next_tick(distance, &shape);
    let normals = gallbladder.rest_normals();
    let tool = last.organs[g].loads[0].shares.first().map(|s| s.0).unwrap();
    let tool_at = Vector3::from(gallbladder.position_coords_m[tool].map(f64::from));
    let (mut near, mut far) = (Vec::new(), Vec::new());
    for (m, p) in positions.iter().enumerate() {
        // A position on no accessible triangle has no surface to measure from.
        if normals[m] == Vector3::zeros() {
            continue;
        }
        let rest = Vector3::from(gallbladder.position_coords_m[m].map(f64::from));
        for offset_mm in [-1.5, -0.5, 0.5, 1.5, 3.0] {
            let x = Vector3::from(p.map(f64::from)) + normals[m] * offset_mm * 1e-3;
            let q = deformation.carry.pull_back(&x);
            let Some(distance_m) = distance.distance_m(&q, &shape, &mut cache) else {
                continue;
            };
            let error = (distance_m - exact_distance(&mesh, &x)).abs();
            match (rest - tool_at).norm() > 0.025 {
                true => far.push(error),
                false => near.push(error),
            }
        }
    }
    let p95 = |e: &mut Vec<f64>| {
        e.sort_by(f64::total_cmp);
        e[e.len() * 95 / 100]
    };
    let (near95, far95) = (p95(&mut near), p95(&mut far));
    eprintln!(
        "distance error p95: {:.3} mm beyond the near field ({} points), {:.3} mm within it ({} points)",
        far95 * 1e3,
        far.len(),
        near95 * 1e3,
        near.len()
    );
    (far95, near95)
}

/// The field read with the modes alone, against the surface the modes alone move: the lattice
/// and its pull-back without the near-field part. The push moves the gallbladder about 12 mm;
/// the error should stay within a quarter of a lattice cell (measured: 0.22 / 0.23 mm).
#[test]
fn the_distance_field_agrees_with_the_exact_distance_to_the_modally_deformed_gallbladder() {
    let (far, near) = distance_errors(true);
    assert!(
        far.max(near) < 0.5e-3,
        "p95 {far} m far from the tool, {near} m near it"
    );
}

/// The field as the contact reads it (modes, the tool's near-field corrections at each
/// lattice node's closest rest point, carry) against the exact distance to the surface the
/// whole field moves: within a quarter of a lattice cell, p95, both within 25 mm of the tool,
/// where the corrections carry most of the coarse gallbladder's response, and beyond.
/// Measured: 0.23 mm beyond, 0.46 mm within; without the corrections 1.5 mm and 9.2 mm,
/// with them but two pull-back steps 1.9 mm within.
#[test]
fn the_distance_field_agrees_with_the_exact_distance_to_the_deformed_gallbladder() {
    let (far, near) = distance_errors(false);
    assert!(
        far.max(near) < 0.5e-3,
        "p95 {far} m far from the tool, {near} m near it"
    );
}

/// Paper 000 hangs the gallbladder and the pancreas from the duodenum: pressed 8 mm, 3 cm
/// from each interface, the duodenum's interface moves and the organ it carries moves with it
/// there (rms mismatch under a quarter of the motion). Measured: gallbladder 0.07 mm on
/// 5.4 mm; pancreas 1.04 mm on 6.2 mm. The pancreas hangs over a wider interface (46
/// positions, 24 mm rms from their centre, against 12 and 8 mm), which the duodenum strains
/// by some 5 % as it bends: a rigid carry cannot follow that, and an affine one (0.35 mm)
/// would stretch the whole pancreas by it.
#[test]
fn the_gallbladder_moves_with_the_duodenum_it_hangs_from() {
    assert_carried_by_the_duodenum("gallbladder");
}

#[test]
fn the_pancreas_moves_with_the_duodenum_it_hangs_from() {
    assert_carried_by_the_duodenum("pancreas");
}

fn assert_carried_by_the_duodenum(carried: &str) {
    let coupling = scene().coupling.as_ref().unwrap();
    let (d, duodenum) = organ("duodenum");
    let (g, _) = organ(carried);
    let attachment = coupling
        .attachments
        .iter()
        .find(|a| (a.carrier, a.carried) == (d, g))
        .unwrap();
    let interface = attachment.interface();
    // Pressed 3 cm from the interface, whose motion is then mostly the duodenum's bending.
    let target = carrier_point_near(duodenum, interface, 0.03);
    let (_, record) = run(push(&target, 0.008, 1.0, 0.2), 1300);
    let last = record.last().unwrap();
    let mut field = vec![0.0; duodenum.dof_count()];
    last.organs[d].field_into(duodenum, &mut field);
    let carry = last.organs[g].carry;
    let (mut moved, mut mismatch) = (0.0, 0.0);
    for &m in interface {
        let node = duodenum.positions[m] as usize;
        let u = Vector3::new(field[3 * node], field[3 * node + 1], field[3 * node + 2]);
        let x = Vector3::from(duodenum.position_coords_m[m].map(f64::from));
        moved += u.norm_squared();
        mismatch += (u - carry.at(&x)).norm_squared();
    }
    let n = interface.len() as f64;
    let (moved, mismatch) = ((moved / n).sqrt(), (mismatch / n).sqrt());
    eprintln!(
        "interface moved {:.3} mm rms, the carried {carried} differs by {:.3} mm rms; carry {:.3?} mm",
        moved * 1e3,
        mismatch * 1e3,
        (carry.translation_m * 1e3).as_slice()
    );
    assert!(moved > 0.5e-3);
    assert!(mismatch < 0.25 * moved);
}

/// Pressed where the tool touches the gallbladder alone, the liver behind it pushes back:
/// the trainee feels a firmer press than in the same scene with the organs' contact taken out
/// (attachments kept). Measured: 0.048 N against 0.011 N. The tool holds the surface under
/// it while the contact pushes, in the same tick, so the liver is felt through the tool.
#[test]
fn the_trainee_feels_the_liver_behind_the_gallbladder() {
    let target = facing_clear_of("gallbladder", -Vector3::z(), "duodenum");
    let felt = |scene: &HapticScene| {
        let device = Box::new(Scripted::new("push", push(&target, 0.012, PUSH_S, 0.5)));
        let mut haptic = HapticLoop::new(scene, device).unwrap();
        haptic.run_simulated(TICKS);
        haptic.hand::<DeviceForce>(0).unwrap().desired_n.norm()
    };
    let mut without_contact = scene().clone();
    if let Some(coupling) = &mut without_contact.coupling {
        std::sync::Arc::make_mut(coupling).pairs.clear();
    }
    let (coupled, alone) = (felt(scene()), felt(&without_contact));
    eprintln!("felt {coupled:.4} N with the liver behind, {alone:.4} N without");
    assert!(coupled > alone * 1.5);
}

/// The push of the other tests also grazes the duodenum. Pressed where the tool touches the
/// gallbladder alone, the contact pushes the gallbladder back onto the tool, which holds it:
/// solved one after the other, tick by tick, the two fought and liver nodes sank 12 mm after
/// about 1.2 s. Solved together, the deepest liver node stays under 0.01 mm.
#[test]
fn pressed_where_the_tool_touches_the_gallbladder_alone_the_liver_stays_out() {
    assert_shallow(pushed_alone());
}

/// While the contact pushes the gallbladder back onto the tool, the tool holds the surface
/// under its tip within the tick: the patch-averaged displacement of the whole deformed field
/// (modes, near-field corrections and carry, evaluated afresh after the tick) puts the
/// surface at the tip's sphere along the normal and leaves it where it was at rest sideways.
/// Tolerance 0.05 mm (measured: 0.007 mm and 0.018 mm at most): the tick moves the tool's load
/// by the linearized answer, exact for this linear vademecum but for the patch and its normal,
/// which the tick keeps. Left for the next tick instead, the contact's push of one tick
/// (about 0.2 mm here, the floppy gallbladder moving 6.8 mm per mN) would open the gap.
#[test]
fn the_tool_holds_the_surface_under_it_while_the_contact_pushes() {
    use pgd_surgery::app::haptic::{
        HandTouches, OrganBody, OrganCoupling, OrganDeformation, OrganIndex, TickClock, Tool,
    };
    use pgd_surgery::devices::TICK_S;
    let target = facing_clear_of("gallbladder", -Vector3::z(), "duodenum");
    let device = Box::new(Scripted::new("push", push(&target, 0.012, PUSH_S, 0.5)));
    let mut haptic = HapticLoop::new(scene(), device).unwrap();
    let (g, l) = (organ("gallbladder").0, organ("liver").0);
    let mut checked = 0;
    for tick in 0..TICKS {
        haptic.tick(TickClock {
            tick,
            time_s: tick as f64 * TICK_S,
            overruns_in_a_row: 0,
        });
        let tool = haptic.hand::<Tool>(0).unwrap();
        let (tip, radius) = (tool.sample.unwrap().tip_m, tool.probe.tip_radius_m);
        let world = haptic.world_mut();
        let pushing = world
            .resource::<OrganCoupling>()
            .0
            .pairs
            .iter()
            .any(|p| (p.master, p.shell) == (g, l) && p.report().nodes_in_contact > 0);
        if !pushing || tick % 50 != 0 {
            continue;
        }
        let (body, touch, deformation) = world
            .query::<(&OrganIndex, &OrganBody, &HandTouches, &OrganDeformation)>()
            .iter(world)
            .find(|(i, ..)| i.0 == g)
            .map(|(_, b, t, d)| (b.clone(), t.0[0].clone(), d.0.clone()))
            .unwrap();
        let contact = touch.contact.expect("the tool presses the gallbladder");
        let vademecum = &body.vademecum;
        let mut now = deformation.clone();
        now.evaluate(vademecum);
        let mut field = vec![0.0; vademecum.dof_count()];
        now.field_into(vademecum, &mut field);
        let under: Vector3<f64> = touch
            .patch
            .shares
            .iter()
            .map(|&(m, share)| {
                let node = vademecum.positions[m] as usize;
                let rest = Vector3::from(vademecum.position_coords_m[m].map(f64::from));
                let u = Vector3::new(field[3 * node], field[3 * node + 1], field[3 * node + 2]);
                (u + now.carry.at(&rest)) * share
            })
            .sum();
        let n = contact.hit.normal;
        let gap = (tip - contact.hit.point_m - under).dot(&n) - radius;
        let sideways = (under - n * under.dot(&n)).norm();
        eprintln!(
            "tick {tick}: depth {:.2} mm, gap {:.4} mm, sideways {:.4} mm",
            contact.depth_m * 1e3,
            gap * 1e3,
            sideways * 1e3
        );
        assert!(gap.abs() < 0.05e-3, "gap {gap} m at tick {tick}");
        assert!(sideways < 0.05e-3, "sideways {sideways} m at tick {tick}");
        checked += 1;
    }
    assert!(checked > 10, "{checked} ticks checked");
}
