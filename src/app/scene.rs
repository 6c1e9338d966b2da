//! The default training scene: the four abdominal organs in their anatomical places (the
//! generator builds them in one frame), each with its vademecum from `vademecums/`.

use std::path::Path;
use std::sync::Arc;

use nalgebra::Vector3;

use super::haptic::HapticScene;
use crate::cli::{OnStale, ensure_vademecum};
use crate::contact::Probe;
use crate::fem::Law;
use crate::haptics::{PressTarget, SafetySettings};
use crate::mesh::organs::Organ;
use crate::pgd::Vademecum;

pub const SCENE_ORGANS: [Organ; 4] = [
    Organ::Liver,
    Organ::Gallbladder,
    Organ::Pancreas,
    Organ::Duodenum,
];

/// The default scene, its vademecums loaded (rebuilt first if missing or stale, unless
/// `on_stale` refuses).
pub fn default_scene(dir: &Path, on_stale: OnStale) -> Result<HapticScene, String> {
    let organs = SCENE_ORGANS
        .iter()
        .map(|&organ| {
            let vademecum = ensure_vademecum(dir, organ, Law::Linear, on_stale)?;
            Ok((organ.name().to_owned(), Arc::new(vademecum)))
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok(HapticScene {
        organs,
        probe: Probe::default(),
        safety: SafetySettings::default(),
    })
}

/// Per organ, the accessible point that faces the surgeon most (the largest anterior
/// component of its normal): where the built-in demo presses.
pub fn press_targets(scene: &HapticScene) -> Vec<PressTarget> {
    scene
        .organs
        .iter()
        .filter_map(|(_, vademecum)| most_anterior(vademecum))
        .collect()
}

fn most_anterior(vademecum: &Vademecum) -> Option<PressTarget> {
    let normals = vademecum.rest_normals();
    let best = (0..normals.len()).max_by(|&a, &b| normals[a].y.total_cmp(&normals[b].y))?;
    Some(PressTarget {
        point_m: Vector3::from(vademecum.position_coords_m[best].map(f64::from)),
        normal: normals[best],
    })
}
