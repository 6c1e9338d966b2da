//! An electrosurgical hook's energy and what it burns, by an **energy threshold**: a piece of
//! tissue is burned through once it has taken the energy that heats it from body temperature
//! to 100 °C and boils off its water. At the powers a hook is used at, tissue under it reaches
//! 100 °C within tens of milliseconds, and what the exercise needs (a strand divided, a wall
//! burned how deep, a perforation) is set by that energy. A thermal damage integral
//! (Arrhenius) describes slow coagulation below 100 °C, needs a temperature field, and its
//! rate constants differ by orders of magnitude between tissues; it is not used.
//!
//! The energy goes into a zone under the hook whose width depends on the mode: a narrow one in
//! cut (a continuous waveform that vaporises what it touches), a wider one in coagulation (a
//! modulated waveform whose heat spreads before it boils the tissue), so coagulation divides
//! more slowly at the same power and burns a wider mark. `docs/dissection.md` has the values
//! and their sources.

use std::fmt;
use std::ops::RangeInclusive;

use super::bed::Bed;

/// The generator's output the trainer accepts (W): electrosurgical units deliver up to a few
/// hundred watts; laparoscopic dissection with a hook runs at 20–60 W.
pub const POWER_RANGE_W: RangeInclusive<f64> = 1.0..=120.0;

/// Body temperature and the boiling point of the tissue's water (°C).
const BODY_C: f64 = 37.0;
const BOILING_C: f64 = 100.0;
/// The latent heat of vaporisation of water at 100 °C (J/kg).
const WATER_LATENT_J_PER_KG: f64 = 2.257e6;

/// How the hook's energy is delivered.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize)]
pub enum CauteryMode {
    Cut,
    Coagulate,
}

impl CauteryMode {
    /// The width of the zone the energy goes into (m): 1 mm in cut, 3 mm in coagulation.
    pub fn zone_width_m(self) -> f64 {
        match self {
            Self::Cut => 1e-3,
            Self::Coagulate => 3e-3,
        }
    }

    /// The area of tissue surface under the zone (m²): a disc of its width.
    pub fn zone_area_m2(self) -> f64 {
        std::f64::consts::PI * (0.5 * self.zone_width_m()).powi(2)
    }
}

/// A hook's setting, checked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cautery {
    pub mode: CauteryMode,
    pub power_w: f64,
}

/// A power the generator does not deliver.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PowerOutOfRange {
    pub power_w: f64,
}

impl fmt::Display for PowerOutOfRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} W is not a power the hook delivers ({} to {} W; a hook dissects at 20 to 60 W)",
            self.power_w,
            POWER_RANGE_W.start(),
            POWER_RANGE_W.end()
        )
    }
}

impl std::error::Error for PowerOutOfRange {}

impl Cautery {
    pub fn new(mode: CauteryMode, power_w: f64) -> Result<Self, PowerOutOfRange> {
        match POWER_RANGE_W.contains(&power_w) {
            true => Ok(Self { mode, power_w }),
            false => Err(PowerOutOfRange { power_w }),
        }
    }

    /// The energy delivered over `seconds` with the button held (J).
    pub fn energy_j(&self, seconds: f64) -> f64 {
        self.power_w * seconds
    }
}

/// What heating a tissue to burning takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TissueHeat {
    pub density_kg_per_m3: f64,
    pub specific_heat_j_per_kg_k: f64,
    /// The share of its mass that is water.
    pub water_fraction: f64,
}

impl TissueHeat {
    /// Soft tissue: 1,060 kg/m³, 3,600 J/(kg K), three quarters water (the liver's and the
    /// gallbladder wall's figures lie within a few per cent of these).
    pub const SOFT_TISSUE: Self = Self {
        density_kg_per_m3: 1060.0,
        specific_heat_j_per_kg_k: 3600.0,
        water_fraction: 0.75,
    };

    /// Fat: 911 kg/m³, 2,348 J/(kg K) (the IT'IS Foundation's tissue database), a fifth water
    /// (adipose tissue holds 10 to 30 %).
    pub const FAT: Self = Self {
        density_kg_per_m3: 911.0,
        specific_heat_j_per_kg_k: 2348.0,
        water_fraction: 0.2,
    };

    /// The energy that burns a kilogram through (J/kg): heated to 100 °C, its water boiled.
    pub fn burn_j_per_kg(&self) -> f64 {
        self.specific_heat_j_per_kg_k * (BOILING_C - BODY_C)
            + self.water_fraction * WATER_LATENT_J_PER_KG
    }

    /// The energy that burns a cubic metre through (J/m³).
    pub fn burn_j_per_m3(&self) -> f64 {
        self.density_kg_per_m3 * self.burn_j_per_kg()
    }

    /// How deep (m) `energy_j` burns into a wall under the zone of `mode`.
    pub fn burned_depth_m(&self, energy_j: f64, mode: CauteryMode) -> f64 {
        energy_j / (self.burn_j_per_m3() * mode.zone_area_m2())
    }

    /// The energy (J) that divides a tie of `area_m2` of connective tissue `thickness_m`
    /// thick: a channel the zone's width, across the tie's side, through the layer.
    pub fn tie_burn_j(&self, area_m2: f64, thickness_m: f64, mode: CauteryMode) -> f64 {
        self.burn_j_per_m3() * mode.zone_width_m() * area_m2.sqrt() * thickness_m
    }
}

/// The energy each tie of a bed has taken from the hook, and what divides it.
#[derive(Clone, Debug, PartialEq)]
pub struct TieBurns {
    pub tissue: TissueHeat,
    /// The connective tissue layer's thickness (m).
    pub thickness_m: f64,
    absorbed_j: Vec<f64>,
}

impl TieBurns {
    /// Nothing burned yet, for a bed of `ties` ties.
    pub fn new(ties: usize, tissue: TissueHeat, thickness_m: f64) -> Self {
        Self {
            tissue,
            thickness_m,
            absorbed_j: vec![0.0; ties],
        }
    }

    /// Tie `tie` of `bed` takes `energy_j` in `mode`; once it has taken what divides it, it
    /// fails for good. Returns whether it was divided now.
    /// Every tie as if never heated.
    pub fn cool(&mut self) {
        self.absorbed_j.fill(0.0);
    }

    pub fn heat(&mut self, bed: &mut Bed, tie: usize, energy_j: f64, mode: CauteryMode) -> bool {
        let law = bed.law;
        let target = &mut bed.ties[tie];
        if target.state.failed(&law) {
            return false;
        }
        self.absorbed_j[tie] += energy_j;
        let needed = (self.tissue).tie_burn_j(target.area_m2, self.thickness_m, mode);
        if self.absorbed_j[tie] < needed {
            return false;
        }
        target.state.sever(&law);
        true
    }
}

#[cfg(test)]
mod tests {

    use super::*;
    use crate::dissection::CohesiveLaw;
    use crate::dissection::bed::tie_over_plane;

    /// Two ties of 1 cm² and 0.25 cm².
    fn bed() -> Bed {
        Bed {
            law: CohesiveLaw::gallbladder_bed(),
            ties: vec![tie_over_plane(0, 1e-4), tie_over_plane(0, 0.25e-4)],
        }
    }

    /// Held on a tie at P watts, the hook divides it on the tick its energy passes
    /// `ρ (c ΔT + w L) × zone width × side × thickness`, not before; the tie then fails for
    /// good and takes no more. Coagulation, three times as wide a zone, takes three times as
    /// long; a tie of a quarter the area, half as long.
    #[test]
    fn a_tie_is_divided_when_it_has_taken_the_energy_of_its_channel() {
        let tissue = TissueHeat::SOFT_TISSUE;
        let per_m3 = 1060.0 * (3600.0 * 63.0 + 0.75 * 2.257e6);
        let tick_s = 1e-3;
        for (mode, width_m) in [(CauteryMode::Cut, 1e-3), (CauteryMode::Coagulate, 3e-3)] {
            for (tie, side_m) in [(0, 1e-2), (1, 0.5e-2)] {
                let hook = Cautery::new(mode, 30.0).unwrap();
                let mut bed = bed();
                let mut burns = TieBurns::new(bed.ties.len(), tissue, 2e-3);
                let expected_s = per_m3 * width_m * side_m * 2e-3 / 30.0;
                let mut divided_at = None;
                for tick in 1..=20_000 {
                    if burns.heat(&mut bed, tie, hook.energy_j(tick_s), mode) {
                        divided_at = Some(tick as f64 * tick_s);
                        break;
                    }
                }
                let divided_at = divided_at.expect("divided");
                assert!(
                    (divided_at - expected_s).abs() <= tick_s,
                    "{mode:?} tie {tie}: {divided_at} s against {expected_s} s"
                );
                assert!(bed.ties[tie].state.failed(&bed.law));
                assert!(!burns.heat(&mut bed, tie, 1e3, mode));
                assert!(!bed.ties[1 - tie].state.failed(&bed.law));
            }
        }
    }

    /// A wall under the hook burns as deep as the energy boils the zone's column (depth ×
    /// zone area × ρ (c ΔT + w L) = energy): linear in the energy, and a ninth as deep under
    /// coagulation's zone of nine times the area.
    #[test]
    fn a_wall_burns_as_deep_as_the_energy_boils_under_the_zone() {
        let tissue = TissueHeat::SOFT_TISSUE;
        let per_m3 = 1060.0 * (3600.0 * 63.0 + 0.75 * 2.257e6);
        let hook = Cautery::new(CauteryMode::Cut, 40.0).unwrap();
        let energy = hook.energy_j(0.5);
        let depth = tissue.burned_depth_m(energy, CauteryMode::Cut);
        let area = std::f64::consts::PI * 0.5e-3 * 0.5e-3;
        assert!((depth * area * per_m3 - energy).abs() <= 1e-12 * energy);
        let coag = tissue.burned_depth_m(energy, CauteryMode::Coagulate);
        assert!((depth / coag - 9.0).abs() < 1e-12);
        assert!(
            (tissue.burned_depth_m(2.0 * energy, CauteryMode::Cut) - 2.0 * depth).abs() < 1e-15
        );
    }

    #[test]
    fn a_power_the_generator_does_not_deliver_is_refused() {
        for power_w in [0.0, 0.5, 150.0, f64::NAN, -30.0] {
            let refused = Cautery::new(CauteryMode::Cut, power_w).unwrap_err();
            assert!(refused.to_string().contains("1 to 120 W"), "{refused}");
        }
        assert!(Cautery::new(CauteryMode::Coagulate, 30.0).is_ok());
    }
}
