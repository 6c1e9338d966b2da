//! The tool touches the surface as the organ's other loads have moved it, not the rest surface.

use nalgebra::Vector3;
use pgd_surgery::app::haptic::{HandTouches, OrganDeformation};
use pgd_surgery::contact::ContactSurface;
use pgd_surgery::devices::{DeviceSample, SafetySettings, Trajectory, TrajectoryRow};
use pgd_surgery::pgd::{Deformation, PatchLoad, SurfacePoint, Vademecum};

use crate::common::{TIP_RADIUS_M, haptic, liver, run, scripted, target};

/// The tool's contact depth (m) with the tip at `tip_m`, the liver also loaded by `held`.
fn depth_with(held: &PatchLoad, tip_m: Vector3<f64>) -> Option<(f64, Vector3<f64>)> {
    let still = Trajectory {
        rows: vec![TrajectoryRow::new(0.0, &DeviceSample::at(tip_m))],
    };
    let mut haptic = haptic(scripted(still), SafetySettings::default());
    let world = haptic.world_mut();
    let mut organs = world.query::<&mut OrganDeformation>();
    organs.single_mut(world).unwrap().0.loads.push(held.clone());
    run(&mut haptic, 1);
    let world = haptic.world_mut();
    let touches = world.query::<&HandTouches>().single(world).unwrap();
    touches.0[0].contact.map(|c| (c.depth_m, c.moved_m))
}

/// A held load pushes the liver in by millimetres where the tool comes. A tip 2 mm into the
/// rest surface does not touch the moved surface; a tip 2 mm into the moved surface (averaged
/// over the tool's patch, as the press measures it) touches it 2 mm deep (tolerance 0.1 mm:
/// the normal is the rest surface's).
#[test]
fn the_tool_touches_the_surface_other_loads_have_moved() {
    let vademecum = &liver().vademecum;
    let target = target();
    let hit = ContactSurface::new(vademecum)
        .unwrap()
        .closest(&target.point_m)
        .unwrap();
    let held = PatchLoad {
        shares: vademecum.patch(&hit.at).shares,
        force_n: -target.normal * 0.3,
    };
    let field = vademecum.field(&hit.at, &held.force_n);
    let moved: Vector3<f64> = held
        .shares
        .iter()
        .map(|&(m, share)| whole_field_at_position(vademecum, m, &field) * share)
        .sum();
    let sunk_m = -moved.dot(&target.normal);
    assert!(
        sunk_m > 4e-3,
        "the held load should sink the surface: {sunk_m} m"
    );

    let into_rest = target.point_m + target.normal * (TIP_RADIUS_M - 2e-3);
    assert_eq!(
        depth_with(&PatchLoad::default(), into_rest).map(|c| c.0 > 1.9e-3),
        Some(true)
    );
    assert_eq!(
        depth_with(&held, into_rest),
        None,
        "touched the rest surface"
    );

    let into_moved = into_rest - target.normal * sunk_m;
    let (depth, seen_moved) = depth_with(&held, into_moved).expect("the tool should touch");
    eprintln!("depth {depth:.5} m, surface moved {seen_moved:?} (whole field {moved:?})");
    assert!(
        (seen_moved - moved).norm() < 1e-6 * moved.norm() + 1e-9,
        "{seen_moved:?}"
    );
    assert!((depth - 2e-3).abs() < 1e-4, "depth {depth} m");
}

/// A surface point's displacement from the whole field (`3 × nodes`) at its triangle's corners.
fn whole_field_at(vademecum: &Vademecum, at: &SurfacePoint, field: &[f64]) -> Vector3<f64> {
    vademecum.triangles[at.triangle]
        .iter()
        .zip(at.barycentric)
        .map(|(&m, l)| whole_field_at_position(vademecum, m as usize, field) * l)
        .sum()
}

/// A load position's displacement from the whole field.
fn whole_field_at_position(vademecum: &Vademecum, m: usize, field: &[f64]) -> Vector3<f64> {
    let n = vademecum.positions[m] as usize;
    Vector3::new(field[3 * n], field[3 * n + 1], field[3 * n + 2])
}

/// What a retraction task watches, a surface point's displacement under the organ's loads
/// (evaluated at that point only, every tick), is the whole field's there: at the loaded point
/// and at one 3 cm away (relative tolerance 1e-6).
#[test]
fn a_surface_point_moves_as_the_whole_field_says() {
    let vademecum = &liver().vademecum;
    let surface = ContactSurface::new(vademecum).unwrap();
    let target = target();
    let hit = surface.closest(&target.point_m).unwrap();
    let held = PatchLoad {
        shares: vademecum.patch(&hit.at).shares,
        force_n: -target.normal * 0.3 + Vector3::new(0.1, 0.0, 0.05),
    };
    let mut deformation = Deformation::new(vademecum, 1);
    deformation.loads[0] = held.clone();
    deformation.evaluate(vademecum);
    let field = vademecum.field(&hit.at, &held.force_n);
    let away = surface
        .closest(&(target.point_m + Vector3::new(0.03, 0.0, 0.0)))
        .unwrap();
    for at in [hit.at, away.at] {
        let expected = whole_field_at(vademecum, &at, &field);
        let watched = deformation.displacement(vademecum, &at);
        assert!(expected.norm() > 1e-4, "{expected:?}");
        assert!(
            (watched - expected).norm() < 1e-6 * expected.norm(),
            "{watched:?} against {expected:?}"
        );
    }
}
