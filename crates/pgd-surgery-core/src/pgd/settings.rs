//! What a vademecum is built with: the tool's patch, the near field's radius, the error
//! target, the PGD and the KSV load steps. Written into the vademecum's header, so that a
//! file built with other settings is refused.

use serde::{Deserialize, Serialize};

use super::enrichment::PgdSettings;
use super::organ::press_scale;
use super::responses::SecantSettings;
use crate::fem::Law;
use crate::mesh::organs::Organ;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BuildSettings {
    /// Radius (m) of the tool tip's contact patch: every load is spread over it.
    pub tool_tip_radius_m: f64,
    /// Nodes within this distance (m) of a load get its exact response (the local correction).
    pub local_radius_m: f64,
    /// Target of the estimator: each node-centred load's relative L2 error of the vademecum's
    /// field, root mean square over the loads; enrichment stops there or at the cap. The
    /// default, 10 %, is the bound the targets set on the field the trainee watches; the
    /// near field makes it exact around the tool, so this bounds the rest of the organ.
    pub target_error: f64,
    pub pgd: PgdSettings,
    /// Nonlinear laws only: the linear depth (m) of the tool's patch at each load step after
    /// the linear one, increasing. The deepest is the vademecum's valid range.
    pub load_steps_m: Vec<f64>,
    pub secant: SecantSettings,
}

impl Default for BuildSettings {
    /// The abdominal organs' settings.
    fn default() -> Self {
        Self::for_organ(None)
    }
}

impl BuildSettings {
    /// The default settings for `organ` (or a mesh file): its tool and near-field radii.
    pub fn for_organ(organ: Option<Organ>) -> Self {
        let radii = super::organ::tool_radii_m(organ);
        Self {
            tool_tip_radius_m: radii.tool_tip_m,
            local_radius_m: radii.near_field_m(),
            target_error: 0.1,
            pgd: PgdSettings::default(),
            load_steps_m: DEFAULT_LOAD_STEPS_M.to_vec(),
            secant: SecantSettings::default(),
        }
    }

    /// The default settings for `organ` under `law`: [`Self::for_organ`] with the law's
    /// load steps ([`default_load_steps_m`]).
    pub fn for_organ_law(organ: Option<Organ>, law: Law) -> Self {
        let settings = Self::for_organ(organ);
        Self {
            load_steps_m: default_load_steps_m(organ, settings.tool_tip_radius_m, law),
            ..settings
        }
    }

    /// The settings a user chooses for a vademecum under `law`, in a line (for messages).
    pub fn summary(&self, law: Law) -> String {
        let common = format!(
            "tool tip {:.1} mm, local radius {:.1} mm, target error {}, at most {} modes",
            self.tool_tip_radius_m * 1e3,
            self.local_radius_m * 1e3,
            self.target_error,
            self.pgd.max_modes,
        );
        if law == Law::Linear {
            return common;
        }
        let secant = &self.secant;
        format!(
            "{common}, load steps {:?} mm, fixed point: mixing {}, Anderson depth {}, Newton while it costs at most {} times the fixed point",
            self.load_steps_m
                .iter()
                .map(|m| m * 1e3)
                .collect::<Vec<_>>(),
            secant.mixing,
            secant.anderson_depth,
            secant.newton_budget
        )
    }
}

/// KSV load steps: three, as in paper 000, up to the deepest indentation over which the KSV
/// law stays stable under a 6 mm tool on the organs here: beyond about 1.5 mm the elements
/// under the tool lose stability in compression (measured in docs/pgd.md).
pub const DEFAULT_LOAD_STEPS_M: [f64; 3] = [0.5e-3, 1.0e-3, 1.5e-3];

/// Neo-Hookean load steps on the liver, in tool radii: 2.5 to 25 mm under the abdominal organs'
/// 6 mm tool, the depths a trainee presses; the same proportions under the cornea's.
pub const NEO_HOOKEAN_STEPS_TOOL_RADII: [f64; 6] = [
    2.5 / 6.0,
    5.0 / 6.0,
    10.0 / 6.0,
    15.0 / 6.0,
    20.0 / 6.0,
    25.0 / 6.0,
];

/// Exponential load steps on the liver, in tool radii: 2.5 to 60 mm of linear depth under the
/// 6 mm tool. The law stiffens, so a step presses less deep than its level: on the coarse liver
/// the neo-Hookean steps' 25 mm answered 15.6 mm of tool depth, these steps' 60 mm about 25 mm.
pub const EXPONENTIAL_STEPS_TOOL_RADII: [f64; 6] = [
    2.5 / 6.0,
    5.0 / 6.0,
    10.0 / 6.0,
    20.0 / 6.0,
    35.0 / 6.0,
    60.0 / 6.0,
];

/// The load steps `law` is built with by default for `organ` under a tool of
/// `tool_tip_radius_m`: the neo-Hookean family's reach the depths a trainee presses (the
/// exponential law's deeper levels for the same depths), the same share of each organ's
/// thickness ([`press_scale`]); KSV's stop where it loses stability (the linear law has none;
/// it keeps KSV's in its header).
pub fn default_load_steps_m(organ: Option<Organ>, tool_tip_radius_m: f64, law: Law) -> Vec<f64> {
    let scale = press_scale(organ);
    let radii = match law {
        Law::Exponential => &EXPONENTIAL_STEPS_TOOL_RADII,
        _ => &NEO_HOOKEAN_STEPS_TOOL_RADII,
    };
    match law.is_hyperelastic() {
        true => radii
            .iter()
            .map(|r| r * tool_tip_radius_m * scale)
            .collect(),
        false => DEFAULT_LOAD_STEPS_M.to_vec(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn steps(organ: Organ, law: Law) -> Vec<f64> {
        BuildSettings::for_organ_law(Some(organ), law).load_steps_m
    }

    /// The liver is pressed to 25 mm of linear depth under the neo-Hookean law, to 60 mm under
    /// the exponential law, which presses less deep than its levels; the other abdominal
    /// organs to the same share of their thickness, step for step (the scales themselves are
    /// checked against the generated meshes in `tests/geometry`).
    #[test]
    fn the_organs_steps_are_the_livers_in_proportion_to_their_thickness() {
        for (law, deepest_m) in [(Law::NeoHookean, 0.025), (Law::Exponential, 0.060)] {
            let liver = steps(Organ::Liver, law);
            assert!(
                (liver.last().unwrap() - deepest_m).abs() < 1e-12,
                "{liver:?}"
            );
            for organ in [Organ::Gallbladder, Organ::Pancreas, Organ::Duodenum] {
                let scale = press_scale(Some(organ));
                assert!(scale < 1.0, "{}: {scale}", organ.name());
                let scaled: Vec<f64> = liver.iter().map(|l| l * scale).collect();
                let own = steps(organ, law);
                assert_eq!(own.len(), scaled.len());
                for (a, b) in own.iter().zip(&scaled) {
                    assert!((a - b).abs() < 1e-12, "{}: {own:?}", organ.name());
                }
            }
        }
    }
}
