//! Vademecum builds split across machines. A build's costly part is per position: the exact
//! responses to its unit loads and, for a nonlinear law, each load step's secant responses
//! to the tool's patch centred on it. `pgd build --shard K/N` does that work for the K-th of N
//! runs of positions and saves it as a part; `pgd merge` joins the parts and separates each
//! step into modes and near field, as a whole build does, giving the same vademecum.
//!
//! A run starts on a block of [`BLOCK_COLUMNS`] columns, so every column is solved in the
//! same block as in a whole build. What a nonlinear step decides over all its loads — the
//! share of unconverged loads it tolerates, Newton's budget — a shard decides over its own:
//! where no load needs them, the merged vademecum is the whole build's to the last bit.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::time::Instant;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::build::{
    BuildReport, NonlinearStep, OrganModel, PositionRanges, Separating, StepSink, position_work,
    with_context,
};
use super::container::{self, Kind, Reader, put_f64};
use super::error::VademecumError;
use super::responses::{BLOCK_COLUMNS, Responses, SecantReport};
use super::settings::BuildSettings;
use super::vademecum::Vademecum;
use super::{Progress, mesh_hash};
use crate::fem::FemError;

/// Bumped on any change of layout or meaning; older parts are refused, not misread.
const PART_VERSION: u32 = 1;
const KIND: Kind = Kind {
    magic: b"PGDSHARD",
    version: PART_VERSION,
    name: "vademecum part",
};

/// Shard `index` of `count` (from 1): which run of the load positions a build computes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl FromStr for Shard {
    type Err = String;

    /// `K/N`, with 1 ≤ K ≤ N.
    fn from_str(text: &str) -> Result<Self, String> {
        let hint = "write it K/N, shard K of N counted from 1 (as 2/4)";
        let (index, count) = text
            .split_once('/')
            .ok_or_else(|| format!("{text:?}: no '/'; {hint}"))?;
        let number = |part: &str| {
            part.trim()
                .parse::<usize>()
                .map_err(|_| format!("{text:?}: {part:?} is not a whole number; {hint}"))
        };
        let shard = Self {
            index: number(index)?,
            count: number(count)?,
        };
        if shard.index == 0 || shard.index > shard.count {
            return Err(format!("{text:?}: K must be from 1 to N; {hint}"));
        }
        Ok(shard)
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Shard {
    /// This shard's positions among `total`: a contiguous run of whole blocks of
    /// [`BLOCK_COLUMNS`] positions (the last block shorter), the blocks shared out as evenly
    /// as they go. A shard past the blocks has none.
    pub fn positions(self, total: usize) -> Range<usize> {
        let blocks = total.div_ceil(BLOCK_COLUMNS);
        let block = |k: usize| (k * blocks / self.count * BLOCK_COLUMNS).min(total);
        block(self.index - 1)..block(self.index)
    }
}

/// A nonlinear load step's outcome over a shard's positions.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShardStep {
    pub level_m: f64,
    /// The positions it reaches (organ numbering, sorted).
    pub reached: Vec<usize>,
    pub fixed_point: SecantReport,
    pub seconds: f64,
}

/// What a part says of itself: the build it belongs to, its positions and steps.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PartHeader {
    pub shard: Shard,
    /// What makes the organ's model again for the merge: the `pgd build` arguments.
    pub command: Vec<String>,
    pub mesh_hash: String,
    pub settings: BuildSettings,
    /// All the build's positions, and this part's.
    pub total_positions: usize,
    pub positions: Range<usize>,
    /// The responses' rows (free dofs).
    pub rows: usize,
    /// The time the unit loads' responses took.
    pub exact_seconds: f64,
    /// Nonlinear laws, per position of the part: the reference compliance (m/N).
    pub reference: Vec<f32>,
    /// The part's positions the nonlinear steps load.
    pub loaded: usize,
    pub steps: Vec<ShardStep>,
    /// The part's whole time, from the model to the responses.
    pub seconds: f64,
}

/// A shard's work: the exact responses of its positions' unit loads, and per nonlinear step
/// the corrections of their secant responses.
pub struct ShardPart {
    pub header: PartHeader,
    pub exact: Responses,
    pub corrections: Vec<Responses>,
}

/// A part and the file it came from (for messages).
pub struct PartFile {
    pub path: PathBuf,
    pub part: ShardPart,
}

/// Why parts cannot be merged.
#[derive(Debug, Error)]
pub enum MergeError {
    #[error(transparent)]
    File(#[from] VademecumError),
    #[error("{0}")]
    Fem(#[from] FemError),
    #[error("no parts given: name the files `pgd build --shard K/N` wrote")]
    NoParts,
    #[error(
        "{file}: a part of another build than {first}: their {what} differ; merge the parts of one `pgd build` command"
    )]
    OtherBuild {
        file: PathBuf,
        first: PathBuf,
        what: &'static str,
    },
    #[error("{file} and {other}: both are shard {shard}; give each shard once")]
    Twice {
        file: PathBuf,
        other: PathBuf,
        shard: Shard,
    },
    #[error(
        "shards {missing:?} of {count} are missing; run `pgd build … --shard K/{count}` for each"
    )]
    Missing { count: usize, missing: Vec<usize> },
    #[error(
        "{file}: built for {found} load positions where this organ has {expected}; its mesh or build arguments have changed since"
    )]
    OtherPositions {
        file: PathBuf,
        expected: usize,
        found: usize,
    },
}

/// Computes shard `shard` of `organ`'s vademecum: its positions' responses, every load step
/// of the settings (the merge decides where they stop). `command` is kept in the part, for
/// the merge to make the model again.
pub fn build_shard(
    organ: &OrganModel,
    settings: &BuildSettings,
    shard: Shard,
    command: Vec<String>,
    progress: &dyn Progress,
) -> Result<ShardPart, FemError> {
    let started = Instant::now();
    with_context(organ, settings, progress, |context| {
        let total_positions = context.patches.positions.len();
        let positions = shard.positions(total_positions);
        let mut recording = Recording::default();
        let ranges = position_work(context, positions.clone(), &mut recording)?;
        let (exact, exact_seconds) = recording
            .exact
            .expect("the positions' exact responses come first");
        let header = PartHeader {
            shard,
            command,
            mesh_hash: mesh_hash(organ.model.mesh()),
            settings: settings.clone(),
            total_positions,
            positions,
            rows: context.rows(),
            exact_seconds,
            reference: ranges.reference,
            loaded: recording.loaded,
            steps: recording.steps,
            seconds: started.elapsed().as_secs_f64(),
        };
        Ok(ShardPart {
            header,
            exact,
            corrections: recording.corrections,
        })
    })
}

/// The sink of a shard: every step kept as it comes, none judged.
#[derive(Default)]
struct Recording {
    exact: Option<(Responses, f64)>,
    corrections: Vec<Responses>,
    steps: Vec<ShardStep>,
    loaded: usize,
}

impl StepSink for Recording {
    fn linear(&mut self, exact: Responses, seconds: f64) -> Result<(), FemError> {
        self.exact = Some((exact, seconds));
        Ok(())
    }

    fn nonlinear(&mut self, step: NonlinearStep) -> Result<bool, FemError> {
        self.loaded = step.loaded;
        self.corrections.push(step.corrections.clone());
        self.steps.push(ShardStep {
            level_m: step.level_m,
            reached: step.reached,
            fixed_point: step.fixed_point,
            seconds: step.seconds,
        });
        Ok(true)
    }
}

/// Joins the parts of one build of `organ` (any order) into its vademecum: each step's
/// responses separated as a whole build separates them, the steps stopping where a whole
/// build's would. The report's brute-force times are the parts' summed.
pub fn merge(
    organ: &OrganModel,
    settings: &BuildSettings,
    parts: Vec<PartFile>,
    progress: &dyn Progress,
) -> Result<(Vademecum, BuildReport), MergeError> {
    let started = Instant::now();
    let mut parts = in_order(parts)?;
    check_organ(organ, settings, &parts)?;
    with_context(organ, settings, progress, |context| {
        let expected = context.patches.positions.len();
        let first = &parts[0];
        if first.part.header.total_positions != expected {
            return Err(MergeError::OtherPositions {
                file: first.path.clone(),
                expected,
                found: first.part.header.total_positions,
            });
        }
        let steps = first.part.header.steps.len();
        let rows = context.rows();
        let mut separating = Separating::new(context);
        let exact = Responses::joined(rows, parts.iter().map(|p| &p.part.exact));
        parts
            .iter_mut()
            .for_each(|p| p.part.exact.columns = Vec::new());
        let seconds = parts.iter().map(|p| p.part.header.exact_seconds).sum();
        separating.linear(exact, seconds)?;
        let mut range_level_m = vec![0.0f32; expected];
        for s in 0..steps {
            let corrections = Responses::joined(rows, parts.iter().map(|p| &p.part.corrections[s]));
            parts
                .iter_mut()
                .for_each(|p| p.part.corrections[s].columns = Vec::new());
            let step = joined_step(&parts, s, &corrections);
            let (level_m, reached) = (step.level_m, step.reached.clone());
            if !separating.nonlinear(step)? {
                break;
            }
            reached
                .into_iter()
                .for_each(|m| range_level_m[m] = level_m as f32);
        }
        let reference = parts
            .iter()
            .flat_map(|p| p.part.header.reference.iter().copied())
            .collect();
        let ranges = PositionRanges {
            reference,
            range_level_m,
        };
        Ok(separating.finish(organ, ranges, started))
    })
}

/// Step `s` over all the parts.
fn joined_step<'a>(parts: &[PartFile], s: usize, corrections: &'a Responses) -> NonlinearStep<'a> {
    let steps = || parts.iter().map(move |p| &p.part.header.steps[s]);
    NonlinearStep {
        level_m: parts[0].part.header.steps[s].level_m,
        corrections,
        reached: steps()
            .flat_map(|step| step.reached.iter().copied())
            .collect(),
        loaded: parts.iter().map(|p| p.part.header.loaded).sum(),
        fixed_point: steps()
            .map(|step| step.fixed_point)
            .reduce(SecantReport::merge)
            .unwrap_or_default(),
        seconds: steps().map(|step| step.seconds).sum(),
    }
}

/// The parts in shard order, refused unless they are every shard of one build, once.
fn in_order(mut parts: Vec<PartFile>) -> Result<Vec<PartFile>, MergeError> {
    let (first, rest) = parts.split_first().ok_or(MergeError::NoParts)?;
    let first_header = &first.part.header;
    let count = first_header.shard.count;
    for part in rest {
        let header = &part.part.header;
        let other = |what| MergeError::OtherBuild {
            file: part.path.clone(),
            first: first.path.clone(),
            what,
        };
        if header.command != first_header.command {
            return Err(other("build arguments"));
        }
        if header.mesh_hash != first_header.mesh_hash {
            return Err(other("meshes"));
        }
        if header.settings != first_header.settings {
            return Err(other("build settings"));
        }
        if header.shard.count != count {
            return Err(other("shard counts"));
        }
    }
    parts.sort_by_key(|p| p.part.header.shard.index);
    if let Some(pair) = parts
        .windows(2)
        .find(|w| w[0].part.header.shard == w[1].part.header.shard)
    {
        return Err(MergeError::Twice {
            file: pair[0].path.clone(),
            other: pair[1].path.clone(),
            shard: pair[0].part.header.shard,
        });
    }
    let missing: Vec<usize> = (1..=count)
        .filter(|k| !parts.iter().any(|p| p.part.header.shard.index == *k))
        .collect();
    if !missing.is_empty() {
        return Err(MergeError::Missing { count, missing });
    }
    Ok(parts)
}

/// Refuses parts built for another mesh or settings than `organ`'s.
fn check_organ(
    organ: &OrganModel,
    settings: &BuildSettings,
    parts: &[PartFile],
) -> Result<(), MergeError> {
    let part = &parts[0];
    let expected = mesh_hash(organ.model.mesh());
    if part.part.header.mesh_hash != expected {
        return Err(VademecumError::OtherMesh {
            file: part.path.clone(),
            expected,
            found: part.part.header.mesh_hash.clone(),
        }
        .into());
    }
    if &part.part.header.settings != settings {
        return Err(VademecumError::OtherSettings {
            file: part.path.clone(),
            expected: format!("{settings:?}"),
            found: format!("{:?}", part.part.header.settings),
        }
        .into());
    }
    Ok(())
}

/// Writes `part` to `path` atomically.
pub fn save_part(path: &Path, part: &ShardPart) -> Result<(), VademecumError> {
    let header = ron::to_string(&part.header).map_err(|e| VademecumError::Unwritable {
        file: path.to_path_buf(),
        why: e.to_string(),
    })?;
    let mut payload = Vec::new();
    put_f64(&mut payload, &part.exact.columns);
    for corrections in &part.corrections {
        put_f64(&mut payload, &corrections.columns);
    }
    container::write_atomically(path, &container::encode(&KIND, header.as_bytes(), &payload))
}

/// Reads and checks a part.
pub fn load_part(path: &Path) -> Result<PartFile, VademecumError> {
    let bytes = container::read(path)?;
    let (header, payload) = container::checked_parts(&KIND, path, &bytes)?;
    let malformed = |what: String| VademecumError::Malformed {
        file: path.to_path_buf(),
        what,
    };
    let header: PartHeader = std::str::from_utf8(header)
        .map_err(|e| e.to_string())
        .and_then(|text| ron::from_str(text).map_err(|e| e.to_string()))
        .map_err(|e| malformed(format!("header ({e})")))?;
    if header.positions != header.shard.positions(header.total_positions) {
        return Err(malformed(format!(
            "header (positions {:?} are not shard {}'s)",
            header.positions, header.shard
        )));
    }
    let mut reader = Reader::new(path, payload);
    let count = header.positions.len();
    let mut columns = |what: &str, parameters: usize| {
        let values = reader.take_f64(what)?;
        match values.len() == header.rows * parameters {
            true => Ok(Responses {
                rows: header.rows,
                columns: values,
            }),
            false => Err(malformed(format!("{what} ({} values)", values.len()))),
        }
    };
    let exact = columns("exact responses", 3 * count)?;
    let corrections = (0..header.steps.len())
        .map(|s| columns(&format!("step {} corrections", s + 1), count))
        .collect::<Result<Vec<_>, _>>()?;
    reader.finish()?;
    Ok(PartFile {
        path: path.to_path_buf(),
        part: ShardPart {
            header,
            exact,
            corrections,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_read_as_k_of_n_and_refuse_the_rest() {
        assert_eq!("2/4".parse(), Ok(Shard { index: 2, count: 4 }));
        for bad in ["0/4", "5/4", "2", "a/4", "2/", "/"] {
            let error = bad.parse::<Shard>().unwrap_err();
            assert!(error.contains("K/N"), "{bad}: {error}");
        }
    }

    /// The shards' runs tile the positions in order, each starting on a block.
    #[test]
    fn shards_tile_the_positions_in_whole_blocks() {
        for total in [0, 1, 47, 48, 49, 100, 1_456] {
            for count in 1..=6 {
                let runs: Vec<Range<usize>> = (1..=count)
                    .map(|index| Shard { index, count }.positions(total))
                    .collect();
                assert_eq!(runs[0].start, 0);
                assert_eq!(runs[count - 1].end, total, "{total} in {count}");
                for pair in runs.windows(2) {
                    assert_eq!(pair[0].end, pair[1].start);
                }
                for run in &runs {
                    assert!(run.start % BLOCK_COLUMNS == 0 || run.start == total);
                }
            }
        }
        assert_eq!(Shard { index: 1, count: 1 }.positions(100), 0..100);
    }
}
