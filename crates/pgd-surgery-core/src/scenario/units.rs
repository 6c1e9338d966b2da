//! Quantities in the units a scenario names, each refused out of its sensible range with a
//! hint, while the file is read (so the error carries the line, column and field path).

use serde::Deserialize;

/// A length in millimetres, more than 0.5 mm and at most half a metre.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct Millimetres(pub f64);

impl Millimetres {
    pub fn metres(self) -> f64 {
        self.0 * 1e-3
    }
}

impl TryFrom<f64> for Millimetres {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if !v.is_finite() => Err(format!("{v} is not a length")),
            v if v < 0.5 => Err(format!(
                "{v} mm is too small: lengths here are in millimetres (a 6 mm tip is `6.0`, not `0.006`)"
            )),
            v if v > 500.0 => Err(format!(
                "{v} mm is larger than the abdomen: lengths here are in millimetres"
            )),
            v => Ok(Self(v)),
        }
    }
}

/// A force in newtons, from 0 to 20 N.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct Newtons(pub f64);

impl TryFrom<f64> for Newtons {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if !v.is_finite() || v < 0.0 => {
                Err(format!("{v} is not a force (newtons, 0 or more)"))
            }
            v if v > 20.0 => Err(format!(
                "{v} N is more than any haptic device gives: forces here are in newtons (a firm press on the liver is about 0.3 N)"
            )),
            v => Ok(Self(v)),
        }
    }
}

impl std::fmt::Display for Newtons {
    /// To the millinewton, with two decimals at least: 0.06, 0.035, 0.60.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let text = format!("{:.3}", self.0);
        match text.strip_suffix('0') {
            Some(two) => f.write_str(two),
            None => f.write_str(&text),
        }
    }
}

/// A duration in seconds, more than 0 and at most an hour.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct Seconds(pub f64);

impl TryFrom<f64> for Seconds {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if !v.is_finite() || v <= 0.0 => {
                Err(format!("{v} is not a duration (seconds, more than 0)"))
            }
            v if v > 3600.0 => Err(format!(
                "{v} s is more than an hour: durations here are in seconds"
            )),
            v => Ok(Self(v)),
        }
    }
}

/// A Young's modulus of soft tissue, from 100 Pa to 1 MPa.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct Pascals(pub f64);

impl TryFrom<f64> for Pascals {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if v.is_finite() && (100.0..=1e6).contains(&v) => Ok(Self(v)),
            v => Err(format!(
                "{v} Pa is not the stiffness of soft tissue: from 100 Pa to 1 MPa (liver about 1.6 kPa; kilopascals must be written in pascals)"
            )),
        }
    }
}

/// How many times the device's motion is scaled in the scene: from 0.1 (fine work) to 10.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct Scale(pub f64);

impl TryFrom<f64> for Scale {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if v.is_finite() && (0.1..=10.0).contains(&v) => Ok(Self(v)),
            v => Err(format!(
                "{v} is not a workspace scale: from 0.1 to 10 (1 moves the tool as far as the hand)"
            )),
        }
    }
}

/// A stiffness ratio of a nodule to its organ: more than 1 (stiffer) and at most 50.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct Ratio(pub f64);

impl TryFrom<f64> for Ratio {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if !v.is_finite() || v <= 1.0 => Err(format!(
                "{v} is not the ratio of a stiffer nodule: it must be more than 1 (a tumour is typically 3 to 10 times stiffer)"
            )),
            v if v > 50.0 => Err(format!(
                "{v} is stiffer than any tissue over its organ: at most 50 (a tumour is typically 3 to 10 times stiffer)"
            )),
            v => Ok(Self(v)),
        }
    }
}

/// A Poisson's ratio of soft tissue: from 0 to 0.499 (incompressible at 0.5, which linear
/// elements lock on).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct PoissonRatio(pub f64);

impl TryFrom<f64> for PoissonRatio {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if v.is_finite() && (0.0..=0.499).contains(&v) => Ok(Self(v)),
            v => Err(format!(
                "{v} is not a Poisson's ratio of soft tissue: from 0 to 0.499 (organs are about 0.45 to 0.49)"
            )),
        }
    }
}

/// The exponential law's stiffening exponent b: from 0 (neo-Hookean) to 50.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct Stiffening(pub f64);

impl TryFrom<f64> for Stiffening {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if v.is_finite() && (0.0..=50.0).contains(&v) => Ok(Self(v)),
            v => Err(format!(
                "{v} is not a stiffening exponent: from 0 (neo-Hookean) to 50 (`pgd fit` gives it from a uniaxial test of the tissue)"
            )),
        }
    }
}

/// A number of vademecum modes: from 1 to 400.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(try_from = "u64")]
pub struct ModeCount(pub usize);

impl TryFrom<u64> for ModeCount {
    type Error = String;
    fn try_from(value: u64) -> Result<Self, String> {
        match value {
            1..=400 => Ok(Self(value as usize)),
            v => Err(format!(
                "{v} modes: from 1 to 400 (the builder stops earlier when its error target is met)"
            )),
        }
    }
}

/// A tissue's fracture toughness in joules per square metre, from 10 to 100,000 (soft organs
/// are 10²–10³, skin and cornea 10³–10⁴).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct Toughness(pub f64);

impl TryFrom<f64> for Toughness {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if v.is_finite() && (10.0..=1e5).contains(&v) => Ok(Self(v)),
            v => Err(format!(
                "{v} J/m² is not a tissue's toughness (10 to 100000; the liver's is about 190)"
            )),
        }
    }
}

/// A laparoscope's viewing angle to its shaft, in degrees: from 0 to 70 (optics are made at
/// 0°, 30°, 45° and 70°).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct ScopeAngle(pub f64);

impl ScopeAngle {
    pub fn radians(self) -> f64 {
        self.0.to_radians()
    }
}

impl TryFrom<f64> for ScopeAngle {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if v.is_finite() && (0.0..=70.0).contains(&v) => Ok(Self(v)),
            v => Err(format!(
                "{v}° is not a laparoscope's angle: from 0 to 70 degrees (0 and 30 are the usual optics)"
            )),
        }
    }
}

/// A laparoscope's field of view across its round image, in degrees: from 30 to 120.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct FieldOfView(pub f64);

impl FieldOfView {
    pub fn radians(self) -> f64 {
        self.0.to_radians()
    }
}

impl TryFrom<f64> for FieldOfView {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if v.is_finite() && (30.0..=120.0).contains(&v) => Ok(Self(v)),
            v => Err(format!(
                "{v}° is not a laparoscope's field of view: from 30 to 120 degrees (about 70 is usual)"
            )),
        }
    }
}

/// The length of a blade's edge in the tissue when it first parts it, in millimetres: from
/// 0.001 (the point of a diamond knife) to 50.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct EdgeLength(pub f64);

impl EdgeLength {
    pub fn metres(self) -> f64 {
        self.0 * 1e-3
    }
}

impl TryFrom<f64> for EdgeLength {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if v.is_finite() && (0.001..=50.0).contains(&v) => Ok(Self(v)),
            v => Err(format!(
                "{v} mm is not a blade's edge in the tissue: from 0.001 (a diamond knife's point) \
                 to 50 mm"
            )),
        }
    }
}

/// A number of radial incisions: from 1 to 16 (keratotomies make 4 or 8; more adds little).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(try_from = "u64")]
pub struct IncisionCount(pub usize);

impl TryFrom<u64> for IncisionCount {
    type Error = String;
    fn try_from(value: u64) -> Result<Self, String> {
        match value {
            1..=16 => Ok(Self(value as usize)),
            v => Err(format!(
                "{v} incisions: from 1 to 16 (radial keratotomy makes 4 or 8)"
            )),
        }
    }
}

/// A depth as a share of a tissue's thickness, strictly between 0 and 1 (1 would cut through).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct DepthFraction(pub f64);

impl TryFrom<f64> for DepthFraction {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if v.is_finite() && v > 0.0 && v < 1.0 => Ok(Self(v)),
            v => Err(format!(
                "{v} is not a depth fraction: more than 0 and less than 1 of the thickness \
                 (keratotomies cut 0.8 to 0.9 deep; 1 perforates)"
            )),
        }
    }
}

/// A refractive power in dioptres, more than 0 and at most 20.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct Dioptres(pub f64);

impl TryFrom<f64> for Dioptres {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if v.is_finite() && v > 0.0 && v <= 20.0 => Ok(Self(v)),
            v => Err(format!(
                "{v} D is not a correction: more than 0 and at most 20 dioptres (radial \
                 keratotomy corrects 2 to 8)"
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Newtons;

    #[test]
    fn a_force_is_written_to_the_millinewton_with_two_decimals_at_least() {
        assert_eq!(Newtons(0.06).to_string(), "0.06");
        assert_eq!(Newtons(0.035).to_string(), "0.035");
        assert_eq!(Newtons(0.6).to_string(), "0.60");
        assert_eq!(Newtons(3.3).to_string(), "3.30");
        assert_eq!(Newtons(0.0304).to_string(), "0.03");
    }
}

/// The widest gap between two organs' surfaces that connective tissue ties, in
/// millimetres: from 0.5 to 10.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct TieGap(pub f64);

impl TryFrom<f64> for TieGap {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if v.is_finite() && (0.5..=10.0).contains(&v) => Ok(Self(v)),
            v => Err(format!(
                "{v} mm is not a gap that connective tissue bridges (0.5 to 10 mm; the \
                 gallbladder's bed is 3)"
            )),
        }
    }
}

/// The energy that frees a square metre of attachment, in J/m²: from 1 to 1000.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct FractureEnergy(pub f64);

impl TryFrom<f64> for FractureEnergy {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if v.is_finite() && (1.0..=1000.0).contains(&v) => Ok(Self(v)),
            v => Err(format!(
                "{v} J/m² is not the fracture energy of connective tissue (1 to 1000; the \
                 gallbladder's bed is taken as 50, liver parenchyma is 76 to 225)"
            )),
        }
    }
}

/// The largest traction connective tissue carries, in pascals: from 100 Pa to 100 kPa.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct PeakTraction(pub f64);

impl TryFrom<f64> for PeakTraction {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if v.is_finite() && (100.0..=1e5).contains(&v) => Ok(Self(v)),
            v => Err(format!(
                "{v} Pa is not the peak traction of connective tissue (100 to 100000 Pa; the \
                 gallbladder's bed is taken as 5000)"
            )),
        }
    }
}

/// Connective tissue's traction per metre of opening before damage, in Pa/m: from 1e5 to
/// 1e9.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct TieStiffness(pub f64);

impl TryFrom<f64> for TieStiffness {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if v.is_finite() && (1e5..=1e9).contains(&v) => Ok(Self(v)),
            v => Err(format!(
                "{v} Pa/m is not a stiffness of connective tissue (1e5 to 1e9 Pa/m; the \
                 gallbladder's bed is taken as 5e6, its peak reached at 1 mm)"
            )),
        }
    }
}

/// The hook's power on its generator, in watts: what the generator delivers (1 to 120 W).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct Watts(pub f64);

impl TryFrom<f64> for Watts {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        crate::dissection::Cautery::new(crate::dissection::CauteryMode::Cut, value)
            .map(|hook| Self(hook.power_w))
            .map_err(|refused| refused.to_string())
    }
}

/// The share of an attachment to release, from more than 0 to 1 (all of it).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct ReleaseShare(pub f64);

impl TryFrom<f64> for ReleaseShare {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if v.is_finite() && v > 0.0 && v <= 1.0 => Ok(Self(v)),
            v => Err(format!(
                "{v} is not a share of the attachment: more than 0 and at most 1 (0.9 frees \
                 nine tenths of it)"
            )),
        }
    }
}

/// The length of a clip applier's jaws or of scissors' blades, in millimetres: from 3 to 30
/// (a medium-large ligating clip is about 9 mm long).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct JawLength(pub f64);

impl JawLength {
    pub fn metres(self) -> f64 {
        self.0 * 1e-3
    }
}

impl TryFrom<f64> for JawLength {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if v.is_finite() && (3.0..=30.0).contains(&v) => Ok(Self(v)),
            v => Err(format!(
                "{v} mm is not the length of a laparoscopic instrument's jaws: from 3 to 30 mm \
                 (a medium-large clip is 9 mm, scissors' blades about 15)"
            )),
        }
    }
}

/// A score, 0 to 100.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "f64")]
pub struct Score(pub f64);

impl TryFrom<f64> for Score {
    type Error = String;
    fn try_from(value: f64) -> Result<Self, String> {
        match value {
            v if v.is_finite() && (0.0..=100.0).contains(&v) => Ok(Self(v)),
            v => Err(format!("{v} is not a score: scores run from 0 to 100")),
        }
    }
}

/// A number of attempts, 1 to 100.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(try_from = "usize")]
pub struct AttemptCount(pub usize);

impl TryFrom<usize> for AttemptCount {
    type Error = String;
    fn try_from(value: usize) -> Result<Self, String> {
        match value {
            1..=100 => Ok(Self(value)),
            v => Err(format!(
                "{v} is not a number of attempts to ask for: 1 to 100 (learning curves flatten \
                 after 10 to 15)"
            )),
        }
    }
}
