//! The vademecum file: `vademecums/<organ>.vdm`, in the [`container`](super::container)
//! layout with the magic `PGDVADEM`. Its header is JSON (self-describing: mesh hash,
//! material, regions, load directions and steps, build settings); its payload the arrays,
//! modes as f32.

use std::path::Path;

use super::container::{self, Kind, Reader, put};
use super::error::VademecumError;
use super::local::LocalPart;
use super::region::{RegionArrays, RegionResponse};
use super::responses::SecantSettings;
use super::settings::BuildSettings;
use super::vademecum::{Header, MAX_STEPS, Step, StepLoads, Vademecum};
use crate::fem::{Inclusion, Law, Material};
use crate::mesh::TetMesh;

/// Bumped on any change of layout or meaning; older files are refused, not misread.
pub const FORMAT_VERSION: u32 = 6;
const KIND: Kind = Kind {
    magic: b"PGDVADEM",
    version: FORMAT_VERSION,
    name: "vademecum",
};

/// Writes `vademecum` to `path` atomically.
pub fn save(path: &Path, vademecum: &Vademecum) -> Result<(), VademecumError> {
    check_round_trip(&vademecum.header).map_err(|why| VademecumError::Unwritable {
        file: path.to_path_buf(),
        why,
    })?;
    container::write_atomically(path, &encode(vademecum))
}

/// The bytes of the file `save` writes.
/// A header with a non-finite number would be written as JSON `null` and never load again: the
/// header must read back equal to itself before anything is written.
fn check_round_trip(header: &Header) -> Result<(), String> {
    let json = serde_json::to_vec(header).map_err(|e| e.to_string())?;
    let back: Header = serde_json::from_slice(&json).map_err(|e| e.to_string())?;
    if &back == header {
        Ok(())
    } else {
        Err("a number in it is not finite".into())
    }
}

pub fn encode(vademecum: &Vademecum) -> Vec<u8> {
    let header = serde_json::to_vec_pretty(&vademecum.header).expect("plain data serializes");
    container::encode(&KIND, &header, &payload(vademecum))
}

/// Reads only the header of `path` (cheap: for staleness checks and listings).
pub fn read_header(path: &Path) -> Result<Header, VademecumError> {
    let bytes = container::read(path)?;
    let (header, _) = checked_parts(path, &bytes)?;
    Ok(header)
}

/// Reads and checks a vademecum file.
pub fn load(path: &Path) -> Result<Vademecum, VademecumError> {
    decode(path, &container::read(path)?)
}

/// Checks and reads the bytes of a vademecum file; `path` names it in errors.
pub fn decode(path: &Path, bytes: &[u8]) -> Result<Vademecum, VademecumError> {
    let (header, payload) = checked_parts(path, bytes)?;
    let vademecum = read_payload(&mut Reader::new(path, payload), header)?;
    validate(path, &vademecum)?;
    Ok(vademecum)
}

impl Vademecum {
    /// Refuses a vademecum built for another mesh (or other regions) than `mesh`.
    pub fn check_mesh(&self, file: &Path, mesh: &TetMesh) -> Result<(), VademecumError> {
        let expected = super::mesh_hash(mesh);
        if expected != self.header.mesh_hash {
            return Err(VademecumError::OtherMesh {
                file: file.to_path_buf(),
                expected,
                found: self.header.mesh_hash.clone(),
            });
        }
        Ok(())
    }

    /// Refuses a vademecum built for another material law or constants than `material`, or
    /// with other inclusions in the tissue.
    pub fn check_material(
        &self,
        file: &Path,
        material: &Material,
        inclusions: &[Inclusion],
    ) -> Result<(), VademecumError> {
        let header = &self.header;
        if header.material != *material || header.inclusions != inclusions {
            return Err(VademecumError::OtherMaterial {
                file: file.to_path_buf(),
                expected: tissue(material, inclusions),
                found: tissue(&header.material, &header.inclusions),
            });
        }
        Ok(())
    }

    /// Refuses a vademecum built with other settings than `settings` (a tool tip of another
    /// radius would feel another stiffness). A linear vademecum has no load steps, so the
    /// load steps and their fixed point's settings do not count for it.
    pub fn check_settings(
        &self,
        file: &Path,
        settings: &BuildSettings,
    ) -> Result<(), VademecumError> {
        let law = self.header.material.law;
        // The steps are compared apart, to 1e-9 relative: a command line gives them in decimal.
        let relevant = |s: &BuildSettings| BuildSettings {
            load_steps_m: Vec::new(),
            secant: match law {
                Law::Linear => SecantSettings::default(),
                _ => s.secant,
            },
            ..s.clone()
        };
        let (built, asked) = (&self.header.settings.load_steps_m, &settings.load_steps_m);
        let same_steps = law == Law::Linear
            || (built.len() == asked.len()
                && built
                    .iter()
                    .zip(asked)
                    .all(|(b, a)| (b - a).abs() <= 1e-9 * a.abs()));
        if !same_steps || relevant(&self.header.settings) != relevant(settings) {
            return Err(VademecumError::OtherSettings {
                file: file.to_path_buf(),
                expected: settings.summary(law),
                found: self.header.settings.summary(law),
            });
        }
        Ok(())
    }
}

/// Checks the container; returns the header and the payload bytes.
fn checked_parts<'a>(path: &Path, bytes: &'a [u8]) -> Result<(Header, &'a [u8]), VademecumError> {
    let (header, payload) = container::checked_parts(&KIND, path, bytes)?;
    let header = serde_json::from_slice(header).map_err(|e| VademecumError::Malformed {
        file: path.to_path_buf(),
        what: format!("header: {e}"),
    })?;
    Ok((header, payload))
}

fn payload(v: &Vademecum) -> Vec<u8> {
    let mut out = Vec::new();
    put(&mut out, &v.positions);
    put(&mut out, v.position_coords_m.as_flattened());
    put(&mut out, &v.position_areas_m2);
    put(&mut out, v.position_normals.as_flattened());
    put(&mut out, v.triangles.as_flattened());
    put(&mut out, &v.reference_compliance_m_per_n);
    put(&mut out, &v.range_level_m);
    put(&mut out, &[v.steps.len() as u32]);
    for step in &v.steps {
        put(&mut out, &step.spatial);
        put(&mut out, &step.parametric);
        let l = &step.local;
        put(&mut out, &l.neighbour_offsets);
        put(&mut out, &l.neighbours);
        put(&mut out, &l.compliance);
        put(&mut out, &l.correction_offsets);
        put(&mut out, &l.correction_nodes);
        put(&mut out, &l.correction);
    }
    if let Some(cuts) = &v.cuts {
        put(&mut out, &cuts.positions);
        put(&mut out, &cuts.held);
        put(&mut out, &cuts.spatial);
        put(&mut out, &cuts.parametric);
        put(&mut out, &cuts.near_offsets);
        put(&mut out, &cuts.near_nodes);
        put(&mut out, &cuts.near);
    }
    out
}

/// The cut section, present when the header announces it.
fn read_cuts(r: &mut Reader, header: &Header) -> Result<Option<RegionResponse>, VademecumError> {
    if header.cuts.is_none() {
        return Ok(None);
    }
    let arrays = RegionArrays {
        positions: r.take("cut positions")?,
        held: r.take("held nodes")?,
        spatial: r.take("cut spatial modes")?,
        parametric: r.take("cut parametric modes")?,
        near_offsets: r.take("cut near-field offsets")?,
        near_nodes: r.take("cut near-field nodes")?,
        near: r.take("cut near fields")?,
    };
    check_cuts(r, header, &arrays)?;
    let patch_radius_m = header.cuts.as_ref().and_then(|c| c.settings.patch_radius_m);
    Ok(Some(
        RegionResponse::new(arrays, header.node_count).with_patch_radius(patch_radius_m),
    ))
}

/// The product of a header's sizes, `None` where it overflows: whatever a file claims, the
/// check against the arrays it holds (which its length bounds) cannot panic or wrap.
fn product(factors: &[usize]) -> Option<usize> {
    factors.iter().try_fold(1usize, |p, &f| p.checked_mul(f))
}

/// The cut arrays agree with the header and with each other.
fn check_cuts(r: &Reader, header: &Header, arrays: &RegionArrays) -> Result<(), VademecumError> {
    let RegionArrays {
        positions,
        held,
        spatial,
        parametric,
        near_offsets: offsets,
        near_nodes: nodes,
        near,
    } = arrays;
    let node_count = header.node_count;
    let beyond = |list: &[u32]| list.iter().any(|&n| n as usize >= node_count);
    if beyond(positions) || beyond(held) || beyond(nodes) {
        return Err(r.malformed("cut section (a node beyond the header's node count)"));
    }
    let m = positions.len();
    let modes = header.cuts.as_ref().map_or(0, |c| c.report.modes);
    if product(&[modes, 3, node_count]) != Some(spatial.len())
        || product(&[modes, 3, m]) != Some(parametric.len())
    {
        return Err(r.malformed("cut modes (sizes differ from the header)"));
    }
    let rows_ok = offsets.len() == m + 1
        && offsets.first() == Some(&0)
        && offsets.windows(2).all(|w| w[0] <= w[1])
        && offsets[m] as usize == nodes.len()
        && near.len() == 9 * nodes.len();
    if !rows_ok {
        return Err(r.malformed("cut near fields (rows differ from the positions)"));
    }
    Ok(())
}

fn read_payload(r: &mut Reader, header: Header) -> Result<Vademecum, VademecumError> {
    let positions = r.take("positions")?;
    let coords: Vec<f32> = r.take("position coordinates")?;
    let position_coords_m = coords.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let position_areas_m2 = r.take("position areas")?;
    let normals: Vec<f32> = r.take("position normals")?;
    let position_normals = normals
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    let flat: Vec<u32> = r.take("triangles")?;
    if !flat.len().is_multiple_of(3) {
        return Err(r.malformed("triangles"));
    }
    let triangles = flat.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    let reference_compliance_m_per_n = r.take("reference compliances")?;
    let range_level_m = r.take("range levels")?;
    let count: Vec<u32> = r.take("step count")?;
    let count = *count.first().ok_or_else(|| r.malformed("step count"))?;
    let mut steps = Vec::new();
    for _ in 0..count {
        steps.push(Step {
            spatial: r.take("spatial modes")?,
            parametric: r.take("parametric modes")?,
            local: LocalPart {
                neighbour_offsets: r.take("neighbour offsets")?,
                neighbours: r.take("neighbours")?,
                compliance: r.take("compliances")?,
                correction_offsets: r.take("correction offsets")?,
                correction_nodes: r.take("correction nodes")?,
                correction: r.take("corrections")?,
            },
        });
    }
    let cuts = read_cuts(r, &header)?;
    r.finish()?;
    Ok(Vademecum {
        header,
        positions,
        position_coords_m,
        position_areas_m2,
        position_normals,
        triangles,
        reference_compliance_m_per_n,
        range_level_m,
        steps,
        cuts,
    })
}

/// Checks that every array agrees with the header and with the others, so evaluation can
/// index without bounds surprises.
fn validate(path: &Path, v: &Vademecum) -> Result<(), VademecumError> {
    let fail = |what: &str| {
        Err(VademecumError::Malformed {
            file: path.to_path_buf(),
            what: what.to_string(),
        })
    };
    let (m, nodes) = (v.positions.len(), v.header.node_count as u32);
    if v.positions.iter().any(|&n| n >= nodes) {
        return fail("positions (a node beyond the header's node count)");
    }
    if v.triangles.iter().flatten().any(|&i| i as usize >= m) {
        return fail("triangles (an index beyond the positions)");
    }
    if v.position_coords_m.len() != m
        || v.position_areas_m2.len() != m
        || v.position_normals.len() != m
    {
        return fail("position coordinates, areas or normals (one per position expected)");
    }
    if v.reference_compliance_m_per_n.len() != m || v.range_level_m.len() != m {
        return fail("reference compliances or range levels (one per position expected)");
    }
    if !v.range_level_m.iter().all(|r| r.is_finite() && *r >= 0.0) {
        return fail("range levels (each a finite, non-negative depth expected)");
    }
    if v.steps.len() != v.header.indentation_levels_m.len() || v.steps.is_empty() {
        return fail("steps (their count differs from the header's load steps)");
    }
    if v.steps.len() > 1 && v.header.step_loads != StepLoads::InwardToolPatch {
        return Err(VademecumError::OlderLoadSteps {
            file: path.to_path_buf(),
            found: v.header.step_loads,
        });
    }
    if v.steps.len() > MAX_STEPS {
        return fail(&format!(
            "steps (more than the {MAX_STEPS} a press can blend)"
        ));
    }
    for (k, step) in v.steps.iter().enumerate() {
        let modes = v
            .header
            .modes_per_step
            .get(k)
            .copied()
            .unwrap_or(usize::MAX);
        if product(&[modes, 3, v.header.node_count]) != Some(step.spatial.len())
            || product(&[modes, v.parameter_count()]) != Some(step.parametric.len())
        {
            return fail(&format!("modes of step {k} (sizes differ from the header)"));
        }
        let l = &step.local;
        let rows = |offsets: &[u32], len: usize, per: usize, values: usize| {
            offsets.len() == m + 1
                && offsets.first() == Some(&0)
                && offsets.windows(2).all(|w| w[0] <= w[1])
                && offsets[m] as usize == len
                && values == per * len
        };
        if !rows(
            &l.neighbour_offsets,
            l.neighbours.len(),
            9,
            l.compliance.len(),
        ) || l.neighbours.iter().any(|&j| j as usize >= m)
        {
            return fail(&format!("compliances of step {k}"));
        }
        if !rows(
            &l.correction_offsets,
            l.correction_nodes.len(),
            9,
            l.correction.len(),
        ) || l.correction_nodes.iter().any(|&n| n >= nodes)
        {
            return fail(&format!("near-field corrections of step {k}"));
        }
    }
    Ok(())
}

/// A material and its inclusions, for a message.
fn tissue(material: &Material, inclusions: &[Inclusion]) -> String {
    match inclusions {
        [] => format!("{material:?}"),
        _ => format!("{material:?} with inclusions {inclusions:?}"),
    }
}
