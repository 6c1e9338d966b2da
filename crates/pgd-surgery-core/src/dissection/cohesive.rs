//! A bilinear cohesive law with irreversible damage: the traction a tie of connective tissue
//! carries per unit area as its two faces separate. It rises with the separation at the
//! tissue's initial stiffness to its peak traction, then falls linearly to nothing at the
//! failure separation; the area under it is the fracture energy, what releasing a square
//! metre of attachment costs. Tension and shear count together through one effective
//! separation; pressing the faces together is resisted undamaged (the organs' contact).
//! Damage follows the largest effective separation reached and never heals: a tie let back
//! unloads along its damaged secant.

use std::fmt;

use nalgebra::{Unit, Vector3};

/// The tissue's traction–separation law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CohesiveLaw {
    /// Traction per unit separation before any damage (Pa/m).
    pub stiffness_pa_per_m: f64,
    /// The largest traction the tissue carries (Pa).
    pub peak_traction_pa: f64,
    /// The energy that frees a unit area (J/m²): the area under the law.
    pub fracture_energy_j_per_m2: f64,
}

/// Why a law was refused.
#[derive(Clone, Debug, PartialEq)]
pub enum CohesiveError {
    /// A parameter that must be finite and positive is not.
    NotPositive { name: &'static str, value: f64 },
    /// The fracture energy is too small for the peak traction and the stiffness: the law
    /// would fail before it peaked (`2 G / T` at most `T / K`).
    Brittle {
        least_j_per_m2: f64,
        given_j_per_m2: f64,
    },
}

impl fmt::Display for CohesiveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotPositive { name, value } => {
                write!(f, "{name} must be finite and above zero, not {value}")
            }
            Self::Brittle {
                least_j_per_m2,
                given_j_per_m2,
            } => write!(
                f,
                "a fracture energy of {given_j_per_m2} J/m² fails before the peak traction; \
                 give more than {least_j_per_m2:.4} J/m², or a lower peak or a stiffer tissue"
            ),
        }
    }
}

impl std::error::Error for CohesiveError {}

impl CohesiveLaw {
    /// The areolar tissue of the gallbladder's bed, assumed (no peel test of it is
    /// published that we know of; `docs/dissection.md` gives the ranges and what bounds
    /// them): 50 J/m², a third of the porcine liver's cutting toughness (76–225 J/m²); a
    /// peak of 5 kPa, far below the liver capsule's failure tension (66–386 kPa); failing at
    /// 20 mm of opening, reached at 1 mm.
    pub fn gallbladder_bed() -> Self {
        Self {
            stiffness_pa_per_m: 5.0e6,
            peak_traction_pa: 5.0e3,
            fracture_energy_j_per_m2: 50.0,
        }
    }

    /// The law, checked: every parameter finite and positive, and the failure separation
    /// beyond the peak's.
    pub fn new(
        stiffness_pa_per_m: f64,
        peak_traction_pa: f64,
        fracture_energy_j_per_m2: f64,
    ) -> Result<Self, CohesiveError> {
        let named = [
            ("stiffness_pa_per_m", stiffness_pa_per_m),
            ("peak_traction_pa", peak_traction_pa),
            ("fracture_energy_j_per_m2", fracture_energy_j_per_m2),
        ];
        if let Some(&(name, value)) = named.iter().find(|(_, v)| !(v.is_finite() && *v > 0.0)) {
            return Err(CohesiveError::NotPositive { name, value });
        }
        let law = Self {
            stiffness_pa_per_m,
            peak_traction_pa,
            fracture_energy_j_per_m2,
        };
        let least_j_per_m2 = 0.5 * peak_traction_pa * law.peak_separation_m();
        if fracture_energy_j_per_m2 <= least_j_per_m2 {
            return Err(CohesiveError::Brittle {
                least_j_per_m2,
                given_j_per_m2: fracture_energy_j_per_m2,
            });
        }
        Ok(law)
    }

    /// The separation at the peak traction (m).
    pub fn peak_separation_m(&self) -> f64 {
        self.peak_traction_pa / self.stiffness_pa_per_m
    }

    /// The separation at which the tie has failed (m): the law's area is the fracture energy.
    pub fn failure_separation_m(&self) -> f64 {
        2.0 * self.fracture_energy_j_per_m2 / self.peak_traction_pa
    }

    /// The damage (0 intact, 1 failed) of a tie whose largest effective separation so far is
    /// `reached_m`: what is left of its stiffness is `1 − d`, so that the traction there lies
    /// on the softening line.
    pub fn damage(&self, reached_m: f64) -> f64 {
        let (peak, failure) = (self.peak_separation_m(), self.failure_separation_m());
        if reached_m <= peak {
            0.0
        } else if reached_m >= failure {
            1.0
        } else {
            failure * (reached_m - peak) / (reached_m * (failure - peak))
        }
    }
}

/// One tie's history: the largest effective separation it has reached (m).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CohesiveTie {
    pub reached_m: f64,
}

impl CohesiveTie {
    /// The traction (Pa) the tie puts on the face that moved by `separation_m` from the other,
    /// pulling it back, under `law`, the faces' `normal` pointing from the other face to this
    /// one. The tie's damage grows with the effective separation `√(⟨δₙ⟩² + |δₜ|²)` (only
    /// opening counts along the normal) and never shrinks; a closing face is pushed back at
    /// the undamaged stiffness.
    pub fn traction(
        &mut self,
        law: &CohesiveLaw,
        separation_m: &Vector3<f64>,
        normal: &Unit<Vector3<f64>>,
    ) -> Vector3<f64> {
        let along = separation_m.dot(normal);
        let opening = along.max(0.0);
        let sliding = separation_m - normal.into_inner() * along;
        let effective = (opening * opening + sliding.norm_squared()).sqrt();
        self.reached_m = self.reached_m.max(effective);
        let kept = self.secant_pa_per_m(law);
        let closing = along.min(0.0);
        -(sliding + normal.into_inner() * opening) * kept
            - normal.into_inner() * (closing * law.stiffness_pa_per_m)
    }

    /// The traction (Pa) of the tie opened by the effective separation `effective_m` (≥ 0)
    /// under `law`, its damage grown with it: what a tie pulled open along a line carries.
    pub fn open(&mut self, law: &CohesiveLaw, effective_m: f64) -> f64 {
        self.reached_m = self.reached_m.max(effective_m);
        self.secant_pa_per_m(law) * effective_m
    }

    /// What is left of the tie's stiffness (Pa/m): a tie let back unloads along it.
    pub fn secant_pa_per_m(&self, law: &CohesiveLaw) -> f64 {
        law.stiffness_pa_per_m * (1.0 - self.damage(law))
    }

    /// How damaged the tie is under `law` (0 intact, 1 failed).
    pub fn damage(&self, law: &CohesiveLaw) -> f64 {
        law.damage(self.reached_m)
    }

    /// Divides the tie for good (burned through): it fails as if opened to its failure
    /// separation.
    pub fn sever(&mut self, law: &CohesiveLaw) {
        self.reached_m = self.reached_m.max(law.failure_separation_m());
    }

    /// Whether the tie has failed: it carries nothing in tension or shear any more.
    pub fn failed(&self, law: &CohesiveLaw) -> bool {
        self.damage(law) >= 1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 2 kPa at 0.5 mm, failing at 10 mm: 10 J/m².
    fn law() -> CohesiveLaw {
        CohesiveLaw::new(4.0e6, 2.0e3, 10.0).unwrap()
    }

    fn up() -> Unit<Vector3<f64>> {
        Vector3::z_axis()
    }

    /// Opened along the normal and held, the traction is the bilinear law's, in closed form:
    /// `K δ` up to the peak, `T (δf − δ) / (δf − δ₀)` on the softening line, nothing beyond.
    #[test]
    fn a_held_opening_carries_the_closed_form_traction() {
        let law = law();
        let (peak, failure) = (law.peak_separation_m(), law.failure_separation_m());
        assert!((peak - 0.5e-3).abs() < 1e-15 && (failure - 10e-3).abs() < 1e-15);
        for delta in [0.1e-3, 0.5e-3, 1.0e-3, 4.0e-3, 9.9e-3, 12e-3] {
            let mut tie = CohesiveTie::default();
            let pulled = tie.traction(&law, &(Vector3::z() * delta), &up());
            let expected = if delta <= peak {
                law.stiffness_pa_per_m * delta
            } else {
                (law.peak_traction_pa * (failure - delta) / (failure - peak)).max(0.0)
            };
            assert!(
                (pulled + Vector3::z() * expected).norm() <= 1e-9 * law.peak_traction_pa,
                "at {delta} m: {pulled:?} against {expected} Pa"
            );
        }
    }

    /// Opened steadily until it fails, the tie has taken the fracture energy (the work of its
    /// traction, summed by the trapezoid rule over 20,000 steps), to 1e-6; shear frees it at
    /// the same cost.
    #[test]
    fn a_tie_opened_to_failure_takes_the_fracture_energy() {
        let law = law();
        for direction in [Vector3::z(), Vector3::x()] {
            let mut tie = CohesiveTie::default();
            let steps = 20_000;
            let end = 1.2 * law.failure_separation_m();
            let (mut work, mut last) = (0.0, 0.0);
            for k in 1..=steps {
                let delta = end * f64::from(k) / f64::from(steps);
                let traction = -tie
                    .traction(&law, &(direction * delta), &up())
                    .dot(&direction);
                work += 0.5 * (traction + last) * end / f64::from(steps);
                last = traction;
            }
            let error = (work - law.fracture_energy_j_per_m2).abs() / law.fracture_energy_j_per_m2;
            assert!(error < 1e-6, "{direction:?}: {work} J/m², off by {error}");
            assert!(tie.failed(&law));
        }
    }

    /// Damage never heals: a tie opened past its peak and let back unloads along its damaged
    /// secant, giving back `(1 − d) K δ²/2` of what it took, keeps its damage when closed, and
    /// reloads along the same secant until it passes where it had reached.
    #[test]
    fn damage_never_heals() {
        let law = law();
        let mut tie = CohesiveTie::default();
        let reached = 3.0e-3;
        tie.traction(&law, &(Vector3::z() * reached), &up());
        let d = tie.damage(&law);
        let expected = law.failure_separation_m() * (reached - law.peak_separation_m())
            / (reached * (law.failure_separation_m() - law.peak_separation_m()));
        assert!((d - expected).abs() < 1e-12 && d > 0.0 && d < 1.0);
        let half = tie.traction(&law, &(Vector3::z() * 0.5 * reached), &up());
        let secant = (1.0 - d) * law.stiffness_pa_per_m;
        assert!((half.z + secant * 0.5 * reached).abs() < 1e-9);
        tie.traction(&law, &Vector3::zeros(), &up());
        assert_eq!(tie.damage(&law), d);
        let again = tie.traction(&law, &(Vector3::z() * reached), &up());
        assert!((again.z + secant * reached).abs() < 1e-9);
        let further = tie.traction(&law, &(Vector3::z() * 1.5 * reached), &up());
        assert!(tie.damage(&law) > d && -further.z < -again.z * 1.5);
    }

    /// Pressed together the faces are pushed apart at the undamaged stiffness, however
    /// damaged the tie, and the press damages nothing.
    #[test]
    fn closing_is_resisted_undamaged() {
        let law = law();
        let mut tie = CohesiveTie {
            reached_m: 2.0 * law.failure_separation_m(),
        };
        let pushed = tie.traction(&law, &(Vector3::z() * -1e-3), &up());
        assert!((pushed.z - law.stiffness_pa_per_m * 1e-3).abs() < 1e-9);
        let mut fresh = CohesiveTie::default();
        fresh.traction(&law, &(Vector3::z() * -1e-3), &up());
        assert_eq!(fresh.damage(&law), 0.0);
    }

    /// A law that fails before it peaks, or a parameter that is not a positive number, is
    /// refused, naming it; the bed's own law is accepted.
    #[test]
    fn bad_laws_are_refused() {
        let bed = CohesiveLaw::gallbladder_bed();
        let checked = CohesiveLaw::new(
            bed.stiffness_pa_per_m,
            bed.peak_traction_pa,
            bed.fracture_energy_j_per_m2,
        );
        assert_eq!(checked, Ok(bed));
        assert!(matches!(
            CohesiveLaw::new(4.0e6, 2.0e3, 0.4),
            Err(CohesiveError::Brittle { .. })
        ));
        let error = CohesiveLaw::new(4.0e6, f64::NAN, 10.0).unwrap_err();
        assert!(error.to_string().contains("peak_traction_pa"), "{error}");
        assert!(CohesiveLaw::new(-1.0, 2.0e3, 10.0).is_err());
    }
}
