//! `pgd fit`: the exponential law fitted to a uniaxial test of tissue, read from CSV, printed
//! with the command that builds with it and drawn against the data.

use std::fmt;
use std::path::Path;

use serde::Serialize;

use crate::fem::{
    ExponentialFit, Law, Material, TISSUE_DENSITY_KG_M3, UniaxialPoint, fit_exponential,
    uniaxial_nominal_stress_pa,
};
use crate::report::{LineChart, Series, line_chart};

/// The fit of one test file.
#[derive(Debug, Serialize)]
pub struct FitReport {
    pub source: String,
    pub points: usize,
    pub fit: ExponentialFit,
    /// The data, as `(stretch, nominal stress in Pa)`.
    #[serde(skip)]
    pub data: Vec<UniaxialPoint>,
}

/// Reads `path` (columns `stretch,nominal_stress_pa`, one row per measurement) and fits the
/// exponential law at Poisson's ratio `poisson`. Errors name the file and the line.
pub fn fit_uniaxial_test(path: &Path, poisson: f64) -> Result<FitReport, String> {
    let data = read_test(path)?;
    let fit = fit_exponential(&data, poisson).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(FitReport {
        source: path.display().to_string(),
        points: data.len(),
        fit,
        data,
    })
}

fn read_test(path: &Path) -> Result<Vec<UniaxialPoint>, String> {
    let at = |line: u64, why: String| format!("{}: line {line}: {why}", path.display());
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(path)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let mut data = Vec::new();
    for record in reader.deserialize::<UniaxialPoint>() {
        let point = record.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line());
            at(
                line,
                format!("{e} (expected the columns stretch,nominal_stress_pa)"),
            )
        })?;
        data.push(point);
    }
    Ok(data)
}

impl fmt::Display for FitReport {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        let fit = &self.fit;
        writeln!(
            f,
            "{}: {} points, ν = {}",
            self.source, self.points, fit.poisson
        )?;
        writeln!(
            f,
            "  exponential: E = {:.1} Pa, b = {:.3}, rms residual {:.3} Pa",
            fit.young_pa, fit.stiffening, fit.rms_pa
        )?;
        writeln!(
            f,
            "  neo-Hookean: E = {:.1} Pa, rms residual {:.3} Pa",
            fit.neo_hookean_young_pa, fit.neo_hookean_rms_pa
        )?;
        writeln!(
            f,
            "build with it: pgd build <organ> --law exponential --young-pa {:.1} --stiffening {:.3} --poisson {}",
            fit.young_pa, fit.stiffening, fit.poisson
        )
    }
}

/// Draws the data and both fits' stress against stretch into `path`.
pub fn plot_fit(report: &FitReport, path: &Path) -> Result<(), String> {
    let mut data: Vec<(f64, f64)> = report
        .data
        .iter()
        .map(|p| (p.stretch, p.nominal_stress_pa))
        .collect();
    data.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (low, high) = (data[0].0.min(1.0), data[data.len() - 1].0.max(1.0));
    let curve = |name: &str, material: Material| Series {
        name: name.to_owned(),
        points: (0..=100)
            .map(|i| low + (high - low) * i as f64 / 100.0)
            .map(|s| (s, uniaxial_nominal_stress_pa(&material, s)))
            .collect(),
    };
    let fit = &report.fit;
    let exponential = fit.material().map_err(|e| e.to_string())?;
    let neo_hookean = Material::new(
        Law::NeoHookean,
        fit.neo_hookean_young_pa,
        fit.poisson,
        TISSUE_DENSITY_KG_M3,
    )
    .map_err(|e| e.to_string())?;
    line_chart(
        path,
        &LineChart {
            title: format!("{}: uniaxial test and fits", report.source),
            x_label: "stretch",
            y_label: "nominal stress (Pa)",
            series: vec![
                Series {
                    name: "measured".into(),
                    points: data,
                },
                curve(
                    &format!("exponential, b = {:.2}", fit.stiffening),
                    exponential,
                ),
                curve("neo-Hookean", neo_hookean),
            ],
        },
    )
}
