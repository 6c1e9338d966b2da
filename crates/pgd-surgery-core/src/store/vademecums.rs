//! The vademecums the trainer runs on: found in `vademecums/`, checked against the organ's
//! mesh and material, and rebuilt (with progress shown) when missing or stale, so that the
//! trainer never runs on a vademecum built for something else.

use std::path::{Path, PathBuf};

use crate::fem::{FemModel, Inclusion, Law, Material};
use crate::mesh::TetMesh;
use crate::mesh::io::ImportOptions;
use crate::mesh::organs::{Organ, OrganSettings, region};
use crate::pgd::{
    self, BuildReport, BuildSettings, OrganModel, Progress, RegionSettings, Vademecum,
    VademecumError, default_load_steps_m,
};

use super::{Bar, OrganSource};
use crate::report;

/// What to do with a missing or stale vademecum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OnStale {
    /// Build it now and save it, showing progress.
    Rebuild,
    /// Fail with the command that builds it.
    Refuse,
    /// A nonlinear one: run on the organ's linear vademecum (built now if need be) while it
    /// builds in the background (the app chooses the linear one); otherwise as `Rebuild`.
    Meanwhile,
}

/// What the trainer wants of one organ's vademecum: the organ's mesh (generated at a
/// resolution, or from a file), its material under a law, built with these settings, kept in
/// `file`.
#[derive(Clone, Debug)]
pub struct VademecumSpec {
    /// What the organ is called in messages.
    pub name: String,
    pub source: OrganSource,
    pub law: Law,
    pub mesh: OrganSettings,
    /// The tissue's Young's modulus (Pa) when not the organ's own.
    pub young_pa: Option<f64>,
    /// The tissue's Poisson's ratio when not the organs' own.
    pub poisson: Option<f64>,
    /// The exponential law's stiffening when not its default.
    pub stiffening: Option<f64>,
    /// Stiffer or softer regions in the organ's tissue (none by default).
    pub inclusions: Vec<Inclusion>,
    pub build: BuildSettings,
    pub file: PathBuf,
}

impl VademecumSpec {
    /// Where the distance field of this vademecum is kept when its organ is a contact master:
    /// beside it, `.vdf` for `.vdm`.
    pub fn field_file(&self) -> PathBuf {
        self.file.with_extension("vdf")
    }

    /// The organ's default vademecum under `law` (the papers' mesh, default settings) under
    /// `dir`.
    pub fn default_in(dir: &Path, organ: Organ, law: Law) -> Self {
        let file = dir.join(vademecum_file_name(organ.name(), law));
        Self::new(organ.name(), OrganSource::Generated(organ), law, file)
    }

    /// The vademecum of the organ `name` from `source` under `law`, the organ's default
    /// settings and tissue, kept in `file`.
    pub fn new(name: &str, source: OrganSource, law: Law, file: PathBuf) -> Self {
        let build = BuildSettings::for_organ_law(source.organ(), law);
        Self {
            name: name.to_owned(),
            source,
            law,
            mesh: OrganSettings::default(),
            young_pa: None,
            poisson: None,
            stiffening: None,
            inclusions: Vec::new(),
            build,
            file,
        }
    }

    /// The command a user runs to build it (options left at their defaults are left out).
    pub fn build_command(&self) -> String {
        let law = self.law.name();
        let source = match &self.source {
            OrganSource::Generated(organ) => organ.name().to_owned(),
            OrganSource::File(file) => {
                let regions = &file.regions;
                let selectors = (regions.clamp.iter().map(|s| format!(" --clamp {s}"))).chain(
                    regions
                        .accessible
                        .iter()
                        .map(|s| format!(" --accessible {s}")),
                );
                file.path.display().to_string() + &selectors.collect::<String>()
            }
        };
        let mut command = format!("cargo run --release --bin pgd -- build {source} --law {law}");
        let mesh = OrganSettings::default();
        let build = BuildSettings::for_organ_law(self.source.organ(), self.law);
        // A mesh file's mesh is as it is: the generator's settings do not apply.
        if let OrganSource::Generated(_) = self.source {
            if self.mesh.resolution != mesh.resolution {
                command += &format!(" --resolution {}", self.mesh.resolution);
            }
            if self.mesh.seed != mesh.seed {
                command += &format!(" --seed {}", self.mesh.seed);
            }
            if self.mesh.cornea_layers != mesh.cornea_layers {
                command += &format!(" --cornea-layers {}", self.mesh.cornea_layers);
            }
        }
        if self.build.tool_tip_radius_m != build.tool_tip_radius_m {
            command += &format!(" --tool-radius-mm {}", self.build.tool_tip_radius_m * 1e3);
        }
        if self.build.local_radius_m != build.local_radius_m {
            command += &format!(" --local-radius-mm {}", self.build.local_radius_m * 1e3);
        }
        if self.build.pgd.max_modes != build.pgd.max_modes {
            command += &format!(" --max-modes {}", self.build.pgd.max_modes);
        }
        // `pgd build` derives the steps from the tool it is given; a spec that keeps another
        // tool's steps (the coarse organs keep the 6 mm tool's) says them.
        let steps = &self.build.load_steps_m;
        let derived =
            default_load_steps_m(self.source.organ(), self.build.tool_tip_radius_m, self.law);
        if self.law != Law::Linear && *steps != derived {
            // To the micrometre: the file's check holds steps equal to 1e-9 relative.
            let mm: Vec<String> = steps
                .iter()
                .map(|s| format!("{}", (s * 1e6).round() / 1e3))
                .collect();
            command += &format!(" --load-steps-mm {}", mm.join(","));
        }
        if let Some(young_pa) = self.young_pa {
            command += &format!(" --young-pa {young_pa}");
        }
        if let Some(poisson) = self.poisson {
            command += &format!(" --poisson {poisson}");
        }
        if let Some(stiffening) = self.stiffening {
            command += &format!(" --stiffening {stiffening}");
        }
        for inclusion in &self.inclusions {
            command += &format!(" --inclusion {}", inclusion_arg(inclusion));
        }
        command + &format!(" --out {}", self.file.display())
    }
}

/// The file name of the vademecum of `stem` under `law`: `<stem>.vdm` for the linear law,
/// `<stem>-<law>.vdm` for the others, so that a nonlinear vademecum never replaces the linear
/// one beside it.
pub fn vademecum_file_name(stem: &str, law: Law) -> String {
    match law {
        Law::Linear => format!("{stem}.vdm"),
        _ => format!("{stem}-{}.vdm", law.name()),
    }
}

/// The vademecum `spec` asks for, checked for its mesh, material and settings; a missing or
/// stale one is rebuilt or refused per `on_stale`. The organ's mesh comes with it: its regions
/// (attachments) are not in the vademecum.
pub fn ensure_vademecum(
    spec: &VademecumSpec,
    on_stale: OnStale,
) -> Result<(Vademecum, TetMesh), String> {
    ensure_with(spec, on_stale, &Bar::default())
}

/// [`ensure_vademecum`], a build's progress shown on `progress`.
pub(super) fn ensure_with(
    spec: &VademecumSpec,
    on_stale: OnStale,
    progress: &dyn Progress,
) -> Result<(Vademecum, TetMesh), String> {
    let name = &spec.name;
    let mesh = spec.source.load(&spec.mesh, &ImportOptions::default())?;
    let mut material = pgd::organ::material(spec.source.material_of(), spec.law);
    material.young_pa = spec.young_pa.unwrap_or(material.young_pa);
    material.poisson = spec.poisson.unwrap_or(material.poisson);
    material.stiffening = spec.stiffening.unwrap_or(material.stiffening);
    let why = match checked(spec, &mesh, &material) {
        Ok(vademecum) => return Ok((vademecum, mesh)),
        Err(why) => why,
    };
    let command = spec.build_command();
    if on_stale == OnStale::Refuse {
        return Err(format!("{why}\nbuild it with:\n  {command}"));
    }
    eprintln!("{why}\nbuilding it now (the same as `{command}`):");
    let job = BuildJob {
        source: name,
        mesh: mesh.clone(),
        material,
        inclusions: &spec.inclusions,
        settings: spec.build.clone(),
        cuts: None,
        newton_samples: 0,
    };
    let (vademecum, _, [csv, png]) = build_and_save_with(job, &spec.file, progress)?;
    eprintln!(
        "wrote {} (convergence curves: {} and {})",
        spec.file.display(),
        csv.display(),
        png.display()
    );
    Ok((vademecum, mesh))
}

/// What a vademecum is built from: an organ's mesh (`source` names it in messages), its
/// material and stiffer regions, and the build settings.
pub struct BuildJob<'a> {
    pub source: &'a str,
    pub mesh: TetMesh,
    pub material: Material,
    pub inclusions: &'a [Inclusion],
    pub settings: BuildSettings,
    /// Also build the cut section over this region.
    pub cuts: Option<RegionSettings>,
    /// Nonlinear laws: Newton paths timed as the brute-force baseline (0: none).
    pub newton_samples: usize,
}

/// Seed of the load parameters the brute-force baseline times.
const NEWTON_SEED: u64 = 5;

/// Builds `job`'s vademecum with progress bars (the organ clamped at its `clamped` region,
/// loaded over its `accessible` one) and saves it at `file`, with its convergence curves
/// beside it; returns the vademecum, the build's report and the curves' files.
pub fn build_and_save(
    job: BuildJob,
    file: &Path,
) -> Result<(Vademecum, BuildReport, [PathBuf; 2]), String> {
    build_and_save_with(job, file, &Bar::default())
}

/// [`build_and_save`], its progress shown on `progress`.
fn build_and_save_with(
    job: BuildJob,
    file: &Path,
    progress: &dyn Progress,
) -> Result<(Vademecum, BuildReport, [PathBuf; 2]), String> {
    let source = job.source;
    finish_and_save(job, file, progress, |organ, settings| {
        pgd::build(organ, settings, progress).map_err(|e| format!("{source}: {e}"))
    })
}

/// Joins the `parts` of `job`'s build (`pgd build --shard`) into its vademecum and saves it as
/// [`build_and_save`] does.
pub fn merge_and_save(
    job: BuildJob,
    parts: Vec<pgd::PartFile>,
    file: &Path,
) -> Result<(Vademecum, BuildReport, [PathBuf; 2]), String> {
    let (source, progress) = (job.source, Bar::default());
    finish_and_save(job, file, &progress, |organ, settings| {
        pgd::merge(organ, settings, parts, &progress).map_err(|e| match e {
            pgd::MergeError::Fem(e) => format!("{source}: {e}"),
            other => other.to_string(),
        })
    })
}

/// Computes shard `shard` of `job`'s build and saves it at `file`; `command` is what makes
/// the model again for the merge.
pub fn build_part(
    job: BuildJob,
    shard: pgd::Shard,
    command: Vec<String>,
    file: &Path,
) -> Result<pgd::PartHeader, String> {
    let source = job.source;
    let model = model_of(source, job.mesh, job.material, job.inclusions)?;
    let part = pgd::build_shard(
        &organ_model(source, &model),
        &job.settings,
        shard,
        command,
        &Bar::default(),
    )
    .map_err(|e| format!("{source}: {e}"))?;
    pgd::save_part(file, &part).map_err(|e| e.to_string())?;
    Ok(part.header)
}

/// The clamped model of the mesh of `source`, its material and stiffer regions.
fn model_of(
    source: &str,
    mesh: TetMesh,
    material: Material,
    inclusions: &[Inclusion],
) -> Result<FemModel, String> {
    pgd::organ::clamped_model(mesh, material)
        .and_then(|model| model.with_inclusions(inclusions))
        .map_err(|e| format!("{source}: {e}"))
}

fn organ_model<'a>(source: &str, model: &'a FemModel) -> OrganModel<'a> {
    OrganModel {
        source: source.to_owned(),
        model,
        clamped_region: region::CLAMPED.into(),
        accessible_region: region::ACCESSIBLE.into(),
    }
}

/// Makes `job`'s vademecum with `make` (its errors said in full), adds its cut section and
/// Newton baseline if asked, and saves it at `file` with its convergence curves beside it.
fn finish_and_save(
    job: BuildJob,
    file: &Path,
    progress: &dyn Progress,
    make: impl FnOnce(&OrganModel, &BuildSettings) -> Result<(Vademecum, BuildReport), String>,
) -> Result<(Vademecum, BuildReport, [PathBuf; 2]), String> {
    let source = job.source;
    let model = model_of(source, job.mesh, job.material, job.inclusions)?;
    let (mut vademecum, mut built) = make(&organ_model(source, &model), &job.settings)?;
    if let Some(cuts) = &job.cuts {
        let report = pgd::add_cuts(&mut vademecum, &model, cuts, progress)
            .map_err(|e| format!("{source}: cut section: {e}"))?;
        built.total_seconds += report.total_seconds;
        built.cuts = Some(report);
    }
    if job.newton_samples > 0 {
        eprintln!(
            "timing the brute-force baseline: {} Newton paths",
            job.newton_samples
        );
        built.newton_baseline =
            pgd::newton_baseline(&model, &vademecum, job.newton_samples, NEWTON_SEED)
                .map_err(|e| format!("{source}: brute-force baseline: {e}"))?;
    }
    pgd::save(file, &vademecum).map_err(|e| e.to_string())?;
    built.file_bytes = std::fs::metadata(file).map_or(0, |m| m.len());
    let curves = report::write_convergence_of(file, &vademecum.header)?;
    Ok((vademecum, built, curves))
}

/// Loads the spec's file and refuses it unless it was built for `mesh`, `material` and the
/// spec's settings.
fn checked(
    spec: &VademecumSpec,
    mesh: &TetMesh,
    material: &Material,
) -> Result<Vademecum, VademecumError> {
    let file = &spec.file;
    let vademecum = pgd::load(file)?;
    vademecum.check_mesh(file, mesh)?;
    vademecum.check_material(file, material, &spec.inclusions)?;
    vademecum.check_settings(file, &spec.build)?;
    Ok(vademecum)
}

/// An inclusion as `pgd build --inclusion` takes it: `X,Y,Z,RADIUS,RATIO`, lengths in mm.
fn inclusion_arg(inclusion: &Inclusion) -> String {
    let [x, y, z] = inclusion.centre_m.map(|c| c * 1e3);
    let radius_mm = inclusion.radius_m * 1e3;
    format!("{x},{y},{z},{radius_mm},{}", inclusion.stiffness_ratio)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A spec that keeps the 6 mm tool's steps under a 12 mm tool (as the coarse organs do)
    /// says them, since `pgd build` would derive twice as deep ones from the 12 mm tool; the
    /// organ's own steps under its own tool go unsaid.
    #[test]
    fn the_build_command_says_steps_the_tool_would_not_give() {
        let dir = Path::new("vademecums");
        let own = VademecumSpec::default_in(dir, Organ::Liver, Law::Exponential);
        assert!(!own.build_command().contains("--load-steps-mm"));
        let mut coarse = own.clone();
        coarse.build.tool_tip_radius_m = 0.012;
        let command = coarse.build_command();
        assert!(
            command.contains("--tool-radius-mm 12 ")
                && command.contains("--load-steps-mm 2.5,5,10,20,35,60 "),
            "{command}"
        );
    }
}
