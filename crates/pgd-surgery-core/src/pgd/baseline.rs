//! The brute-force alternative a nonlinear vademecum build must beat, timed on the same
//! machine in the same run: one full Newton path (with line search) per load parameter,
//! through the vademecum's load steps to its deepest one. Timing every parameter would take
//! hours on an organ, so a random sample is timed and the mean scaled to all of them.

use std::time::Instant;

use serde::Serialize;

use super::Vademecum;
use super::load_patches::parameter_load;
use super::tool_patch::inward_normal;
use crate::fem::{FemError, FemModel, Loads, NewtonSettings};

/// Newton's residual tolerance for the baseline: tighter than the secant fixed point's change
/// (1e-3), so that the baseline is not cheapened, and far from the reference solves' 1e-10.
const RELATIVE_TOLERANCE: f64 = 1e-6;

/// The timed sample and what it scales to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct NewtonBaseline {
    /// Load parameters timed.
    pub samples: usize,
    /// Of them, those whose Newton path failed (an element turned inside out, or no
    /// convergence): timed up to the failure.
    pub failed: usize,
    /// Uniform increments of each path: the first load step is one increment and the deepest
    /// is a whole number of them.
    pub increments: usize,
    pub deepest_m: f64,
    /// Mean seconds of one Newton path.
    pub seconds_per_load: f64,
    /// The loads of each of the vademecum's nonlinear steps: one per position.
    pub loads: usize,
    /// `seconds_per_load × loads`: the brute-force build of the same responses.
    pub estimated_seconds: f64,
}

/// Times `samples` Newton paths of `model` (the model `vademecum` was built for) at random load
/// positions (seeded by `seed`), each loaded as the build loads it at its deepest step: the
/// tool's patch centred on its position, pushing into the organ, whose linear response is
/// that step's depth. `None` for a vademecum with one (linear) step.
pub fn newton_baseline(
    model: &FemModel,
    vademecum: &Vademecum,
    samples: usize,
    seed: u64,
) -> Result<Option<NewtonBaseline>, FemError> {
    let levels = &vademecum.header.indentation_levels_m;
    let (Some(&first_m), Some(&deepest_m)) = (levels.get(1), levels.last()) else {
        return Ok(None);
    };
    let increments = ((deepest_m / first_m).round() as usize).max(1);
    let settings = NewtonSettings {
        load_steps: increments,
        relative_tolerance: RELATIVE_TOLERANCE,
        ..NewtonSettings::default()
    };
    let loads = vademecum.positions.len();
    let mut rng = fastrand::Rng::with_seed(seed);
    let (mut seconds, mut failed) = (0.0, 0);
    for _ in 0..samples {
        let force = nodal_load(model, vademecum, rng.usize(..loads), deepest_m)?;
        let clock = Instant::now();
        let solved = model.solve_static(&force, &settings);
        seconds += clock.elapsed().as_secs_f64();
        failed += usize::from(solved.is_err());
    }
    let seconds_per_load = seconds / samples.max(1) as f64;
    Ok(Some(NewtonBaseline {
        samples,
        failed,
        increments,
        deepest_m,
        seconds_per_load,
        loads,
        estimated_seconds: seconds_per_load * loads as f64,
    }))
}

/// The load at position `m` whose linear response is `depth_m` deep, as a nonlinear
/// vademecum's steps load it: the tool's patch centred on the position, pushing along its
/// inward normal.
fn nodal_load(
    model: &FemModel,
    vademecum: &Vademecum,
    m: usize,
    depth_m: f64,
) -> Result<Loads, FemError> {
    let compliance_m_per_n = f64::from(vademecum.reference_compliance_m_per_n[m]);
    let magnitude_n = match compliance_m_per_n > 0.0 {
        true => depth_m / compliance_m_per_n,
        false => 0.0,
    };
    let inward = inward_normal(&vademecum.position_normals[m]);
    let shares = vademecum.patch_centred_on(m);
    let nodal_shares = shares
        .iter()
        .map(|&(j, share)| (vademecum.positions[j] as usize, share));
    parameter_load(model.mesh().node_count(), nodal_shares, inward, magnitude_n)
}
