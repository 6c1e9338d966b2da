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

/// The pressure driving a fluid through a tube and its viscosity, what feeds it at most
/// (m³/s), and how much there is to let out (m³).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FlowLaw {
    pub pressure_pa: f64,
    pub viscosity_pa_s: f64,
    pub supply_m3_per_s: f64,
    pub reservoir_m3: f64,
}

/// Poiseuille's law holds over a tube many times longer than wide: a cut nearer its source
/// than this is taken at this length (m).
pub const SHORTEST_TUBE_M: f64 = 5e-3;

impl FlowLaw {
    /// Mean arterial pressure (90 mmHg) and whole blood's viscosity (3.5 mPa·s), fed by the
    /// hepatic artery without a limit the trainer sets.
    pub const ARTERIAL: Self = Self {
        pressure_pa: 12_000.0,
        viscosity_pa_s: 3.5e-3,
        supply_m3_per_s: f64::INFINITY,
        reservoir_m3: f64::INFINITY,
    };
    /// Blood back from the gallbladder's wall: capillary pressure (15 mmHg).
    pub const BACK_BLEEDING: Self = Self {
        pressure_pa: 2_000.0,
        viscosity_pa_s: 3.5e-3,
        supply_m3_per_s: f64::INFINITY,
        reservoir_m3: f64::INFINITY,
    };
    /// Bile from the liver's side: at most what the liver secretes (600 mL a day).
    pub const HEPATIC_BILE: Self = Self {
        pressure_pa: 1_200.0,
        viscosity_pa_s: 1.0e-3,
        supply_m3_per_s: 600e-6 / 86_400.0,
        reservoir_m3: f64::INFINITY,
    };
    /// Bile from the gallbladder's side: its content (40 mL) runs out at the ducts' pressure
    /// (12 cm of water), at about water's viscosity.
    pub const GALLBLADDER_BILE: Self = Self {
        pressure_pa: 1_200.0,
        viscosity_pa_s: 1.0e-3,
        supply_m3_per_s: f64::INFINITY,
        reservoir_m3: 40e-6,
    };

    /// The flow through a lumen of radius `lumen_m` over `length_m` of tube (m³/s):
    /// `π r⁴ Δp / 8 μ L`, or the supply where that is less.
    pub fn flow_m3_per_s(&self, lumen_m: f64, length_m: f64) -> f64 {
        let poiseuille = std::f64::consts::PI * lumen_m.powi(4) * self.pressure_pa
            / (8.0 * self.viscosity_pa_s * length_m.max(SHORTEST_TUBE_M));
        poiseuille.min(self.supply_m3_per_s)
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
    /// What there is to let out (m³; infinite for a stump its source keeps feeding).
    pub reservoir_m3: f64,
    /// What it has let out so far (m³).
    pub lost_m3: f64,
    pub stopped: bool,
}

impl Leak {
    /// The stump of `structure` cut at `arc_length_m`, on `side`, letting out `fluid` by
    /// `law` through a lumen of `lumen_m` and `from_source_m` of tube.
    pub fn new(
        (structure, side, arc_length_m): (Structure, Side, f64),
        fluid: Fluid,
        law: &FlowLaw,
        lumen_m: f64,
        from_source_m: f64,
    ) -> Self {
        Self {
            fluid,
            structure,
            side,
            arc_length_m,
            flow_m3_per_s: law.flow_m3_per_s(lumen_m, from_source_m),
            reservoir_m3: law.reservoir_m3,
            lost_m3: 0.0,
            stopped: false,
        }
    }

    /// Lets it flow for `dt_s` unless it has been stopped or has nothing left.
    pub fn advance(&mut self, dt_s: f64) {
        if !self.stopped {
            self.lost_m3 = (self.lost_m3 + self.flow_m3_per_s * dt_s).min(self.reservoir_m3);
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
