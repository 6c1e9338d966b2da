//! A bed: one organ bound to another by cohesive ties where their surfaces face each other at
//! rest (the gallbladder in its bed on the liver). Each tie joins a load position of the
//! organ to be freed to the facing point of the base organ's surface, carries the law's
//! traction over the position's share of the surface, and loads both organs, equal and
//! opposite. Their separation is the two displacements' difference: the rest gap, however
//! small, is the tissue's own thickness.

use std::fmt;

use nalgebra::{Unit, Vector3};

use super::cohesive::{CohesiveLaw, CohesiveTie};
use crate::contact::{ContactSurface, SurfaceHit};
use crate::pgd::{SurfacePoint, Vademecum};

/// The most the two surfaces' normals may turn from facing each other for a tie (60°).
const FACING_COS: f64 = 0.5;

/// One tie.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tie {
    /// The freed organ's load position.
    pub position: usize,
    /// The facing point of the base organ's surface at rest.
    pub facing: SurfacePoint,
    /// The base's outward normal there: the tie opens along it.
    pub normal: Unit<Vector3<f64>>,
    /// The position's share of the freed organ's surface (m²).
    pub area_m2: f64,
    pub state: CohesiveTie,
}

/// Where a tie's two ends are (m, the scene's frame): on the freed organ and on its base.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TieEnds {
    pub freed_m: Vector3<f64>,
    pub base_m: Vector3<f64>,
}

impl TieEnds {
    pub fn middle_m(&self) -> Vector3<f64> {
        (self.freed_m + self.base_m) * 0.5
    }
}

/// The freed organ's surface as its load positions: where each is at rest (m), its outward
/// normal and its share of the surface (m²).
pub struct FreedSurface<'a> {
    pub coords_m: &'a [[f32; 3]],
    pub normals: &'a [Vector3<f64>],
    pub areas_m2: &'a [f32],
}

/// Why no bed was made.
#[derive(Clone, Debug, PartialEq)]
pub enum BedError {
    /// No load position of the freed organ faces the base's surface within the gap; the
    /// nearest facing one is `nearest_m` away (infinite when none faces it at all).
    NotFacing { gap_m: f64, nearest_m: f64 },
}

impl fmt::Display for BedError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotFacing { gap_m, nearest_m } if nearest_m.is_finite() => write!(
                f,
                "the surfaces do not face each other within {:.1} mm: the nearest facing points \
                 are {:.1} mm apart",
                gap_m * 1e3,
                nearest_m * 1e3
            ),
            Self::NotFacing { gap_m, .. } => write!(
                f,
                "the surfaces do not face each other within {:.1} mm: none of them turns toward \
                 the other",
                gap_m * 1e3
            ),
        }
    }
}

impl std::error::Error for BedError {}

/// The ties between two organs, and their law.
#[derive(Clone, Debug, PartialEq)]
pub struct Bed {
    pub law: CohesiveLaw,
    pub ties: Vec<Tie>,
}

impl Bed {
    /// Ties every load position of `freed` that faces the base's surface within `gap_m` (the
    /// point of the base nearest it, by `closest`, no further than the gap, the two normals
    /// turned from each other by less than 60°).
    pub fn between(
        law: CohesiveLaw,
        freed: &FreedSurface<'_>,
        closest: impl Fn(&Vector3<f64>) -> Option<SurfaceHit>,
        gap_m: f64,
    ) -> Result<Self, BedError> {
        let mut ties = Vec::new();
        let mut nearest_m = f64::INFINITY;
        for (position, coords) in freed.coords_m.iter().enumerate() {
            let at = Vector3::from(coords.map(f64::from));
            let Some(hit) = closest(&at) else {
                continue;
            };
            if freed.normals[position].dot(&hit.normal) > -FACING_COS {
                continue;
            }
            let distance_m = (at - hit.point_m).norm();
            nearest_m = nearest_m.min(distance_m);
            if distance_m > gap_m {
                continue;
            }
            ties.push(Tie {
                position,
                facing: hit.at,
                normal: Unit::new_normalize(hit.normal),
                area_m2: f64::from(freed.areas_m2[position]),
                state: CohesiveTie::default(),
            });
        }
        if ties.is_empty() {
            return Err(BedError::NotFacing { gap_m, nearest_m });
        }
        Ok(Self { law, ties })
    }

    /// [`Self::between`] the organ of the vademecum `freed` and the base organ's contact
    /// surface `base`.
    pub fn on(
        law: CohesiveLaw,
        freed: &Vademecum,
        base: &ContactSurface,
        gap_m: f64,
    ) -> Result<Self, BedError> {
        let normals = freed.rest_normals();
        let surface = FreedSurface {
            coords_m: &freed.position_coords_m,
            normals: &normals,
            areas_m2: &freed.position_areas_m2,
        };
        Self::between(law, &surface, |at| base.closest(at), gap_m)
    }

    /// The bed's area (m²).
    pub fn area_m2(&self) -> f64 {
        self.ties.iter().map(|t| t.area_m2).sum()
    }

    /// The share of the bed's area whose ties have failed.
    pub fn released_share(&self) -> f64 {
        let released = (self.ties.iter())
            .filter(|t| t.state.failed(&self.law))
            .fold(0.0, |sum, t| sum + t.area_m2);
        released / self.area_m2()
    }
}

/// A whole tie of `area_m2` at load position `position` over the plane `z = 0`, facing the
/// first corner of triangle 0: the dissection modules' tests' bed.
#[cfg(test)]
pub(crate) fn tie_over_plane(position: usize, area_m2: f64) -> Tie {
    Tie {
        position,
        facing: SurfacePoint {
            triangle: 0,
            barycentric: [1.0, 0.0, 0.0],
        },
        normal: Unit::new_normalize(Vector3::z()),
        area_m2,
        state: CohesiveTie::default(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The base: the plane z = 0, its outward normal up, every point its own nearest; a
    /// point's barycentric weights carry its x and y so that the test can tell them apart.
    fn plane(at: &Vector3<f64>) -> Option<SurfaceHit> {
        Some(SurfaceHit {
            at: SurfacePoint {
                triangle: 0,
                barycentric: [at.x, at.y, 0.0],
            },
            point_m: Vector3::new(at.x, at.y, 0.0),
            normal: Vector3::z(),
        })
    }

    /// A 5 × 5 grid 2 mm apart, 0.5 mm above the plane and facing it; two more positions
    /// above it facing away, and one facing it 10 mm up.
    struct Freed {
        coords_m: Vec<[f32; 3]>,
        normals: Vec<Vector3<f64>>,
        areas_m2: Vec<f32>,
    }

    fn freed() -> Freed {
        let mut coords_m: Vec<[f32; 3]> = (0..25)
            .map(|k| [0.002 * (k % 5) as f32, 0.002 * (k / 5) as f32, 0.0005])
            .collect();
        let mut normals = vec![-Vector3::z(); 25];
        coords_m.extend([[0.0, 0.0, 0.0005], [0.002, 0.0, 0.0005], [0.0, 0.0, 0.01]]);
        normals.extend([Vector3::z(), Vector3::x(), -Vector3::z()]);
        let areas_m2 = vec![4e-6; coords_m.len()];
        Freed {
            coords_m,
            normals,
            areas_m2,
        }
    }

    fn bed_on_plane(freed: &Freed, gap_m: f64) -> Result<Bed, BedError> {
        let surface = FreedSurface {
            coords_m: &freed.coords_m,
            normals: &freed.normals,
            areas_m2: &freed.areas_m2,
        };
        Bed::between(CohesiveLaw::gallbladder_bed(), &surface, plane, gap_m)
    }

    /// Within 1 mm the bed ties the 25 facing positions only; the one 10 mm up is not tied,
    /// and a bed asked within 0.2 mm is refused, naming the nearest facing distance.
    #[test]
    fn a_bed_ties_the_positions_that_face_the_base_within_the_gap() {
        let freed = freed();
        let bed = bed_on_plane(&freed, 1e-3).unwrap();
        let tied: Vec<usize> = bed.ties.iter().map(|t| t.position).collect();
        assert_eq!(tied, (0..25).collect::<Vec<_>>());
        assert!((bed.area_m2() - 25.0 * f64::from(4e-6_f32)).abs() < 1e-18);
        let refused = bed_on_plane(&freed, 0.2e-3).unwrap_err();
        assert_eq!(
            refused,
            BedError::NotFacing {
                gap_m: 0.2e-3,
                nearest_m: 0.0005f32 as f64
            }
        );
        assert!(refused.to_string().contains("0.5 mm apart"), "{refused}");
    }
}
