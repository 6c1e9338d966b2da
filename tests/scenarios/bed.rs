//! The gallbladder's bed in the default scene: ties where the coarse gallbladder faces the
//! liver.

use std::sync::Arc;

use nalgebra::Vector3;
use pgd_surgery::contact::{ContactSurface, Coupling, CouplingSettings};
use pgd_surgery::dissection::{Bed, BedError, CohesiveLaw, TiedOrgans};
use pgd_surgery::pgd::{Deformation, Vademecum, load};

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
        let at = Vector3::from(gallbladder.position_coords_m[tie.position].map(f64::from));
        let hit = surface.closest(&at).unwrap();
        assert!((at - hit.point_m).norm() <= 3e-3);
    }
    let pancreas = coarse("pancreas");
    match Bed::on(law, &pancreas, &surface, 3e-3) {
        Err(BedError::NotFacing { nearest_m, .. }) => assert!(nearest_m > 3e-3),
        Ok(bed) => panic!("the pancreas tied to the liver by {} ties", bed.ties.len()),
    }
}

/// The gallbladder and the liver of the coarse scene, as a coupling with no contact pairs
/// (the ties alone between them), the bed between them and a deformation for each.
struct Tied {
    organs: [Arc<Vademecum>; 2],
    coupling: Coupling,
    tied: TiedOrgans,
    deformations: [Deformation; 2],
}

impl Tied {
    fn new() -> Self {
        let organs = [coarse("gallbladder"), coarse("liver")].map(Arc::new);
        let named: Vec<(String, Arc<Vademecum>)> = ["gallbladder", "liver"]
            .into_iter()
            .map(String::from)
            .zip(organs.iter().cloned())
            .collect();
        let settings = CouplingSettings {
            master: "none".into(),
            ..CouplingSettings::default()
        };
        let (coupling, _) = Coupling::new(&named, &[], &settings, None).unwrap();
        let surface = ContactSurface::new(&organs[1]).unwrap();
        let bed = Bed::on(CohesiveLaw::gallbladder_bed(), &organs[0], &surface, 3e-3).unwrap();
        let tied = TiedOrgans::new(bed, (0, organs[0].clone()), (1, organs[1].clone()));
        let deformations = [0, 1].map(|o| Deformation::new(&organs[o], 1));
        Self {
            organs,
            coupling,
            tied,
            deformations,
        }
    }

    /// One tick as the contact stage runs it.
    fn tick(&mut self) {
        for (o, deformation) in self.deformations.iter_mut().enumerate() {
            deformation.evaluate(&self.organs[o]);
            self.coupling.read(o, deformation, &[]);
        }
        self.coupling.tick();
        self.tied.tick(&mut self.coupling);
        for (o, deformation) in self.deformations.iter_mut().enumerate() {
            self.coupling.write(o, deformation);
        }
    }

    /// Each organ's field of its modes (the near field of the pull left out).
    fn fields(&self) -> [Vec<f64>; 2] {
        [0, 1].map(|o| modal_field(&self.organs[o], &self.deformations[o]))
    }
}

/// An organ's field of its modes: what its coefficients move, without the near field of its
/// loads.
fn modal_field(vademecum: &Vademecum, deformation: &Deformation) -> Vec<f64> {
    let mut u = vec![0.0; vademecum.dof_count()];
    for (step, coefficients) in deformation.coefficients.iter().enumerate() {
        vademecum.add_modes(step, coefficients, &mut u);
    }
    u
}

/// The displacement (m) of a blend of load positions in a field.
fn blend_moved(vademecum: &Vademecum, u: &[f64], blend: &[(usize, f64)]) -> Vector3<f64> {
    blend
        .iter()
        .map(|&(m, w)| {
            let node = vademecum.positions[m] as usize;
            Vector3::new(u[3 * node], u[3 * node + 1], u[3 * node + 2]) * w
        })
        .sum()
}

/// The gallbladder pulled off the liver at the middle of its bed, 0.2 N over a patch, held:
/// the ties settle within a few hundred ticks, each carrying its secant stiffness times the
/// separation that both organs' fields of modes leave between its ends (to 1e-3 of the
/// largest force); the pulled point moves a hundredth of what it does free, and the liver
/// takes what the gallbladder's ties take.
#[test]
fn the_bed_holds_the_gallbladder_to_the_liver_through_both_organs_fields() {
    let mut tied = Tied::new();
    let centre = tied.tied.bed.ties.len() / 2;
    let tie = tied.tied.bed.ties[centre];
    let pull = tie.normal.into_inner() * 0.2;
    let load = &mut tied.deformations[0].loads[0];
    load.shares = tied.organs[0].patch_centred_on(tie.position);
    load.force_n = pull;
    let mut free = tied.deformations[0].clone();
    free.evaluate(&tied.organs[0]);
    let u = modal_field(&tied.organs[0], &free);
    let free_moved_m = blend_moved(&tied.organs[0], &u, &[(tie.position, 1.0)]);
    let mut last = Vector3::zeros();
    for _ in 0..400 {
        tied.tick();
        let force = tied.tied.report().force_on_freed_n;
        assert!(force.iter().all(|c| c.is_finite()));
        last = force;
    }
    let fields = tied.fields();
    let law = tied.tied.bed.law;
    let mut worst = 0.0f64;
    let mut largest = 0.0f64;
    for (t, force) in tied.tied.bed.ties.iter().zip(tied.tied.forces_n()) {
        let freed = blend_moved(&tied.organs[0], &fields[0], &[(t.position, 1.0)]);
        let corners = tied.organs[1].triangles[t.facing.triangle];
        let facing: Vec<(usize, f64)> = (0..3)
            .map(|c| (corners[c] as usize, t.facing.barycentric[c]))
            .collect();
        let base = blend_moved(&tied.organs[1], &fields[1], &facing);
        let k = law.stiffness_pa_per_m * (1.0 - t.state.damage(&law)) * t.area_m2;
        let expected = -(freed - base) * k;
        worst = worst.max((force - expected).norm());
        largest = largest.max(force.norm());
    }
    let held_moved_m = blend_moved(&tied.organs[0], &fields[0], &[(tie.position, 1.0)]);
    eprintln!(
        "ties take {:.3} N of the 0.2 N pull; worst tie off its law by {:.2e} N of {:.2e} N; \
         the pulled point moves {:.2} mm tied, {:.2} mm free",
        -last.dot(&tie.normal),
        worst,
        largest,
        held_moved_m.norm() * 1e3,
        free_moved_m.norm() * 1e3
    );
    assert!(
        worst <= 1e-3 * largest,
        "worst {worst:e} N of {largest:e} N"
    );
    assert!(held_moved_m.norm() < 0.01 * free_moved_m.norm());
    let liver_force = tied.deformations[1].coupling_force_n;
    assert!((liver_force + last).norm() <= 1e-12 * last.norm().max(1.0));
}
