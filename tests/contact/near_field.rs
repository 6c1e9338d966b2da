//! The master's near-field displacement as the contact reads it ([`NearField`]) against the
//! whole deformed field (`Deformation::field_into`, which adds every node's corrections to the
//! modes): at every surface position, the same, and its largest motion.

use nalgebra::Vector3;
use pgd_surgery::contact::NearField;
use pgd_surgery::pgd::{Deformation, SurfacePoint};

use crate::common::{organ, scene};

/// The tool's 10 mN on the gallbladder's first triangle, and another load on a triangle
/// elsewhere: their corrections superpose.
fn loaded_gallbladder() -> (usize, Deformation) {
    let (g, gallbladder) = organ("gallbladder");
    let mut deformation = Deformation::new(gallbladder, 2);
    let at = |triangle| SurfacePoint {
        triangle,
        barycentric: [0.2, 0.3, 0.5],
    };
    let facing = gallbladder.triangle_facing(0).normalize();
    deformation.loads[0].shares = gallbladder.patch(&at(0)).shares;
    deformation.loads[0].force_n = -facing * 0.01;
    let other = gallbladder.triangles.len() / 2;
    deformation.loads[1].shares = gallbladder.patch(&at(other)).shares;
    deformation.loads[1].force_n = Vector3::new(0.002, -0.003, 0.004);
    deformation.evaluate(gallbladder);
    (g, deformation)
}

/// Within f32 rounding (1e-5 of the largest correction, 1e-12 m at least).
#[test]
fn the_near_field_is_the_whole_field_less_the_modes_at_every_surface_position() {
    let (g, deformation) = loaded_gallbladder();
    let (_, gallbladder) = organ("gallbladder");
    let mut whole = vec![0.0; gallbladder.dof_count()];
    deformation.field_into(gallbladder, &mut whole);
    for (step, coefficients) in deformation.coefficients.iter().enumerate() {
        let minus: Vec<f64> = coefficients.iter().map(|c| -c).collect();
        gallbladder.add_modes(step, &minus, &mut whole);
    }
    let mut near = NearField::new(scene().organs[g].1.clone());
    near.set_loads(&deformation.loads);
    near.gather();
    let correction = |m: usize| {
        let node = gallbladder.positions[m] as usize;
        Vector3::from_column_slice(&whole[3 * node..3 * node + 3])
    };
    let largest = (0..gallbladder.positions.len())
        .map(|m| correction(m).norm())
        .fold(0.0, f64::max);
    assert!(largest > 1e-5, "the loads' corrections reach {largest} m");
    let mut worst = 0.0f64;
    for m in 0..gallbladder.positions.len() {
        let read = Vector3::from(near.at(m)).map(f64::from);
        worst = worst.max((read - correction(m)).norm());
    }
    eprintln!(
        "largest correction {:.3} mm, worst difference {:.2e} m",
        largest * 1e3,
        worst
    );
    assert!(worst <= (1e-5 * largest).max(1e-12), "{worst} m");
    let bound = near.largest_m() as f64;
    assert!(
        (bound - largest).abs() <= 1e-5 * largest,
        "{bound} m against {largest} m"
    );
}

/// Before this tick's gather the near field reads zero, and on the next tick it moves half
/// way to the new loads' corrections each tick (the relaxation).
#[test]
fn the_near_field_follows_its_loads_half_a_tick_at_a_time() {
    let (g, deformation) = loaded_gallbladder();
    let (_, gallbladder) = organ("gallbladder");
    let mut near = NearField::new(scene().organs[g].1.clone());
    near.set_loads(&deformation.loads);
    assert!((0..gallbladder.positions.len()).all(|m| near.at(m) == [0.0; 3]));
    near.gather();
    let full: Vec<[f32; 3]> = (0..gallbladder.positions.len())
        .map(|m| near.at(m))
        .collect();
    let mut doubled = deformation.loads.clone();
    doubled.iter_mut().for_each(|l| l.force_n *= 2.0);
    let mut ticks = vec![];
    for _ in 0..3 {
        near.set_loads(&doubled);
        near.gather();
        ticks.push(
            (0..gallbladder.positions.len())
                .map(|m| near.at(m))
                .collect::<Vec<_>>(),
        );
    }
    let ratio = |now: &[[f32; 3]]| {
        let (a, b): (f64, f64) = now.iter().zip(&full).fold((0.0, 0.0), |(a, b), (n, f)| {
            let (n, f) = (
                Vector3::from(*n).map(f64::from),
                Vector3::from(*f).map(f64::from),
            );
            (a + n.dot(&f), b + f.norm_squared())
        });
        a / b
    };
    let ratios: Vec<f64> = ticks.iter().map(|t| ratio(t)).collect();
    eprintln!("near field over the first loads' after 1, 2, 3 ticks: {ratios:?}");
    for (ratio, expected) in ratios.iter().zip([1.5, 1.75, 1.875]) {
        assert!((ratio - expected).abs() < 1e-5, "{ratios:?}");
    }
}

/// How far the near field moved a surface position since the last tick, as it reports it for
/// the contact's skip of clear nodes: the largest change read at the positions, tick by tick.
/// The ticks follow the contact's calls (gathered while it is active): it appears, moves
/// towards doubled loads, decays once the loads are gone; the last tick is not gathered, as
/// once the field is negligible, and it reads zero.
#[test]
fn the_near_field_reports_how_far_it_moved_since_the_last_tick() {
    let (g, deformation) = loaded_gallbladder();
    let (_, gallbladder) = organ("gallbladder");
    let mut near = NearField::new(scene().organs[g].1.clone());
    let read = |near: &NearField| -> Vec<Vector3<f64>> {
        (0..gallbladder.positions.len())
            .map(|m| Vector3::from(near.at(m)).map(f64::from))
            .collect()
    };
    let mut doubled = deformation.loads.clone();
    doubled.iter_mut().for_each(|l| l.force_n *= 2.0);
    let none = Vec::new();
    let mut last = read(&near);
    let ticks = [
        (&deformation.loads, true),
        (&doubled, true),
        (&doubled, true),
        (&none, true),
        (&none, false),
    ];
    for (loads, gathered) in ticks {
        near.set_loads(loads);
        assert!(near.is_active(), "the field is carried while it decays");
        if gathered {
            near.gather();
        }
        let now = read(&near);
        let moved = now
            .iter()
            .zip(&last)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        let reported = near.largest_change_m() as f64;
        eprintln!("moved {moved:.3e} m, reported {reported:.3e} m");
        assert!(moved > 0.0);
        assert!(
            (reported - moved).abs() <= 1e-5 * moved,
            "{reported} m against {moved} m"
        );
        last = now;
    }
    assert!(last.iter().all(|u| *u == Vector3::zeros()));
}

/// The vectorized sum of a correction entry (`LocalPart::add_residual`, four lanes per
/// column) is the entry's residual, at every entry including the last, whose third column
/// ends the array; lane 3 is scratch.
#[test]
fn a_correction_entry_summed_four_lanes_at_a_time_is_its_residual() {
    let (_, gallbladder) = organ("gallbladder");
    let local = &gallbladder.steps[0].local;
    let force = [0.004f32, -0.01, 0.007];
    let entries = local.correction.len() / 9;
    let mut checked = 0;
    for e in (0..entries).step_by(97).chain([entries - 1]) {
        let mut sum = [0.0f32, 0.0, 0.0, 5.0];
        local.add_residual(e, &force, &mut sum);
        let expected = local.residual(e, &Vector3::from(force));
        for c in 0..3 {
            // f32 rounding of a three-term sum, relative to its terms.
            let term = |d: usize| local.correction[9 * e + 3 * d + c] * force[d];
            let scale: f32 = (0..3).map(|d| term(d).abs()).sum();
            assert!(
                (sum[c] - expected[c]).abs() <= 1e-6 * scale,
                "entry {e}, component {c}: {} against {}",
                sum[c],
                expected[c]
            );
            checked += (scale > 0.0) as usize;
        }
    }
    assert!(checked > 100, "only {checked} non-zero components");
}
