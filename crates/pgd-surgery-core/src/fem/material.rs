//! Isotropic hyperelastic materials for soft tissue.

use serde::{Deserialize, Serialize};

use super::FemError;

/// Which strain measure and energy the material uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Law {
    /// Small-strain isotropic linear elasticity: exact only for vanishing loads.
    Linear,
    /// Kirchhoff–Saint Venant: the linear law applied to the Green–Lagrange strain, so it is
    /// exact under large rotations. It stiffens under stretch and softens (and finally loses
    /// stability) under strong compression.
    KirchhoffSaintVenant,
    /// Compressible neo-Hookean, `ψ = μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)²`: the same small-strain
    /// limit as the linear law, stable at any compression (the energy grows without bound as
    /// an element's volume goes to zero) and stiffening as tissue is pressed.
    NeoHookean,
    /// The neo-Hookean law with an exponentially stiffening shear part (Demiray's form, made
    /// compressible): `ψ = μ/(2b) (e^{b x} − 1) + λ/2 (ln J)²`, `x = I₁ − 3 − 2 ln J ≥ 0`,
    /// `b` the material's [`Material::stiffening`]. Its stress is the neo-Hookean one with the
    /// shear modulus `μ e^{b x}`, so it matches the linear law at small strain, tends to the
    /// neo-Hookean law as `b → 0`, and firms up as tissue is pressed the way liver does.
    Exponential,
}

impl Law {
    /// Whether its shear modulus grows with the strain: how much a press along the normal
    /// stiffens the tissue under the tool then says how much it stiffens it across (see
    /// `pgd::Vademecum::compliance`). The other laws' nonlinearity is geometric and
    /// volumetric, and differs between the two.
    pub fn modulus_grows_with_strain(self) -> bool {
        self == Law::Exponential
    }

    /// The name the command line and reports use.
    pub fn name(self) -> &'static str {
        match self {
            Law::Linear => "linear",
            Law::KirchhoffSaintVenant => "ksv",
            Law::NeoHookean => "neo-hookean",
            Law::Exponential => "exponential",
        }
    }

    /// Whether the law is nonlinear and stable at any compression, so that its vademecums
    /// reach the depths a trainee presses (the neo-Hookean family).
    pub fn is_hyperelastic(self) -> bool {
        matches!(self, Law::NeoHookean | Law::Exponential)
    }

    /// The stiffening a material of this law gets unless told otherwise.
    pub fn default_stiffening(self) -> f64 {
        match self {
            Law::Exponential => DEFAULT_STIFFENING,
            _ => 0.0,
        }
    }

    /// Whether the law's volumetric energy lives on nodal volumes (see `volumetric.rs`) rather
    /// than in each element.
    pub(super) fn has_nodal_volumes(self) -> bool {
        self.is_hyperelastic()
    }
}

/// An isotropic elastic material in SI units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Material {
    pub law: Law,
    pub young_pa: f64,
    pub poisson: f64,
    pub density_kg_m3: f64,
    /// The exponent `b` of the exponential law (dimensionless; see [`Law::Exponential`]):
    /// how fast the shear modulus grows with strain. Ignored by the other laws.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub stiffening: f64,
}

fn is_zero(value: &f64) -> bool {
    *value == 0.0
}

/// The exponential law's default stiffening `b`, for tissue without a fit of its own.
pub const DEFAULT_STIFFENING: f64 = 2.0;

/// Soft tissue is close to water.
pub const TISSUE_DENSITY_KG_M3: f64 = 1060.0;

impl Material {
    /// A validated material, with the law's default stiffening. Young's modulus and density must
    /// be positive and finite; Poisson's ratio must lie in (−1, 0.5), where the strain energy
    /// is positive definite.
    pub fn new(
        law: Law,
        young_pa: f64,
        poisson: f64,
        density_kg_m3: f64,
    ) -> Result<Self, FemError> {
        let material = Self {
            law,
            young_pa,
            poisson,
            density_kg_m3,
            stiffening: law.default_stiffening(),
        };
        material.validate()?;
        Ok(material)
    }

    /// The same tissue under `law`: a new law gets its default stiffening.
    pub fn with_law(self, law: Law) -> Self {
        match law == self.law {
            true => self,
            false => Self {
                law,
                stiffening: law.default_stiffening(),
                ..self
            },
        }
    }

    /// The material with the exponential law's stiffening `b` (validated: finite, ≥ 0).
    pub fn with_stiffening(self, stiffening: f64) -> Result<Self, FemError> {
        let material = Self { stiffening, ..self };
        material.validate()?;
        Ok(material)
    }

    /// The liver of paper 000: E = 1.60 kPa, ν = 0.48.
    pub fn liver(law: Law) -> Self {
        Self {
            law,
            young_pa: 1600.0,
            poisson: 0.48,
            density_kg_m3: TISSUE_DENSITY_KG_M3,
            stiffening: law.default_stiffening(),
        }
    }

    /// Checks the constants; called by every constructor and by the assembler, since the
    /// fields are public for serialization.
    pub fn validate(&self) -> Result<(), FemError> {
        let bad = |field: &'static str, value: f64, expected: &'static str| {
            Err(FemError::Material {
                field,
                value,
                expected,
            })
        };
        if !(self.young_pa.is_finite() && self.young_pa > 0.0) {
            return bad(
                "young_pa",
                self.young_pa,
                "a positive, finite modulus in pascals",
            );
        }
        if !(self.poisson > -1.0 && self.poisson < 0.5) {
            return bad(
                "poisson",
                self.poisson,
                "a ratio strictly between -1 and 0.5 (0.5 is incompressible, which linear tetrahedra cannot represent)",
            );
        }
        if !(self.stiffening.is_finite() && self.stiffening >= 0.0) {
            return bad(
                "stiffening",
                self.stiffening,
                "a finite, non-negative exponent (0 is the neo-Hookean law)",
            );
        }
        if !(self.density_kg_m3.is_finite() && self.density_kg_m3 > 0.0) {
            return bad(
                "density_kg_m3",
                self.density_kg_m3,
                "a positive, finite density in kg/m³",
            );
        }
        Ok(())
    }

    /// Lamé constants (λ, μ) in pascals.
    pub fn lame(&self) -> (f64, f64) {
        let (e, nu) = (self.young_pa, self.poisson);
        let mu = e / (2.0 * (1.0 + nu));
        let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        (lambda, mu)
    }
}
