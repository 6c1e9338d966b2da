//! The options of `pgd`, as clap parses them, and their conversion into the library's
//! settings.

use std::path::{Path, PathBuf};

use clap::{Args, Parser, Subcommand};
use pgd_surgery::cli::LoadedMesh;
use pgd_surgery::contact::{CouplingSettings, PenaltySettings, PointshellDensity};
use pgd_surgery::cutting::CutPattern;
use pgd_surgery::cutting::keratotomy::REFERENCE_MESH;
use pgd_surgery::devices::PressMotion;
use pgd_surgery::fem::{Inclusion, Law, Material, TISSUE_DENSITY_KG_M3};
use pgd_surgery::mesh::io::{Frame, ImportOptions};
use pgd_surgery::mesh::organs::{CORNEA_LAYERS, Organ, OrganSettings};
use pgd_surgery::mesh::{MeshDensity, RegionSelectors, Selector};
use pgd_surgery::pgd::{
    self, BuildSettings, PgdSettings, RegionSettings, SecantSettings, ValidationSettings,
};
use pgd_surgery::store::vademecum_file_name;
use pgd_surgery::{bench, cli, store};

#[derive(Parser)]
#[command(
    name = "pgd",
    version,
    about = "Offline tools of the PGD surgery trainer: organ meshes and benchmarks of the numerical core"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand)]
pub enum Command {
    /// Generate an organ (liver, gallbladder, pancreas, duodenum, cornea) or read a mesh file
    /// (.msh, .vtk, .vtu, or an .obj/.stl/.ply/VTK polydata surface, which is mended and
    /// tetrahedralized), pick its regions if asked, and print its statistics, regions and
    /// quality report. Exits with status 1 if the mesh cannot be simulated.
    Mesh {
        #[command(flatten)]
        mesh: MeshArgs,
        /// Also write the mesh (with its regions) as .vtu for ParaView.
        #[arg(long, value_name = "FILE.vtu")]
        out: Option<PathBuf>,
        /// Also draw the organ with its clamped (red) and accessible (green) regions as PNG.
        #[arg(long, value_name = "FILE.png")]
        preview: Option<PathBuf>,
        /// Print the report as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Build the vademecum of an organ or of a mesh file with `clamped` and `accessible`
    /// regions: exact local responses, PGD global modes, and the brute-force baseline measured
    /// in the same run. Writes vademecums/<name>.vdm unless --out says otherwise.
    Build {
        #[command(flatten)]
        mesh: MeshArgs,
        #[command(flatten)]
        material: MaterialArgs,
        #[command(flatten)]
        build: BuildArgs,
        /// Where to write the vademecum.
        #[arg(long, value_name = "FILE.vdm")]
        out: Option<PathBuf>,
        /// Also precompute the organ's distance field for organ-against-organ contact, as
        /// a scene's contact master needs it (the gallbladder by default), and write it beside
        /// the vademecum (FILE.vdf). The trainer otherwise builds it on first use.
        #[arg(long)]
        distance_field: bool,
        /// Compute only shard K of N (from 1) of the load positions, for a build split across
        /// machines: writes a part (by default the vademecum's name with .part-K-of-N.vdp) that
        /// `pgd merge` joins with the others into the vademecum. The part keeps these
        /// arguments: every shard of one build is run with the same ones.
        #[arg(long, value_name = "K/N")]
        shard: Option<pgd::Shard>,
        /// Print the build report as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Join the parts of a build split with `pgd build --shard K/N` into its vademecum: the
    /// same file the whole build writes. Makes the organ's model again from the arguments the
    /// parts keep (their mesh files must be where they were), refuses parts of another build
    /// or a missing shard, and adds the cut section, distance field and Newton baseline the
    /// build asked for.
    Merge {
        /// Every part of the build, in any order.
        #[arg(required = true, value_name = "PART.vdp")]
        parts: Vec<PathBuf>,
        /// Where to write the vademecum (default: where the whole build would).
        #[arg(long, value_name = "FILE.vdm")]
        out: Option<PathBuf>,
        /// Also precompute the organ's distance field (FILE.vdf), as `pgd build` does.
        #[arg(long)]
        distance_field: bool,
        /// Print the build report as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Check a vademecum against full FEM on the same mesh at random loads it was not built on:
    /// felt-force and displacement errors (mean, p50, p95), and the build's convergence
    /// curves as CSV and PNG.
    Validate(ValidateArgs),
    /// Radial keratotomy on the cornea: N radial incisions from the optical zone's edge to
    /// 0.5 mm inside the limbus, under 15 mmHg of intraocular pressure, solved by full X-FEM;
    /// prints the change of central corneal power in dioptres.
    Cut {
        /// The organ: radial keratotomy is defined on the cornea.
        organ: String,
        /// Radial incisions, evenly spaced.
        #[arg(long, default_value_t = 4)]
        incisions: usize,
        /// Diameter of the optical zone left uncut, in millimetres.
        #[arg(long, default_value_t = 3.0)]
        optical_zone_mm: f64,
        /// Depth of the incisions as a fraction of the corneal thickness.
        #[arg(long, default_value_t = 0.9)]
        depth_fraction: f64,
        /// Multiplies the cornea's nodes per layer (1 = 2,800; the reference 0.6 keeps a
        /// radial incision some twenty elements long, and is what the trainer predicts on).
        #[arg(long, default_value_t = REFERENCE_MESH.0)]
        resolution: f64,
        /// Elements through the thickness: a cut's depth counts in these.
        #[arg(long, default_value_t = REFERENCE_MESH.1)]
        cornea_layers: usize,
        /// Print the report as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Press the organ with its tool (a rigid sphere, frictionless) to a depth, solving full
    /// nonlinear FEM at every step, and print the force–depth curve of each law: the reference
    /// a nonlinear vademecum is checked against. Writes the curves side by side as a PNG.
    Indent {
        #[command(flatten)]
        mesh: MeshArgs,
        /// Young's modulus, Poisson's ratio and inclusions (--law is ignored: see --laws).
        #[command(flatten)]
        material: MaterialArgs,
        /// Material laws to press with, in order.
        #[arg(long, value_enum, value_delimiter = ',', default_values = ["linear", "ksv", "neo-hookean"])]
        laws: Vec<LawArg>,
        /// Press at the accessible surface node nearest this point, `X,Y,Z` in millimetres
        /// (default: the accessible face's middle).
        #[arg(long, value_name = "X,Y,Z", value_parser = cli::parse_point_mm)]
        at: Option<[f64; 3]>,
        /// Deepest depth in millimetres (default: 25/6 of the tool's radius, 25 mm under the
        /// abdominal 6 mm tool).
        #[arg(long)]
        depth_mm: Option<f64>,
        /// Equal depth steps from rest to the deepest (each a full Newton solve).
        #[arg(long, default_value_t = 25)]
        steps: usize,
        /// Where to draw the curves (default: <source>-indentation.png in the current folder).
        #[arg(long, value_name = "FILE.png")]
        plot: Option<PathBuf>,
        /// Print the report as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Fit the exponential law to a uniaxial test of tissue (compression or tension): Young's
    /// modulus and stiffening b by least squares, the neo-Hookean fit beside it, and both
    /// drawn against the data.
    Fit {
        /// CSV with the columns `stretch,nominal_stress_pa` (stretch below 1 and stress
        /// negative in compression), one row per measurement.
        data: PathBuf,
        /// Poisson's ratio the fit holds fixed.
        #[arg(long, default_value_t = pgd::organ::POISSON)]
        poisson: f64,
        /// Where to draw the fit (default: <data>.fit.png beside the data).
        #[arg(long, value_name = "FILE.png")]
        plot: Option<PathBuf>,
        /// Print the fit as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Time the numerical core and print medians (and ratios to a baseline run alongside).
    Bench {
        #[command(subcommand)]
        what: BenchTarget,
    },
}

/// `pgd validate`'s options.
#[derive(clap::Args)]
pub struct ValidateArgs {
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// The vademecum (default: vademecums/<source>.vdm, or <source>-<law>.vdm with --law).
    #[arg(long, value_name = "FILE.vdm")]
    pub vademecum: Option<PathBuf>,
    /// The law of the default vademecum file (the file's own law is the one checked).
    #[arg(long, value_enum, default_value = "linear")]
    pub law: LawArg,
    /// Number of random loads (default 60), or of cut patterns with --cuts (default 5).
    #[arg(long)]
    pub samples: Option<usize>,
    /// Seed of the random loads.
    #[arg(long, default_value_t = ValidationSettings::default().seed)]
    pub sample_seed: u64,
    /// Largest indentation of the random loads, in millimetres (default: 10/3 of the
    /// organ's tool radius, 20 for the abdominal organs; the smallest is a tenth of it).
    #[arg(long)]
    pub max_indentation_mm: Option<f64>,
    /// The random loads' directions lie within this angle of the inward normal, in
    /// degrees (0: along it; less than 90).
    #[arg(long, default_value_t = ValidationSettings::default().max_tilt_deg)]
    pub max_tilt_deg: f64,
    /// Presses along the normal at random points, full FEM against the vademecum from
    /// zero to the largest indentation, printed and drawn as force–depth curves
    /// (FILE.force-depth.png beside the vademecum).
    #[arg(long, default_value_t = ValidationSettings::default().curves)]
    pub curves: usize,
    /// Press beyond the vademecum's range: each load between its point's range edge and
    /// --max-indentation-mm, the curves to --max-indentation-mm, measuring what the
    /// trainer extrapolates past the load steps (a nonlinear vademecum).
    #[arg(long)]
    pub beyond_range: bool,
    /// Check the cut section instead, on cut patterns drawn at random, each incision made
    /// in three segments: `radial:N` (the cornea), N radial incisions at random angles,
    /// optical zones of 3–5 mm and depths of 60–95 %, under 15 mmHg; `straight:N`, N
    /// incisions 20 mm long and 10 mm deep into the accessible face, under the tool
    /// beside the first; --samples patterns (default 5 here).
    #[arg(long, value_name = "PATTERN", value_parser = cli::parse_cut_pattern)]
    pub cuts: Option<CutPattern>,
    /// With --cuts: run the cut state on the factorized stiffness instead of the cut
    /// section (the reference path; a sparse solve per enriched function).
    #[arg(long, requires = "cuts")]
    pub exact_response: bool,
    /// With --cuts: how far from a segment's enriched functions the patch solved for
    /// them reaches, in millimetres (default: three mean element edges).
    #[arg(long, requires = "cuts", conflicts_with = "exact_response")]
    pub cut_patch_mm: Option<f64>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Where the mesh comes from.
#[derive(Args)]
pub struct MeshArgs {
    /// An organ (liver, gallbladder, pancreas, duodenum, cornea) or a mesh file.
    pub source: String,
    /// Organs: multiplies the node count (1 = the papers' sizes).
    #[arg(long, default_value_t = 1.0)]
    pub resolution: f64,
    /// Organs: varies proportions deterministically (another patient).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The cornea: elements through its thickness (a cut's depth is resolved to one of them;
    /// radial keratotomy wants 8).
    #[arg(long, default_value_t = CORNEA_LAYERS)]
    pub cornea_layers: usize,
    /// Files: multiplies coordinates (0.001 for files in millimetres).
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    /// Surfaces (.obj, .stl, .ply, VTK polydata), and volumes meshed anew: target node count
    /// of the tetrahedralization.
    #[arg(long, default_value_t = 4000)]
    pub nodes: usize,
    /// Files, instead of --nodes: the elements' size in millimetres (after --scale); the surface is
    /// remeshed to it too. A size that would give more than 200,000 nodes is refused.
    #[arg(long, value_name = "MM", conflicts_with = "nodes")]
    pub element_mm: Option<f64>,
    /// Files: the patient frame their coordinates are in, ras or lps (default: the one the
    /// file states, as 3D Slicer writes SPACE=RAS or SPACE=LPS in its header, else ras); lps
    /// is turned into the trainer's ras.
    #[arg(long)]
    pub frame: Option<Frame>,
    /// Files: the nodes held fixed, picked by where they are (millimetres, after --scale):
    /// box:X0,Y0,Z0,X1,Y1,Z1, sphere:X,Y,Z,R, plane:X,Y,Z,NX,NY,NZ (the side the normal
    /// points to), facing:NX,NY,NZ,DEG, region:NAME; given again, they add up; not:… takes
    /// its part away. Without it, the file's own `clamped` region.
    #[arg(long, value_name = "SELECTOR")]
    pub clamp: Vec<Selector>,
    /// Files: the surface the tool may touch, picked as --clamp picks (default with --clamp:
    /// the surface no clamped node touches; without either, the file's own `accessible`).
    #[arg(long, value_name = "SELECTOR")]
    pub accessible: Vec<Selector>,
}

impl MeshArgs {
    /// The mesh, its regions picked by the selectors given (with what each picked).
    pub fn load(&self) -> Result<LoadedMesh, String> {
        let (organ, mut mesh) = store::load_source(&store::MeshSource {
            name: &self.source,
            organ: OrganSettings {
                resolution: self.resolution,
                seed: self.seed,
                cornea_layers: self.cornea_layers,
            },
            import: ImportOptions {
                scale: self.scale,
                density: match self.element_mm {
                    Some(mm) => MeshDensity::ElementSize { size_m: mm * 1e-3 },
                    None => MeshDensity::Nodes(self.nodes),
                },
                regions: RegionSelectors::default(),
                frame: self.frame,
            },
        })?;
        let selectors = RegionSelectors {
            clamp: self.clamp.clone(),
            accessible: self.accessible.clone(),
        };
        let selection = match selectors.is_empty() {
            true => None,
            false => {
                Some((selectors.apply(&mut mesh)).map_err(|e| format!("{}: {e}", self.source))?)
            }
        };
        Ok(LoadedMesh {
            organ,
            mesh,
            selection,
        })
    }

    /// The file name a vademecum of this source gets by default.
    pub fn stem(&self) -> String {
        Path::new(&self.source)
            .file_stem()
            .map_or_else(|| self.source.clone(), |s| s.to_string_lossy().into_owned())
    }
}

/// The material law of a build.
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum LawArg {
    /// Linear elasticity: one load step.
    Linear,
    /// Kirchhoff–Saint Venant by load steps: exact under large rotations, but it softens and
    /// loses stability under strong compression.
    Ksv,
    /// Compressible neo-Hookean by load steps: stable at any compression, stiffens as the
    /// tool presses deeper.
    NeoHookean,
    /// Neo-Hookean with a shear modulus that grows exponentially with strain (`--stiffening`):
    /// firms up under the tool the way liver does.
    Exponential,
}

impl LawArg {
    pub fn law(self) -> Law {
        match self {
            LawArg::Linear => Law::Linear,
            LawArg::Ksv => Law::KirchhoffSaintVenant,
            LawArg::NeoHookean => Law::NeoHookean,
            LawArg::Exponential => Law::Exponential,
        }
    }
}

#[derive(Args)]
pub struct MaterialArgs {
    /// Material law.
    #[arg(long, value_enum, default_value = "linear")]
    pub law: LawArg,
    /// Young's modulus in Pa (default: the organ's, or the liver's 1.6 kPa for mesh files).
    #[arg(long)]
    pub young_pa: Option<f64>,
    /// Poisson's ratio.
    #[arg(long, default_value_t = pgd::organ::POISSON)]
    pub poisson: f64,
    /// The exponential law's stiffening exponent b: the shear modulus grows as e^(b x), x the
    /// strain invariant I1 − 3 − 2 ln J (default: 2).
    #[arg(long, value_name = "B")]
    pub stiffening: Option<f64>,
    /// A stiffer (or softer) sphere in the tissue, such as a tumour to find by palpation:
    /// its centre and radius in millimetres and its Young's modulus over the organ's, as
    /// `X,Y,Z,RADIUS,RATIO` (e.g. `10,-5,30,7,6`). Repeat for several.
    #[arg(long, value_name = "X,Y,Z,RADIUS,RATIO", value_parser = cli::parse_inclusion)]
    pub inclusion: Vec<Inclusion>,
}

impl MaterialArgs {
    pub fn material(&self, organ: Option<Organ>) -> Result<Material, String> {
        let law = self.law.law();
        let young_pa = self
            .young_pa
            .unwrap_or_else(|| pgd::organ::young_pa(organ.unwrap_or(Organ::Liver)));
        let material = Material::new(law, young_pa, self.poisson, TISSUE_DENSITY_KG_M3)
            .map_err(|e| e.to_string())?;
        match (self.stiffening, law) {
            (None, _) => Ok(material),
            (Some(b), Law::Exponential) => material.with_stiffening(b).map_err(|e| e.to_string()),
            (Some(_), _) => Err("--stiffening applies to --law exponential only".into()),
        }
    }
}

#[derive(Args)]
pub struct BuildArgs {
    /// Radius of the tool tip's contact patch, in millimetres: loads are spread over it
    /// (default: 0.5 for the cornea, 6 for the other organs and mesh files).
    #[arg(long)]
    pub tool_radius_mm: Option<f64>,
    /// Radius around each loaded node, in millimetres, where its exact response is stored
    /// (default: the watched region plus the tool radius, 2.5 for the cornea, 26 for the
    /// other organs and mesh files).
    #[arg(long)]
    pub local_radius_mm: Option<f64>,
    /// Target of the estimator: each node-centred load's relative L2 error of the field (global
    /// modes + exact near field), root mean square over the loads.
    #[arg(long, default_value_t = BuildSettings::default().target_error)]
    pub target_error: f64,
    /// At most this many PGD modes per load step.
    #[arg(long, default_value_t = PgdSettings::default().max_modes)]
    pub max_modes: usize,
    /// Nonlinear laws: the linear response's depth under the tool at each load step after
    /// the linear one, in millimetres, increasing; the deepest is the range the vademecum is
    /// valid over (default: 0.5,1,1.5 for KSV; 2.5,5,10,15,20,25 for the neo-Hookean law and
    /// 2.5,5,10,20,35,60 for the exponential law, which presses less deep than its levels, on
    /// the liver under the 6 mm tool, the same share of the other organs' thickness, in
    /// proportion to the cornea's tool).
    #[arg(long, value_delimiter = ',')]
    pub load_steps_mm: Vec<f64>,
    /// Nonlinear laws: up to this fraction of a load step's loads may fail to converge and
    /// keep the step before's secant response (counted in the report); past it, the failed
    /// positions' range ends at the step before.
    #[arg(long, default_value_t = SecantSettings::default().max_unconverged_fraction)]
    pub max_unconverged: f64,
    /// Nonlinear laws: a load step after the first is kept while at least this share of
    /// the positions still reach it (their loads converged at it and every step before).
    #[arg(long, default_value_t = SecantSettings::default().min_reached_share)]
    pub min_reached_share: f64,
    /// Nonlinear laws: the loads a step's fixed point leaves are solved by Newton while it
    /// costs at most this many times the step's fixed point; a step whose leftovers would
    /// cost more is left out (0: never Newton).
    #[arg(long, default_value_t = SecantSettings::default().newton_budget)]
    pub newton_budget: f64,
    /// Nonlinear laws: the fraction of its residual the fixed point's first steps take
    /// (1: undamped; halved while the residual grows).
    #[arg(long, default_value_t = SecantSettings::default().mixing)]
    pub mixing: f64,
    /// Nonlinear laws: time the brute-force alternative on this many random loads, a full
    /// Newton path each to the deepest step kept, and scale it to all loads (0: skip).
    #[arg(long, default_value_t = 3)]
    pub newton_samples: usize,
    /// Also build the cut section: the uncut organ's response to a unit force at every node
    /// within --cut-depth-mm of the accessible faces, which an incision anywhere there is
    /// condensed onto online (docs/cutting.md).
    #[arg(long)]
    pub cuts: bool,
    /// How deep cuts may go under the accessible faces, in millimetres (default: the
    /// cornea's whole thickness, 20 for the other organs).
    #[arg(long, requires = "cuts")]
    pub cut_depth_mm: Option<f64>,
    /// Radius of each cut load's exact near field, in millimetres (default: 1 for the
    /// cornea, 8 for the other organs).
    #[arg(long, requires = "cuts")]
    pub cut_near_mm: Option<f64>,
    /// PGD modes of the cut section's far field.
    #[arg(long, requires = "cuts")]
    pub cut_modes: Option<usize>,
    /// How far from a segment's enriched functions the cut state's patch solve reaches, in
    /// millimetres (default: 3 for the cornea, 20 for the other organs): wider is closer to
    /// exact and slower.
    #[arg(long, requires = "cuts")]
    pub cut_patch_mm: Option<f64>,
}

/// `mm` as metres, or `default_m` without it; refused unless a positive finite length.
pub fn millimetres(option: &str, mm: Option<f64>, default_m: f64) -> Result<f64, String> {
    match mm {
        Some(mm) if !(mm.is_finite() && mm > 0.0) => Err(format!(
            "--{option} {mm}: expected a positive length in millimetres"
        )),
        Some(mm) => Ok(mm * 1e-3),
        None => Ok(default_m),
    }
}

impl BuildArgs {
    /// The cut section's region, if `--cuts` asks for one.
    pub fn cut_settings(&self, organ: Option<Organ>) -> Result<Option<RegionSettings>, String> {
        if !self.cuts {
            return Ok(None);
        }
        let defaults = RegionSettings::for_organ(organ);
        let length = millimetres;
        let modes = self.cut_modes.unwrap_or(defaults.modes);
        if modes == 0 {
            return Err("--cut-modes 0: expected at least one mode".into());
        }
        Ok(Some(RegionSettings {
            depth_m: length("cut-depth-mm", self.cut_depth_mm, defaults.depth_m)?,
            near_radius_m: length("cut-near-mm", self.cut_near_mm, defaults.near_radius_m)?,
            modes,
            patch_radius_m: match self.cut_patch_mm {
                Some(mm) => Some(length("cut-patch-mm", Some(mm), 0.0)?),
                None => defaults.patch_radius_m,
            },
        }))
    }

    pub fn settings(&self, organ: Option<Organ>, law: Law) -> Result<BuildSettings, String> {
        let defaults = BuildSettings::for_organ_law(organ, law);
        let steps = &self.load_steps_mm;
        if steps.iter().any(|s| !(s.is_finite() && *s > 0.0))
            || steps.windows(2).any(|w| w[1] <= w[0])
        {
            return Err(format!(
                "--load-steps-mm {steps:?}: expected positive indentations in increasing order"
            ));
        }
        if steps.len() >= pgd::MAX_STEPS {
            return Err(format!(
                "--load-steps-mm: {} steps; at most {} beside the linear one",
                steps.len(),
                pgd::MAX_STEPS - 1
            ));
        }
        if !(self.mixing > 0.0 && self.mixing <= 1.0) {
            return Err(format!(
                "--mixing {}: expected a fraction of the residual in (0, 1]",
                self.mixing
            ));
        }
        let tool_tip_radius_m = self
            .tool_radius_mm
            .map_or(defaults.tool_tip_radius_m, |mm| mm * 1e-3);
        let load_steps_m = match steps.is_empty() {
            true => pgd::default_load_steps_m(organ, tool_tip_radius_m, law),
            false => steps.iter().map(|s| s * 1e-3).collect(),
        };
        Ok(BuildSettings {
            tool_tip_radius_m,
            local_radius_m: self
                .local_radius_mm
                .map_or(defaults.local_radius_m, |mm| mm * 1e-3),
            target_error: self.target_error,
            pgd: PgdSettings {
                max_modes: self.max_modes,
                ..PgdSettings::default()
            },
            load_steps_m,
            secant: SecantSettings {
                max_unconverged_fraction: self.max_unconverged,
                min_reached_share: self.min_reached_share,
                newton_budget: self.newton_budget,
                mixing: self.mixing,
                ..defaults.secant
            },
        })
    }
}

#[derive(Subcommand)]
pub enum BenchTarget {
    /// The organ-contact stage: one pair's tick with the organs apart and with the master
    /// pressed until at least 400 pointshell nodes push, against parry's brute-force check of
    /// every node against the deformed master surface.
    Contact(ContactBenchArgs),
    /// A scenario played by its scripted run through the haptic loop on the simulated clock,
    /// every tick's compute timed, against a baseline scenario's run in the same process (by
    /// default the whole cholecystectomy against the liver press).
    Operation {
        /// The scenario timed.
        #[arg(long, default_value = "scenarios/lap-chole-full.scenario.ron")]
        scenario: PathBuf,
        /// Its scripted run.
        #[arg(long, default_value = "scenarios/runs/lap-chole-full.competent.csv")]
        run: PathBuf,
        /// The baseline scenario, timed the same way.
        #[arg(long, default_value = "scenarios/liver-steady-press.scenario.ron")]
        baseline: PathBuf,
        /// The baseline's scripted run.
        #[arg(
            long,
            default_value = "scenarios/runs/liver-steady-press.competent.csv"
        )]
        baseline_run: PathBuf,
        #[command(flatten)]
        runs: SceneBenchArgs,
    },
    /// A stroke of the scalpel through the liver of the four-organ scene, ticked at 1 kHz on
    /// the real clock: tick compute time against the same stroke with a probe, and the cut
    /// state's time per step on its worker thread.
    Scalpel(SceneBenchArgs),
    /// The render side's CPU work per frame on the four-organ scene, each organ pressed by
    /// the tool: the surface vertices formed from the modes there (the trainer's path)
    /// against the whole field formed and the surface picked from it (the baseline), with
    /// normals, p50 and p99 of each.
    Frame {
        /// Frames timed each way.
        #[arg(long, default_value_t = 400)]
        frames: usize,
        /// The coarse organs.
        #[arg(long)]
        coarse: bool,
        /// Where the organs' vademecums are kept (missing or stale ones are rebuilt).
        #[arg(long, default_value = "vademecums")]
        vademecums: PathBuf,
        /// Print the report as JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// The haptic loop on the four-organ scene: tick compute time over a scripted sweep (all
    /// organs, then each), the same press by full FEM, and real-time punctuality per timer.
    Haptics(HapticsBenchArgs),
    /// Incisions added online to the cut state, segment by segment, over the exact uncut
    /// response and over a cut vademecum, against the full X-FEM solve of the same cut after
    /// each segment; the tool's felt force with 0, 4 and 16 segments (a 40 × 40 × 10 mm block).
    Cutting {
        /// Cubes along x, y, z of the block (six tets each).
        #[arg(long, num_args = 3, value_names = ["NX", "NY", "NZ"], default_values_t = [16, 16, 4])]
        cells: Vec<usize>,
        /// Print the report as JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// Reduced dynamics of the four organs (KSV, bases from their linear vademecums): step
    /// time per organ and basis size against the linear law's, the four organs in one tick,
    /// and the energy of an undamped swing under the energy-momentum step, implicit Euler and
    /// Newmark.
    Dynamics {
        /// Basis sizes timed per organ.
        #[arg(long, value_delimiter = ',', default_values_t = [8, 12, 16])]
        modes: Vec<usize>,
        /// Basis size of the four-organ tick and the energy trace.
        #[arg(long, default_value_t = 12)]
        scene_modes: usize,
        /// Ticks timed per case: a pull for the first half, released for the second.
        #[arg(long, default_value_t = 2000)]
        ticks: usize,
        /// Where the organs' linear vademecums are kept (missing or stale ones are rebuilt).
        #[arg(long, default_value = "vademecums")]
        vademecums: PathBuf,
        /// Also draw the energy against time of each scheme as a PNG.
        #[arg(long)]
        plot: Option<PathBuf>,
        /// Print the report as JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// A duct as a rod, clamped at one end and its tip pulled, settled once a tick: the
    /// solve's time per tick and its Newton steps, for 20, 30 and 60 segments.
    Rods {
        /// Ticks timed per rod.
        #[arg(long, default_value_t = 10_000)]
        ticks: usize,
        /// Print the report as JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// A patient's organ as a segmentation gives it: the liver's surface as binary STL in
    /// millimetres imported (read, mended, checked for crossings, tetrahedralized), as it is
    /// and subdivided to --triangles.
    Import {
        /// The subdivided surface's triangles, at least (45,000: the liver's 3,082 triangles
        /// subdivided twice, 49,312).
        #[arg(long, default_value_t = 45_000)]
        triangles: usize,
        /// The nodes to tetrahedralize at (as `pgd mesh --nodes`).
        #[arg(long, default_value_t = 4_000)]
        nodes: usize,
        /// Imports timed per surface.
        #[arg(long, default_value_t = 3)]
        repeats: usize,
        /// Also write the subdivided surface as binary STL (millimetres), to build its
        /// vademecum with `pgd build FILE --scale 0.001 --clamp …`.
        #[arg(long, value_name = "FILE.stl")]
        stl_out: Option<PathBuf>,
        /// Print the report as JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// Assembly, factorization and solve on a liver-sized mesh (~4,300 nodes, ~21,000 tets).
    Fem {
        /// Print the report as JSON instead of a table.
        #[arg(long)]
        json: bool,
        /// How many times each step is timed; the median is reported.
        #[arg(long, default_value_t = 7)]
        repeats: usize,
        /// Cubes along x, y, z of the benchmark box (six tets each).
        #[arg(long, num_args = 3, value_names = ["NX", "NY", "NZ"])]
        cells: Option<Vec<usize>>,
    },
    /// Build time and peak memory of an organ's vademecum (linear and KSV), and the online
    /// evaluations: displacement under the tool, felt force, whole field, file load.
    Vademecum {
        /// The organ (liver, gallbladder, pancreas, duodenum, cornea).
        #[arg(default_value = "liver")]
        organ: String,
        /// Material laws to build, in order (peak memory is the process's, so it only grows).
        #[arg(long, value_enum, value_delimiter = ',', default_values = ["linear", "ksv"])]
        laws: Vec<LawArg>,
        /// Batches timed for each online evaluation; the median is reported.
        #[arg(long, default_value_t = 7)]
        repeats: usize,
        /// Print the report as JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
}

/// The options of a benchmark that times a scene in runs: `pgd bench scalpel`, `pgd bench
/// operation`.
#[derive(clap::Args)]
pub struct SceneBenchArgs {
    /// Runs per figure; the median is reported.
    #[arg(long, default_value_t = 3)]
    pub repeats: usize,
    /// The coarse organs and their 12 mm tool (the scripted runs are written for them; a cut
    /// coarse liver is at half resolution).
    #[arg(long)]
    pub coarse: bool,
    /// Where the organs' vademecums are kept (missing or stale ones are rebuilt).
    #[arg(long, default_value = "vademecums")]
    pub vademecums: PathBuf,
    /// Print the report as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// `pgd bench haptics`'s options.
#[derive(clap::Args)]
pub struct HapticsBenchArgs {
    /// Sweeps run per figure; the median is reported.
    #[arg(long, default_value_t = 5)]
    pub repeats: usize,
    /// Seconds of real-time ticking per timer.
    #[arg(long, default_value_t = 5.0)]
    pub realtime_seconds: f64,
    /// Where the organs' vademecums are kept (missing or stale ones are rebuilt).
    #[arg(long, default_value = "vademecums")]
    pub vademecums: PathBuf,
    /// Every organ moves (reduced dynamics, stepped every tick), as with a grasper.
    #[arg(long)]
    pub dynamic: bool,
    /// The organs' tissue law (each organ's vademecum is built under it; default: the
    /// trainer's, exponential, or linear with --dynamic).
    #[arg(long, value_enum)]
    pub law: Option<LawArg>,
    /// The coarse organs and their 12 mm tool (vademecums that build in minutes).
    #[arg(long)]
    pub coarse: bool,
    /// How deep the sweep presses each organ, in millimetres (deeper than a nonlinear
    /// vademecum's range to time the presses beyond it).
    #[arg(long, default_value_t = PressMotion::default().depth_m * 1e3)]
    pub depth_mm: f64,
    /// Hands: 2 times the four-organ sweep again with a left hand grasping the gallbladder
    /// (which then moves, in both sweeps) and holding it drawn out while the right hand
    /// sweeps (`one_hand` and `two_hands` in the report).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u8).range(1..=2))]
    pub hands: u8,
    /// Print the report as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// `pgd bench contact`: the scene and the contact settings it is timed on.
#[derive(Args)]
pub struct ContactBenchArgs {
    /// Ticks timed per case.
    #[arg(long, default_value_t = 2000)]
    pub ticks: usize,
    /// The coarse scene (quarter-node organs, built in seconds) instead of the full one.
    #[arg(long)]
    pub coarse: bool,
    /// Where the organs' vademecums are kept (missing or stale ones are rebuilt).
    #[arg(long, default_value = "vademecums")]
    pub vademecums: PathBuf,
    /// A dense pointshell (nodes and triangle centres) instead of the boundary nodes.
    #[arg(long, conflicts_with_all = ["subdivide", "sparse"])]
    pub dense: bool,
    /// A pointshell of the centres of each surface triangle cut N times along each edge
    /// (N² points a triangle) instead of the boundary nodes.
    #[arg(long, value_name = "N", value_parser = cli::parse_subdivisions, conflicts_with = "sparse")]
    pub subdivide: Option<u8>,
    /// A sparse pointshell: the boundary nodes kept at least MM millimetres apart.
    #[arg(long, value_name = "MM", value_parser = cli::parse_spacing)]
    pub sparse: Option<u8>,
    /// How many times stiffer than the tissue each node's penalty is: 1000 (the
    /// trainer's) cuts an overlap to 0.1 %; 1 leaves half of it, as a one-pass penalty
    /// does, so that far more nodes stay inside and push.
    #[arg(
        long,
        value_name = "RATIO",
        default_value_t = PenaltySettings::default().stiffness_ratio,
        value_parser = cli::parse_stiffness_ratio
    )]
    pub stiffness_ratio: f64,
    /// The cases to time (all by default): apart, pressed (the master free), held (a
    /// rigid master, settled), sliding (the held master moved sideways at 10 mm/s).
    #[arg(long = "case", value_enum, value_name = "CASE")]
    pub cases: Vec<bench::contact::Case>,
    /// Print the report as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

impl ContactBenchArgs {
    /// The scene's coupling with the pointshell and penalty asked for.
    pub fn coupling(&self) -> CouplingSettings {
        CouplingSettings {
            pointshell: match (self.dense, self.subdivide, self.sparse) {
                (_, Some(n), _) => PointshellDensity::Subdivided(n),
                (_, _, Some(mm)) => PointshellDensity::Sparse(mm),
                (true, ..) => PointshellDensity::Dense,
                (false, ..) => PointshellDensity::Nodes,
            },
            penalty: PenaltySettings {
                stiffness_ratio: self.stiffness_ratio,
                ..PenaltySettings::default()
            },
            ..CouplingSettings::default()
        }
    }
}

/// Where a vademecum of this source goes by default: `vademecums/<source>.vdm` for the linear
/// law, `<source>-<law>.vdm` for the others ([`vademecum_file_name`]).
pub fn default_vademecum(mesh: &MeshArgs, law: Law) -> PathBuf {
    PathBuf::from("vademecums").join(vademecum_file_name(&mesh.stem(), law))
}

/// The `pgd build` arguments `args` (from the subcommand on) without those that differ
/// between the shards of one build (`--shard`, `--out`) or do not change what is built
/// (`--json`): what a part keeps for `pgd merge`.
pub fn shard_command(args: impl Iterator<Item = String>) -> Vec<String> {
    let mut kept = Vec::new();
    let mut skip_value = false;
    for arg in args {
        if std::mem::take(&mut skip_value) {
            continue;
        }
        match arg.as_str() {
            "--shard" | "--out" => skip_value = true,
            "--json" => {}
            _ if arg.starts_with("--shard=") || arg.starts_with("--out=") => {}
            _ => kept.push(arg),
        }
    }
    kept
}
