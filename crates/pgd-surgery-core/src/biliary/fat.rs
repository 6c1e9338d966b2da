//! The fat and peritoneum of the hepatocystic triangle as strands: two layers, one in front
//! of the cystic duct, the artery and the common hepatic duct and one behind them, each a
//! crosshatch of strands parallel to the cystic duct and to the common hepatic duct over the
//! parallelogram the two ducts span. Intact, they hide what lies behind them; the hook burns
//! them and blunt dissection tears them, and the share cleared (by volume) is the critical
//! view's first criterion.

use nalgebra::Vector3;

use super::geometry::Segment;

/// A strand's radius (m): strands a diameter apart leave no gap in front of the ducts.
pub const STRAND_RADIUS_M: f64 = 2e-3;
/// Strands each way in a layer: the first of each runs over a duct.
const STRANDS_EACH_WAY: usize = 6;
/// Clearance between a layer and the tubes' plane, beyond the common duct's radius (m).
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
}

impl FatStrand {
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
}

impl TriangleFat {
    /// The two layers over the parallelogram `triangle`'s two ducts span, in front of and
    /// behind them along `anterior`, clear of a common duct of radius `common_radius_m`.
    pub fn wrapping(triangle: &Triangle, common_radius_m: f64, anterior: Vector3<f64>) -> Self {
        let corner = triangle.junction_m;
        let along_cystic = triangle.cystic_end_m - corner;
        let along_hepatic = triangle.hilum_m - corner;
        let depth = common_radius_m + LAYER_CLEARANCE_M + STRAND_RADIUS_M;
        let mut strands = Vec::with_capacity(4 * STRANDS_EACH_WAY);
        for side in [1.0, -1.0] {
            let layer = corner + anterior * (side * depth);
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
                }));
            }
        }
        Self { strands }
    }

    /// The share of the fat's volume cleared.
    pub fn cleared_share(&self) -> f64 {
        let total: f64 = self.strands.iter().map(FatStrand::volume_m3).sum();
        let cleared: f64 = (self.strands.iter().filter(|s| s.cleared))
            .map(FatStrand::volume_m3)
            .sum();
        if total > 0.0 { cleared / total } else { 1.0 }
    }

    /// Clears every strand whose axis passes within `reach_m` of `at_m`; returns how many.
    pub fn clear_within(&mut self, at_m: Vector3<f64>, reach_m: f64) -> usize {
        let point = Segment::new(at_m, at_m);
        let mut cleared = 0;
        for strand in self.strands.iter_mut().filter(|s| !s.cleared) {
            if strand.axis.closest(&point).distance_m <= reach_m + strand.radius_m {
                strand.cleared = true;
                cleared += 1;
            }
        }
        cleared
    }

    /// Whether an intact strand stands on the sight line.
    pub fn blocks(&self, sight: &Segment) -> bool {
        self.strands.iter().any(|s| s.blocks(sight))
    }
}
