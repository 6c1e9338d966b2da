//! The dimples contact forces make (the near-field part of the contact's compliance) against
//! a full FEM solve of each organ under the same forces.

use nalgebra::Vector3;
use pgd_surgery::fem::{FemModel, Law};
use pgd_surgery::mesh::organs::{Organ, OrganSettings, generate};
use pgd_surgery::pgd::organ::{clamped_model, material};
use pgd_surgery::pgd::{Deformation, RestStiffness, Vademecum};

use super::common::organ;

/// A coarse scene's organ as a full FEM model: the coarse detail's mesh (a quarter of the
/// papers' node count) and the organ's linear tissue, clamped where its vademecum is.
fn coarse_model(organ: Organ) -> FemModel {
    let settings = OrganSettings {
        resolution: 0.25,
        ..OrganSettings::default()
    };
    let mesh = generate(organ, &settings).unwrap();
    clamped_model(mesh, material(organ, Law::Linear)).unwrap()
}

/// The exact displacement field (m) of `model` under the contact's point loads on it.
fn exact_field(model: &FemModel, vademecum: &Vademecum, deformation: &Deformation) -> Vec<f64> {
    let stiffness = RestStiffness::new(model).unwrap();
    let mut load = vec![0.0; stiffness.full_count()];
    for point in &deformation.coupling_points {
        let node = vademecum.positions[point.position] as usize;
        for c in 0..3 {
            load[3 * node + c] += point.force_n[c];
        }
    }
    let mut u = stiffness.restrict(&load);
    stiffness.solve_block(&mut u);
    stiffness.extend(&u)
}

/// The displacement the contact loads give the organ in the trainer: their modes (the
/// coupling's coefficients), and, unless `modes_only`, their near-field corrections. The
/// tool's load is left out on both sides: its accuracy is the vademecum's (`tests/pgd`).
fn trainer_field(vademecum: &Vademecum, deformation: &Deformation, modes_only: bool) -> Vec<f64> {
    let mut u = vec![0.0; vademecum.dof_count()];
    for (step, coefficients) in deformation.coupling.iter().enumerate() {
        vademecum.add_modes(step, coefficients, &mut u);
        if !modes_only {
            for point in &deformation.coupling_points {
                let shares = [(point.position, 1.0)];
                vademecum.add_corrections(step, &shares, &point.force_n, &mut u);
            }
        }
    }
    u
}

/// The errors at the contact loads (relative) of `name`'s field at the end of the push with
/// its corrections and with its modes alone, against full FEM.
fn errors_at_contact(name: &str, organ_kind: Organ) -> (f64, f64) {
    let last = super::pushed_alone().last().unwrap();
    let (index, vademecum) = organ(name);
    let deformation = &last.organs[index];
    assert!(
        deformation.coupling_points.len() >= 3,
        "the contact loads {name} at several positions"
    );
    let model = coarse_model(organ_kind);
    assert_eq!(model.mesh().node_count(), vademecum.header.node_count);
    let exact = exact_field(&model, vademecum, deformation);
    let [whole, modes] = [false, true].map(|modes_only| {
        let u = trainer_field(vademecum, deformation, modes_only);
        error_at_loads(vademecum, deformation, &u, &exact)
    });
    eprintln!(
        "{name}: displacement at the {} contact loads against full FEM: {:.2} % off, {:.1} % with the modes alone",
        deformation.coupling_points.len(),
        100.0 * whole,
        100.0 * modes
    );
    (whole, modes)
}

/// The largest error of `u` against `exact` at the loaded positions, relative to the largest
/// exact displacement there.
fn error_at_loads(liver: &Vademecum, deformation: &Deformation, u: &[f64], exact: &[f64]) -> f64 {
    let at = |field: &[f64], position: usize| {
        let node = liver.positions[position] as usize;
        Vector3::from_column_slice(&field[3 * node..3 * node + 3])
    };
    let positions = deformation.coupling_points.iter().map(|p| p.position);
    let (error, size) = positions.fold((0.0f64, 0.0f64), |(e, s), m| {
        (
            (at(u, m) - at(exact, m)).norm().max(e),
            at(exact, m).norm().max(s),
        )
    });
    error / size
}

/// At the end of the push with the tool on the gallbladder alone, the liver is loaded by
/// the contact forces only. Under those forces a full FEM solve of its mesh moves the loaded
/// positions as the trainer does within 5 % of the largest displacement there (the
/// corrections are exact within the 25 mm local radius; the modes carry what comes from
/// farther). Measured: 3.2 %; the modes alone miss 48 %: that is how much stiffer the contact
/// was before it had the corrections.
#[test]
fn the_liver_dimples_under_the_contact_forces_as_a_full_fem_solve_does() {
    let (whole, modes) = errors_at_contact("liver", Organ::Liver);
    assert!(whole < 0.05, "{whole} with the corrections");
    assert!(modes > 2.0 * whole);
}

/// The gallbladder under the liver's reactions, against full FEM at the reactions, within
/// 5 %. Measured: 0.4 %, and 2.6 % with the modes alone: the floppy coarse gallbladder's
/// modes carry most of its answer to loads spread over its top.
#[test]
fn the_gallbladder_dimples_under_the_reactions_as_a_full_fem_solve_does() {
    let (whole, modes) = errors_at_contact("gallbladder", Organ::Gallbladder);
    assert!(whole < 0.05, "{whole} with the corrections");
    assert!(modes > 2.0 * whole);
}
