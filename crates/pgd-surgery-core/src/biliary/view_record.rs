//! What the critical view of safety was judged on, kept for the debrief's doublet pictures
//! (`report::critical_view`): the tubes, the fat, the clips and the lower third's ties as they
//! were at the last judging before the view was reached, and at the judging that reached it;
//! after that it stays as it was. Its room is made when the exercise is set up, so that the
//! real-time thread keeps it without allocating.

use nalgebra::Vector3;

use super::anatomy::{BiliaryTree, Structure};
use super::clip::Clip;
use super::critical_view::CriticalView;
use super::fat::FatStrand;
use crate::dissection::{Bed, TieEnds};

/// A tube's centreline as judged.
#[derive(Clone, Debug, PartialEq)]
pub struct TubeShape {
    pub structure: Structure,
    pub outer_radius_m: f64,
    pub positions_m: Vec<Vector3<f64>>,
    /// One per segment: whether the scissors divided it.
    pub divided: Vec<bool>,
}

/// A clip where it was on its tube.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipMark {
    pub structure: Structure,
    pub at_m: Vector3<f64>,
    pub closes_lumen: bool,
}

/// A tie of the gallbladder's lower third: its gallbladder end, and whether it has let go.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TieMark {
    pub at_m: Vector3<f64>,
    pub released: bool,
}

/// An organ's surface near the triangle at rest, and how far it had moved as the sight lines
/// met it (its shift where the tubes enter it).
#[derive(Clone, Debug, PartialEq)]
pub struct OrganPatch {
    pub name: String,
    /// Its place among the scene's organs.
    pub organ: usize,
    pub triangles_m: Vec<[Vector3<f64>; 3]>,
    pub shift_m: Vector3<f64>,
}

impl OrganPatch {
    /// The triangles of organ `organ`'s surface (`positions_m`, `triangles`) with a corner
    /// within `radius_m` of `centre_m`.
    pub fn near(
        (name, organ): (&str, usize),
        positions_m: &[[f32; 3]],
        triangles: &[[u32; 3]],
        centre_m: Vector3<f64>,
        radius_m: f64,
    ) -> Self {
        let at = |k: u32| Vector3::from(positions_m[k as usize].map(f64::from));
        let triangles_m = (triangles.iter())
            .map(|t| t.map(at))
            .filter(|corners| corners.iter().any(|c| (c - centre_m).norm() <= radius_m))
            .collect();
        Self {
            name: name.to_owned(),
            organ,
            triangles_m,
            shift_m: Vector3::zeros(),
        }
    }
}

/// One judging of the critical view.
#[derive(Clone, Copy, Debug)]
pub struct Judging<'a> {
    pub time_s: f64,
    pub optic_m: Vector3<f64>,
    pub view: &'a CriticalView,
    pub tree: &'a BiliaryTree,
    pub clips: &'a [Clip],
    /// The gallbladder's bed and where its ties' ends are, if it lies in one.
    pub bed: Option<(&'a Bed, &'a [TieEnds])>,
    /// How far each organ (in the scene's order) had moved as the sight lines met it.
    pub organ_shifts_m: &'a [Vector3<f64>],
}

/// The scene as the critical view was judged on it.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewRecord {
    /// When it was judged (s from the exercise's start); `None` before the first judging.
    pub time_s: Option<f64>,
    pub optic_m: Vector3<f64>,
    pub view: Option<CriticalView>,
    pub tubes: Vec<TubeShape>,
    pub fat: Vec<FatStrand>,
    pub clips: Vec<ClipMark>,
    pub ties: Vec<TieMark>,
    /// The bed's ties in the gallbladder's lower third, as indices into it.
    lower_third: Vec<usize>,
    pub organs: Vec<OrganPatch>,
}

impl ViewRecord {
    /// Room for `tree` at rest, `clip_room` clips and the bed's ties `lower_third` (indices);
    /// `organs` drawn around it.
    pub fn new(
        tree: &BiliaryTree,
        clip_room: usize,
        lower_third: Vec<usize>,
        organs: Vec<OrganPatch>,
    ) -> Self {
        let tubes = (tree.tubes.iter())
            .map(|tube| TubeShape {
                structure: tube.structure,
                outer_radius_m: tube.section.outer_radius_m,
                positions_m: tube.rod.positions.clone(),
                divided: vec![false; tube.rod.nodes() - 1],
            })
            .collect();
        Self {
            time_s: None,
            optic_m: Vector3::zeros(),
            view: None,
            tubes,
            fat: tree.fat.strands.clone(),
            clips: Vec::with_capacity(clip_room),
            ties: Vec::with_capacity(lower_third.len()),
            lower_third,
            organs,
        }
    }

    /// Whether the critical view was reached: the record stays as it was then.
    pub fn reached(&self) -> bool {
        self.view.is_some_and(|v| v.reached())
    }

    /// Keeps `judging`, unless the view was reached before; allocates nothing while the
    /// clips fit the room made.
    pub fn keep(&mut self, judging: &Judging<'_>) {
        if self.reached() {
            return;
        }
        self.time_s = Some(judging.time_s);
        self.optic_m = judging.optic_m;
        self.view = Some(*judging.view);
        for (shape, tube) in self.tubes.iter_mut().zip(&judging.tree.tubes) {
            shape.positions_m.clone_from(&tube.rod.positions);
            let segments = tube.rod.nodes() - 1;
            shape.divided.clear();
            shape
                .divided
                .extend((0..segments).map(|s| tube.rod.is_divided(s)));
        }
        self.fat.clone_from(&judging.tree.fat.strands);
        let room = self.clips.capacity();
        self.clips.clear();
        self.clips
            .extend(judging.clips.iter().take(room).map(|clip| ClipMark {
                structure: clip.structure,
                at_m: clip.position_m(judging.tree),
                closes_lumen: clip.closes_lumen(),
            }));
        for patch in &mut self.organs {
            patch.shift_m = (judging.organ_shifts_m.get(patch.organ))
                .copied()
                .unwrap_or_default();
        }
        self.ties.clear();
        if let Some((bed, ends)) = judging.bed {
            let marks = (self.lower_third.iter())
                .filter_map(|&k| Some((bed.ties.get(k)?, ends.get(k)?)))
                .map(|(tie, end)| TieMark {
                    at_m: end.freed_m,
                    released: tie.state.failed(&bed.law),
                });
            self.ties.extend(marks);
        }
    }

    /// The centre of the tubes' entries into the gallbladder and of their patient ends: where
    /// the pictures look.
    pub fn centre_m(&self) -> Vector3<f64> {
        let ends: Vec<Vector3<f64>> = (self.tubes.iter())
            .filter_map(|t| Some([*t.positions_m.first()?, *t.positions_m.last()?]))
            .flatten()
            .collect();
        ends.iter().sum::<Vector3<f64>>() / ends.len().max(1) as f64
    }
}
