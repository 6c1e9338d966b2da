//! The fat and peritoneum of the hepatocystic triangle as strands: a layer in front of the
//! cystic duct, the artery and the common hepatic duct, a crosshatch of strands parallel to
//! the cystic duct and to the common hepatic duct over the parallelogram the two ducts span
//! (the posterior layer, which a surgeon reaches by turning the gallbladder over, is not
//! modelled), following the triangle's corners as the tubes move. Intact, they hide what lies
//! behind them; the hook burns them and blunt dissection tears them, and the share cleared
//! (by volume) is the critical view's first criterion.

use nalgebra::Vector3;

use super::geometry::Segment;
use crate::dissection::{CauteryMode, TissueHeat};

/// A strand's radius (m): strands a diameter apart leave no gap in front of the ducts.
pub const STRAND_RADIUS_M: f64 = 2e-3;
/// Strands each way: the first of each runs over a duct.
const STRANDS_EACH_WAY: usize = 6;
/// Clearance between the layer and the tubes' plane, beyond the common duct's radius (m).
const LAYER_CLEARANCE_M: f64 = 2.5e-3;

/// The hepatocystic triangle's corners on the ducts: the cystic duct's junction with the
/// common duct, its end on the gallbladder and the common hepatic duct's at the hilum (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    pub junction_m: Vector3<f64>,
    pub cystic_end_m: Vector3<f64>,
    pub hilum_m: Vector3<f64>,
}

/// One strand of fat.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FatStrand {
    pub axis: Segment,
    pub radius_m: f64,
    pub cleared: bool,
    /// The hook's energy it has taken (J).
    pub absorbed_j: f64,
}

impl FatStrand {
    /// The energy that divides it in `mode` (J): its cross-section burned through the width of
    /// the hook's zone.
    pub fn burn_j(&self, mode: CauteryMode) -> f64 {
        TissueHeat::FAT.burn_j_per_m3()
            * mode.zone_width_m()
            * std::f64::consts::PI
            * self.radius_m.powi(2)
    }

    pub fn volume_m3(&self) -> f64 {
        std::f64::consts::PI * self.radius_m.powi(2) * self.axis.length_m()
    }

    /// Whether the sight line `sight` passes through it.
    pub fn blocks(&self, sight: &Segment) -> bool {
        !self.cleared && self.axis.closest(sight).distance_m < self.radius_m
    }
}

/// The triangle's fat.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleFat {
    pub strands: Vec<FatStrand>,
    /// Each strand's ends as weights of the triangle's corners (junction, cystic end, hilum):
    /// the strands follow the corners as the tubes move.
    weights: Vec<[Corners; 2]>,
}

/// Weights of the triangle's three corners, summing to one.
type Corners = [f64; 3];

impl TriangleFat {
    /// The layer over the parallelogram `triangle`'s two ducts span, in front of them along
    /// `anterior`, clear of a common duct of radius `common_radius_m`.
    pub fn wrapping(triangle: &Triangle, common_radius_m: f64, anterior: Vector3<f64>) -> Self {
        let corner = triangle.junction_m;
        let along_cystic = triangle.cystic_end_m - corner;
        let along_hepatic = triangle.hilum_m - corner;
        let depth = common_radius_m + LAYER_CLEARANCE_M + STRAND_RADIUS_M;
        let layer = corner + anterior * depth;
        let mut strands = Vec::with_capacity(2 * STRANDS_EACH_WAY);
        let mut weights = Vec::with_capacity(2 * STRANDS_EACH_WAY);
        for k in 0..STRANDS_EACH_WAY {
            let share = k as f64 / STRANDS_EACH_WAY as f64;
            let rows = [
                (along_hepatic * share, along_cystic),
                (along_cystic * share, along_hepatic),
            ];
            strands.extend(rows.map(|(start, run)| FatStrand {
                axis: Segment::new(layer + start, layer + start + run),
                radius_m: STRAND_RADIUS_M,
                cleared: false,
                absorbed_j: 0.0,
            }));
            // The same ends as weights of (junction, cystic end, hilum).
            weights.push([[1.0 - share, 0.0, share], [-share, 1.0, share]]);
            weights.push([[1.0 - share, share, 0.0], [-share, share, 1.0]]);
        }
        Self { strands, weights }
    }

    /// Moves each strand from where it lies in `rest` as the triangle's corners have moved
    /// from theirs by `moved_m` (junction, cystic end, hilum): the fat goes with the ducts it
    /// wraps when the gallbladder is drawn aside.
    pub fn follow(&mut self, rest: &TriangleFat, moved_m: [Vector3<f64>; 3]) {
        let shift = |w: &Corners| (0..3).map(|k| moved_m[k] * w[k]).sum::<Vector3<f64>>();
        for ((strand, at_rest), [from, to]) in self
            .strands
            .iter_mut()
            .zip(&rest.strands)
            .zip(&self.weights)
        {
            strand.axis = Segment::new(
                at_rest.axis.from_m + shift(from),
                at_rest.axis.to_m + shift(to),
            );
        }
    }

    /// The share of the fat's volume cleared.
    pub fn cleared_share(&self) -> f64 {
        let total: f64 = self.strands.iter().map(FatStrand::volume_m3).sum();
        // Folded from +0: a sum of no strands would start at -0, which prints as "-0 %".
        let cleared = (self.strands.iter().filter(|s| s.cleared))
            .map(FatStrand::volume_m3)
            .fold(0.0, |sum, v| sum + v);
        if total > 0.0 { cleared / total } else { 1.0 }
    }

    /// Whether the intact strand `strand` lies within `reach_m` of `at_m`.
    fn within(strand: &FatStrand, at_m: Vector3<f64>, reach_m: f64) -> bool {
        let point = Segment::new(at_m, at_m);
        !strand.cleared && strand.axis.closest(&point).distance_m <= reach_m + strand.radius_m
    }

    /// Tears every intact strand within `reach_m` of `at_m` (jaws closing on them); returns
    /// how many.
    pub fn tear_within(&mut self, at_m: Vector3<f64>, reach_m: f64) -> usize {
        let mut torn = 0;
        for strand in &mut self.strands {
            if Self::within(strand, at_m, reach_m) {
                strand.cleared = true;
                torn += 1;
            }
        }
        torn
    }

    /// The hook's `energy_j` in `mode`, shared among the intact strands within `reach_m` of
    /// `at_m`; each divided once it has taken [`FatStrand::burn_j`]. Returns how many it
    /// reached, and how many it divided now.
    pub fn heat(
        &mut self,
        at_m: Vector3<f64>,
        reach_m: f64,
        energy_j: f64,
        mode: CauteryMode,
    ) -> (usize, usize) {
        let reached = (self.strands.iter())
            .filter(|s| Self::within(s, at_m, reach_m))
            .count();
        if reached == 0 {
            return (0, 0);
        }
        let share_j = energy_j / reached as f64;
        let mut divided = 0;
        for strand in &mut self.strands {
            if Self::within(strand, at_m, reach_m) {
                strand.absorbed_j += share_j;
                if strand.absorbed_j >= strand.burn_j(mode) {
                    strand.cleared = true;
                    divided += 1;
                }
            }
        }
        (reached, divided)
    }

    /// Whether an intact strand stands on the sight line.
    pub fn blocks(&self, sight: &Segment) -> bool {
        self.strands.iter().any(|s| s.blocks(sight))
    }
}
