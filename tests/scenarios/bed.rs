//! The gallbladder's bed in the default scene: ties where the coarse gallbladder faces the
//! liver.

use pgd_surgery::contact::ContactSurface;
use pgd_surgery::dissection::{Bed, BedError, CohesiveLaw};
use pgd_surgery::pgd::{Vademecum, load};

use super::vademecums;

fn coarse(organ: &str) -> Vademecum {
    load(&vademecums().join(format!("{organ}.coarse.vdm"))).unwrap()
}

/// Within 3 mm the gallbladder's hepatic face is tied to the liver: a few dozen ties over a
/// patch of its surface (not all of it), each where the gallbladder lies within the gap of
/// the liver's surface; the pancreas, which does not face the liver so close, is refused.
#[test]
fn the_gallbladder_lies_in_a_bed_on_the_liver() {
    let (gallbladder, liver) = (coarse("gallbladder"), coarse("liver"));
    let surface = ContactSurface::new(&liver).unwrap();
    let law = CohesiveLaw::gallbladder_bed();
    let bed = Bed::on(law, &gallbladder, &surface, 3e-3).unwrap();
    let whole: f64 = gallbladder
        .position_areas_m2
        .iter()
        .map(|&a| f64::from(a))
        .sum();
    eprintln!(
        "{} ties over {:.1} cm², {:.1} % of the gallbladder's surface",
        bed.ties.len(),
        bed.area_m2() * 1e4,
        100.0 * bed.area_m2() / whole
    );
    assert!(bed.ties.len() >= 20, "{} ties", bed.ties.len());
    assert!(bed.area_m2() < 0.3 * whole);
    for tie in &bed.ties {
        let at =
            nalgebra::Vector3::from(gallbladder.position_coords_m[tie.position].map(f64::from));
        let hit = surface.closest(&at).unwrap();
        assert!((at - hit.point_m).norm() <= 3e-3);
    }
    let pancreas = coarse("pancreas");
    match Bed::on(law, &pancreas, &surface, 3e-3) {
        Err(BedError::NotFacing { nearest_m, .. }) => assert!(nearest_m > 3e-3),
        Ok(bed) => panic!("the pancreas tied to the liver by {} ties", bed.ties.len()),
    }
}
