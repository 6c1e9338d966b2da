//! What a scenario puts in the scene, as its file writes it: the organs (by name, or in full
//! with a mesh, a tissue or a vademecum of their own), the nodules hidden in them, and the
//! spots a task names, in millimetres.

use std::path::PathBuf;

use serde::de::{self, MapAccess, Visitor};
use serde::{Deserialize, Deserializer};

use crate::fem::Law;
use crate::mesh::io::{ImportOptions, MeshFile};
use crate::mesh::organs::{Organ, OrganSettings};
use crate::mesh::{RegionSelectors, Selector, TetMesh};

use super::units::{Millimetres, ModeCount, Pascals, PoissonRatio, Ratio, Stiffening, Toughness};

/// A point in the scene's frame (millimetres; x to the patient's left, y anterior, z to the
/// head), with a radius around it.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spot {
    /// What the trainee is told it is.
    #[serde(default)]
    pub name: String,
    pub at_mm: (f64, f64, f64),
    pub radius_mm: Millimetres,
}

/// A point written in millimetres, in metres.
pub fn metres(at_mm: (f64, f64, f64)) -> nalgebra::Vector3<f64> {
    nalgebra::Vector3::new(at_mm.0, at_mm.1, at_mm.2) * 1e-3
}

impl Spot {
    pub fn centre_m(&self) -> nalgebra::Vector3<f64> {
        metres(self.at_mm)
    }

    /// Whether the tool tip at `tip_m` is within the spot.
    pub fn contains(&self, tip_m: &nalgebra::Vector3<f64>) -> bool {
        (tip_m - self.centre_m()).norm() <= self.radius_mm.metres()
    }
}

/// An organ of the scene, written `Organ(name: …, …)`, or its name alone for a generated organ
/// with its own tissue. Its vademecum is built for what is given here (the first run of the
/// scenario builds it).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(rename = "Organ", deny_unknown_fields)]
pub struct OrganEntry {
    /// What tasks and nodules call it; a generated organ's name unless `mesh` is given.
    pub name: String,
    /// A mesh file (.msh, .vtk, .vtu, in metres, or a closed .obj/.stl surface), written
    /// relative to the scenario's folder (read as such: the path here is resolved). Its
    /// clamped nodes and accessible surface are its own regions `clamped` and `accessible`,
    /// or those `clamp` and `accessible` pick.
    #[serde(default)]
    pub mesh: Option<PathBuf>,
    /// A mesh file's nodes held fixed, picked by where they are (`Box`, `Sphere`, `Plane`,
    /// `Facing`, `Region`, `Not`; millimetres).
    #[serde(default)]
    pub clamp: Vec<Selector>,
    /// A mesh file's surface the tool may touch, picked as `clamp` is; without it, the
    /// surface that no clamped node touches.
    #[serde(default)]
    pub accessible: Vec<Selector>,
    /// Its tissue's Young's modulus, when not the organ's own (for a mesh file: the liver's).
    #[serde(default)]
    pub young_pa: Option<Pascals>,
    /// Its tissue's Poisson's ratio, when not the organs' 0.48.
    #[serde(default)]
    pub poisson_ratio: Option<PoissonRatio>,
    /// At most this many separated modes in its vademecum, when not the builder's default.
    #[serde(default)]
    pub max_modes: Option<ModeCount>,
    /// Its tissue's law (`Linear`, `NeoHookean`, `Exponential`, `KirchhoffSaintVenant`), when
    /// not the default ([`default_law`]: exponential where pressed, linear where cut or moved).
    #[serde(default)]
    pub law: Option<Law>,
    /// The exponential law's stiffening b, when not its default (`law: Exponential` only).
    #[serde(default)]
    pub stiffening: Option<Stiffening>,
    /// Whether it moves (reduced dynamics, and the grasper can pull it) or stays
    /// quasi-static; by default it moves when the tool is a grasper.
    #[serde(default)]
    pub dynamic: Option<bool>,
    /// Its tissue's fracture toughness under a blade, when not the organ's own (the liver's
    /// and the cornea's are known; another organ is cut by a scalpel only when given one).
    #[serde(default)]
    pub toughness_j_per_m2: Option<Toughness>,
}

impl OrganEntry {
    /// Its tissue's toughness under a blade (J/m²): the scenario's, or the organ's own where
    /// it is known (a generated liver or cornea).
    pub fn toughness_j_per_m2(&self) -> Option<f64> {
        let own = match (Organ::from_name(&self.name), &self.mesh) {
            (Some(Organ::Liver), None) => Some(crate::cutting::LIVER_TOUGHNESS_J_PER_M2),
            (Some(Organ::Cornea), None) => Some(crate::cutting::CORNEA_TOUGHNESS_J_PER_M2),
            _ => None,
        };
        self.toughness_j_per_m2.map(|t| t.0).or(own)
    }

    /// Its mesh as a check of the file reads it quickly: a mesh file's own, a generated
    /// organ's at a quarter of its resolution; `None` when it cannot be had (its own check
    /// says why).
    pub fn outline_mesh(&self) -> Option<TetMesh> {
        match (self.mesh_file(), Organ::from_name(&self.name)) {
            (Some(file), _) => crate::mesh::io::load(&file.path, &self.import()).ok(),
            (None, Some(organ)) => {
                let coarse = OrganSettings {
                    resolution: 0.25,
                    ..OrganSettings::default()
                };
                crate::mesh::organs::generate(organ, &coarse).ok()
            }
            (None, None) => None,
        }
    }

    /// Its mesh file and how its regions are found, if it is read from one.
    pub fn mesh_file(&self) -> Option<MeshFile> {
        self.mesh.as_ref().map(|path| MeshFile {
            path: path.clone(),
            regions: self.regions(),
        })
    }

    /// The selectors of its regions.
    fn regions(&self) -> RegionSelectors {
        RegionSelectors {
            clamp: self.clamp.clone(),
            accessible: self.accessible.clone(),
        }
    }

    /// How its mesh file is read.
    pub fn import(&self) -> ImportOptions {
        ImportOptions {
            regions: self.regions(),
            ..ImportOptions::default()
        }
    }

    /// A generated organ with its own tissue and default vademecum.
    pub fn named(name: &str) -> Self {
        Self {
            name: name.to_owned(),
            mesh: None,
            clamp: Vec::new(),
            accessible: Vec::new(),
            young_pa: None,
            poisson_ratio: None,
            max_modes: None,
            law: None,
            stiffening: None,
            dynamic: None,
            toughness_j_per_m2: None,
        }
    }
}

/// The `organs` list: each entry a name or an `Organ(…)`.
pub(super) fn organ_list<'de, D: Deserializer<'de>>(
    deserializer: D,
) -> Result<Vec<OrganEntry>, D::Error> {
    Vec::<OrganItem>::deserialize(deserializer)
        .map(|items| items.into_iter().map(|i| i.0).collect())
}

/// One entry of `organs`, as a name or in full.
struct OrganItem(OrganEntry);

impl<'de> Deserialize<'de> for OrganItem {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(OrganVisitor).map(OrganItem)
    }
}

struct OrganVisitor;

impl<'de> Visitor<'de> for OrganVisitor {
    type Value = OrganEntry;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("an organ's name such as \"liver\", or Organ(name: …, mesh: …)")
    }

    fn visit_str<E: de::Error>(self, name: &str) -> Result<OrganEntry, E> {
        Ok(OrganEntry::named(name))
    }

    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<OrganEntry, A::Error> {
        OrganEntry::deserialize(de::value::MapAccessDeserializer::new(map))
    }
}

/// A sphere of stiffer tissue inside an organ.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Nodule {
    pub organ: String,
    /// Its centre, in the scene's frame (mm).
    pub at_mm: (f64, f64, f64),
    pub radius_mm: Millimetres,
    /// Its Young's modulus over the organ's (tumours are several times stiffer).
    pub stiffness_ratio: Ratio,
}

impl Nodule {
    pub fn centre_m(&self) -> nalgebra::Vector3<f64> {
        metres(self.at_mm)
    }

    /// The nodule as the finite-element model takes it.
    pub fn inclusion(&self) -> crate::fem::Inclusion {
        crate::fem::Inclusion {
            centre_m: self.centre_m().into(),
            radius_m: self.radius_mm.metres(),
            stiffness_ratio: self.stiffness_ratio.0,
        }
    }
}
