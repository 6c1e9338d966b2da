//! What an open tube lets out: blood from a divided artery, bile from a divided duct, at a
//! flow set by the lumen's radius (Poiseuille's law over the tube from its source to the
//! cut), until it is clipped or coagulated.

use serde::Serialize;

use super::anatomy::Structure;

/// Which stump: the one towards the tube's patient end (its node 0) or the other.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Side {
    Patient,
    Gallbladder,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Fluid {
    Blood,
    Bile,
}

/// The pressure driving a fluid through a tube and its viscosity.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FlowLaw {
    pub pressure_pa: f64,
    pub viscosity_pa_s: f64,
}

/// Poiseuille's law holds over a tube many times longer than wide: a cut nearer its source
/// than this is taken at this length (m).
pub const SHORTEST_TUBE_M: f64 = 5e-3;

impl FlowLaw {
    /// Mean arterial pressure (90 mmHg) and whole blood's viscosity (3.5 mPa·s).
    pub const ARTERIAL: Self = Self {
        pressure_pa: 12_000.0,
        viscosity_pa_s: 3.5e-3,
    };
    /// Blood back from the gallbladder's wall: capillary pressure (15 mmHg).
    pub const BACK_BLEEDING: Self = Self {
        pressure_pa: 2_000.0,
        viscosity_pa_s: 3.5e-3,
    };
    /// Bile in the ducts (12 cm of water) at about water's viscosity.
    pub const BILE: Self = Self {
        pressure_pa: 1_200.0,
        viscosity_pa_s: 1.0e-3,
    };

    /// The flow through a lumen of radius `lumen_m` over `length_m` of tube (m³/s):
    /// `π r⁴ Δp / 8 μ L`.
    pub fn flow_m3_per_s(&self, lumen_m: f64, length_m: f64) -> f64 {
        std::f64::consts::PI * lumen_m.powi(4) * self.pressure_pa
            / (8.0 * self.viscosity_pa_s * length_m.max(SHORTEST_TUBE_M))
    }
}

/// An open stump.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Leak {
    pub fluid: Fluid,
    pub structure: Structure,
    pub side: Side,
    /// Where the tube was cut, along it from its patient end (m).
    pub arc_length_m: f64,
    pub flow_m3_per_s: f64,
    /// What it has let out so far (m³).
    pub lost_m3: f64,
    pub stopped: bool,
}

impl Leak {
    pub fn new(
        fluid: Fluid,
        structure: Structure,
        side: Side,
        arc_length_m: f64,
        flow_m3_per_s: f64,
    ) -> Self {
        Self {
            fluid,
            structure,
            side,
            arc_length_m,
            flow_m3_per_s,
            lost_m3: 0.0,
            stopped: false,
        }
    }

    /// Lets it flow for `dt_s` unless it has been stopped.
    pub fn advance(&mut self, dt_s: f64) {
        if !self.stopped {
            self.lost_m3 += self.flow_m3_per_s * dt_s;
        }
    }

    /// Clipped above the cut or coagulated: it lets nothing more out.
    pub fn stop(&mut self) {
        self.stopped = true;
    }

    pub fn lost_ml(&self) -> f64 {
        self.lost_m3 * 1e6
    }

    /// Whether a clip closing the lumen at `arc_length_m` of `structure` lies on this stump.
    pub fn stump_holds(&self, structure: Structure, arc_length_m: f64) -> bool {
        structure == self.structure
            && match self.side {
                Side::Patient => arc_length_m < self.arc_length_m,
                Side::Gallbladder => arc_length_m > self.arc_length_m,
            }
    }
}
