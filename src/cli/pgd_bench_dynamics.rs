//! `pgd bench dynamics`: the four organs' linear vademecums (built if missing), their models
//! under the KSV law, the benchmark run, and the energy plot.

use std::path::Path;

use crate::bench::dynamics::{self, DynamicsBenchReport, DynamicsOrgan};
use crate::fem::{FemModel, Law};
use crate::mesh::organs::Organ;
use crate::pgd::{Vademecum, organ};
use crate::report::{LineChart, Series, line_chart};
use crate::store::{OnStale, VademecumSpec, ensure_vademecum};

/// What `pgd bench dynamics` was asked for.
pub struct DynamicsRequest<'a> {
    pub organs: &'a [Organ],
    pub modes: &'a [usize],
    pub scene_modes: usize,
    pub ticks: usize,
    pub vademecums: &'a Path,
}

/// Loads (or builds) each organ's linear vademecum, makes its KSV model, and runs the
/// benchmark.
pub fn bench_dynamics(request: &DynamicsRequest) -> Result<DynamicsBenchReport, String> {
    if request.ticks < 2 || request.modes.contains(&0) || request.scene_modes == 0 {
        return Err("ticks must be at least 2 and every basis size at least 1".into());
    }
    let loaded: Vec<(Organ, Vademecum, FemModel)> = request
        .organs
        .iter()
        .map(|&o| {
            let spec = VademecumSpec::default_in(request.vademecums, o, Law::Linear);
            let (vademecum, mesh) = ensure_vademecum(&spec, OnStale::Rebuild)?;
            let model = organ::clamped_model(mesh, organ::material(o, Law::KirchhoffSaintVenant))
                .map_err(|e| format!("{}: {e}", o.name()))?;
            Ok((o, vademecum, model))
        })
        .collect::<Result<_, String>>()?;
    let organs: Vec<DynamicsOrgan> = loaded
        .iter()
        .map(|(o, vademecum, model)| DynamicsOrgan {
            name: o.name(),
            model,
            vademecum,
        })
        .collect();
    dynamics::run(&organs, request.modes, request.scene_modes, request.ticks)
        .map_err(|e| e.to_string())
}

/// Each scheme's energy against time, relative to its start.
pub fn plot_energy(report: &DynamicsBenchReport, path: &Path) -> Result<(), String> {
    let trace = &report.energy;
    let series = trace
        .schemes
        .iter()
        .map(|(name, energy)| Series {
            name: name.clone(),
            points: trace
                .time_s
                .iter()
                .copied()
                .zip(energy.iter().copied())
                .collect(),
        })
        .collect();
    line_chart(
        path,
        &LineChart {
            title: format!(
                "{}: undamped swing, {} modes, 1 ms step",
                trace.organ, trace.modes
            ),
            x_label: "time (s)",
            y_label: "energy / initial energy",
            series,
        },
    )
}
