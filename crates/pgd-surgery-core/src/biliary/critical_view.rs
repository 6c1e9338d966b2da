//! The critical view of safety (Strasberg), judged from the scene: (1) the hepatocystic
//! triangle cleared of fat, as the share of its fat's volume cleared; (2) the lower third of
//! the gallbladder separated from its bed, as the share of the bed's area there whose ties
//! have failed; (3) two structures, and only two, seen entering the gallbladder: each tube
//! that enters it seen from the optic along its last centimetre, unhidden by fat, by the other
//! tubes and by the organs.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::anatomy::{BiliaryTree, Structure, Tube};
use super::geometry::Segment;
use crate::dissection::Bed;
use crate::mesh::organs::Abdomen;

/// How much of each criterion is enough; a scenario may ask for more or less.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename = "CriticalView", default, deny_unknown_fields)]
pub struct CriticalViewRule {
    /// The share of the triangle's fat cleared.
    pub triangle_cleared: f64,
    /// The share of the gallbladder's lower third released from its bed.
    pub lower_third_released: f64,
    /// The share of a tube's last centimetre in sight for it to count as seen.
    pub seen_share: f64,
}

impl Default for CriticalViewRule {
    fn default() -> Self {
        Self {
            triangle_cleared: 0.9,
            lower_third_released: 0.9,
            seen_share: 0.5,
        }
    }
}

/// How far back from the gallbladder a tube is looked at (m), and at how many points.
pub const ENTRY_M: f64 = 0.01;
const ENTRY_SAMPLES: usize = 6;

/// Where the gallbladder's lower third starts along its axis, from the fundus (0) to the
/// neck (1).
const LOWER_THIRD_FROM: f64 = 2.0 / 3.0;

/// A tube entering the gallbladder and how much of its entry is in sight.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Entering {
    pub structure: Structure,
    pub seen_share: f64,
}

/// The three criteria as measured, and the rule they were judged by.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CriticalView {
    pub triangle_cleared: f64,
    pub lower_third_released: f64,
    /// The tubes entering the gallbladder, in the tree's order (room for every tube, so that
    /// judging allocates nothing).
    entering: [Option<Entering>; 3],
    pub rule: CriticalViewRule,
}

impl CriticalView {
    /// Judges `tree` from the optic at `optic_m`, the gallbladder's lower third
    /// `lower_third_released` off its bed; `organs_hide` says whether an organ stands on a
    /// sight line.
    pub fn judge(
        tree: &BiliaryTree,
        lower_third_released: f64,
        optic_m: Vector3<f64>,
        organs_hide: impl Fn(&Segment) -> bool,
        rule: CriticalViewRule,
    ) -> Self {
        let entering = std::array::from_fn(|k| {
            let tube = tree.tubes.get(k).filter(|t| t.enters_gallbladder)?;
            Some(Entering {
                structure: tube.structure,
                seen_share: seen_share(tree, tube, optic_m, &organs_hide),
            })
        });
        Self {
            triangle_cleared: tree.fat.cleared_share(),
            lower_third_released,
            entering,
            rule,
        }
    }

    /// The tubes entering the gallbladder, and how much of each is seen.
    pub fn entering(&self) -> impl Iterator<Item = &Entering> {
        self.entering.iter().flatten()
    }

    pub fn triangle_met(&self) -> bool {
        self.triangle_cleared >= self.rule.triangle_cleared
    }

    pub fn lower_third_met(&self) -> bool {
        self.lower_third_released >= self.rule.lower_third_released
    }

    /// The tubes seen entering the gallbladder.
    pub fn seen(&self) -> usize {
        (self.entering())
            .filter(|e| e.seen_share >= self.rule.seen_share)
            .count()
    }

    /// Two tubes enter the gallbladder, and both are seen.
    pub fn two_structures_met(&self) -> bool {
        self.entering().count() == 2 && self.seen() == 2
    }

    /// All three criteria met.
    pub fn reached(&self) -> bool {
        self.triangle_met() && self.lower_third_met() && self.two_structures_met()
    }
}

/// The share of `tube`'s last [`ENTRY_M`] whose near side is in sight from `optic_m`.
fn seen_share(
    tree: &BiliaryTree,
    tube: &Tube,
    optic_m: Vector3<f64>,
    organs_hide: &impl Fn(&Segment) -> bool,
) -> f64 {
    let length_m = tube.length_m();
    let seen = (0..ENTRY_SAMPLES)
        .filter(|&k| {
            let from_end_m = ENTRY_M * (k as f64 + 0.5) / ENTRY_SAMPLES as f64;
            let centre = tube.point_at(length_m - from_end_m);
            let towards = (optic_m - centre).normalize();
            let sight = Segment::new(centre + towards * tube.section.outer_radius_m, optic_m);
            !(tree.fat.blocks(&sight)
                || other_tubes_hide(tree, tube, &sight)
                || organs_hide(&sight))
        })
        .count();
    seen as f64 / ENTRY_SAMPLES as f64
}

fn other_tubes_hide(tree: &BiliaryTree, looked_at: &Tube, sight: &Segment) -> bool {
    (tree
        .tubes
        .iter()
        .filter(|t| t.structure != looked_at.structure))
    .any(|tube| {
        (tube.segments())
            .any(|(_, axis)| axis.closest(sight).distance_m < tube.section.outer_radius_m)
    })
}

/// The share of the area of `bed` within the freed organ's lower third whose ties have
/// failed; 1 where the bed has no tie there. `coords_m` are the freed organ's load positions
/// at rest.
pub fn lower_third_released(bed: &Bed, coords_m: &[[f32; 3]], third: &LowerThird) -> f64 {
    let (mut area, mut released) = (0.0, 0.0);
    for tie in third.tie_indices(bed, coords_m).map(|k| &bed.ties[k]) {
        area += tie.area_m2;
        if tie.state.failed(&bed.law) {
            released += tie.area_m2;
        }
    }
    if area > 0.0 { released / area } else { 1.0 }
}

/// The gallbladder's lower third: its third nearest the neck along its axis from the fundus.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LowerThird {
    pub fundus_m: Vector3<f64>,
    pub neck_m: Vector3<f64>,
}

impl LowerThird {
    /// The gallbladder's of `abdomen`.
    pub fn of(abdomen: &Abdomen) -> Self {
        let (fundus, neck) = abdomen.gallbladder_axis_m();
        Self {
            fundus_m: fundus.coords,
            neck_m: neck.coords,
        }
    }

    /// Whether `at_m` lies in it.
    pub fn holds(&self, at_m: Vector3<f64>) -> bool {
        let axis = self.neck_m - self.fundus_m;
        (at_m - self.fundus_m).dot(&axis) / axis.norm_squared() >= LOWER_THIRD_FROM
    }

    /// The indices of `bed`'s ties in it, `coords_m` the freed organ's load positions at rest.
    pub fn tie_indices<'a>(
        &'a self,
        bed: &'a Bed,
        coords_m: &'a [[f32; 3]],
    ) -> impl Iterator<Item = usize> + 'a {
        (bed.ties.iter().enumerate())
            .filter(|(_, tie)| self.holds(Vector3::from(coords_m[tie.position].map(f64::from))))
            .map(|(k, _)| k)
    }
}
