//! The abdominal organs of paper 000 in their anatomical places, and the cornea of paper 001.

use nalgebra::{Point3, Vector3};

use super::shapes::{ArcTube, capsule, ellipsoid, revolution, smooth_union};
use super::{Organ, OrganSettings, region};
use crate::mesh::{
    Implicit, MeshError, Surface, TetMesh, extrude, revolution as revolution_surface,
    spherical_cap, stuff_to_node_count,
};

/// Gap left between neighbouring organs where one yields to another (m). It covers the chord
/// error of the yielding organ's elements across the dent it gets (measured up to 1 mm at the
/// duodenum's 4 mm elements), so the meshes touch without overlapping.
pub const GAP_M: f64 = 1.2e-3;
/// A surface node within this of a neighbour's surface belongs to the attachment (m).
const ATTACHMENT_M: f64 = 2.5e-3;
/// Gallbladder wall (paper 000) and the cornea's thickness (m).
pub const GALLBLADDER_WALL_M: f64 = 2.5e-3;
pub const CORNEA_THICKNESS_M: f64 = 0.5e-3;
/// Anterior corneal curvature and the radius of its rim (m): 11.5 mm across.
pub const CORNEA_CURVATURE_M: f64 = 7.8e-3;
pub const CORNEA_RIM_M: f64 = 5.75e-3;
/// Elements through the thin walls.
const SHELL_LAYERS: usize = 2;

/// The shapes of the abdominal organs, after each has yielded to those built before it.
pub struct Abdomen {
    right_lobe: (Point3<f64>, Vector3<f64>),
    left_lobe: (Point3<f64>, Vector3<f64>),
    /// The liver's flat posterior face (clamped along the vena cava) and inferior cut (y, z).
    posterior_y: f64,
    inferior_z: f64,
    fundus: Point3<f64>,
    neck: Point3<f64>,
    gallbladder_radius: f64,
    duodenum: ArcTube,
    pancreas_head: (Point3<f64>, Vector3<f64>),
    pancreas_spine: [(Point3<f64>, f64); 4],
}

impl Abdomen {
    /// The layout for a seed: proportions vary by up to ±4 %, placement stays anatomical.
    pub fn new(settings: &OrganSettings) -> Self {
        let mut rng = SplitMix(settings.seed);
        let mut vary = || 1.0 + 0.04 * (2.0 * rng.unit() - 1.0);
        Self {
            right_lobe: (
                Point3::new(0.03, 0.0, 0.0),
                Vector3::new(0.065, 0.06, 0.075) * vary(),
            ),
            left_lobe: (
                Point3::new(-0.04, 0.01, 0.01),
                Vector3::new(0.05, 0.03, 0.05) * vary(),
            ),
            posterior_y: -0.04,
            inferior_z: -0.05,
            fundus: Point3::new(0.05, 0.035, -0.055),
            neck: Point3::new(0.02, -0.038, -0.074),
            gallbladder_radius: 0.0155 * vary(),
            duodenum: ArcTube {
                centre: Point3::new(-0.005, -0.04, -0.115),
                u: Vector3::x(),
                w: Vector3::z(),
                arc_radius: 0.045 * vary(),
                tube_radius: 0.012,
                from: (-130.0f64).to_radians(),
                to: 130.0f64.to_radians(),
            },
            pancreas_head: (
                Point3::new(0.002, -0.04, -0.115),
                Vector3::new(0.03, 0.018, 0.03) * vary(),
            ),
            pancreas_spine: [
                (Point3::new(0.0, -0.04, -0.112), 0.014),
                (Point3::new(-0.035, -0.035, -0.10), 0.013),
                (Point3::new(-0.075, -0.045, -0.09), 0.011),
                (Point3::new(-0.115, -0.055, -0.075), 0.008),
            ],
        }
    }

    /// The gallbladder's axis: its fundus and its neck (m).
    pub fn gallbladder_axis_m(&self) -> (Point3<f64>, Point3<f64>) {
        (self.fundus, self.neck)
    }

    /// The point of the duodenum's axis above its centre at `x_m` (m), on its arc.
    pub fn duodenum_axis_above_m(&self, x_m: f64) -> Point3<f64> {
        let arc = &self.duodenum;
        let cos = ((x_m - arc.centre.x) / arc.arc_radius).clamp(-1.0, 1.0);
        arc.point_at(libm::acos(cos).clamp(arc.from, arc.to))
    }

    /// Length of the gallbladder from fundus to neck (m).
    pub fn gallbladder_length_m(&self) -> f64 {
        (self.neck - self.fundus).norm()
    }

    /// Mid-wall radius of the pear-shaped sac at `t ∈ [0, 1]` from fundus to neck.
    pub fn gallbladder_profile(&self, t: f64) -> f64 {
        // Full in the body, round at the fundus, tapering to the neck; the sixth power keeps
        // the ends blunt enough for the duodenum's elements to wrap the neck.
        let u = 2.0 * t - 1.0;
        self.gallbladder_radius * (1.0 - 0.45 * t) * (1.0 - u.powi(6)).max(0.0).sqrt()
    }

    fn gallbladder_outer(&self, p: &Point3<f64>) -> f64 {
        // The sac lies inside this capsule, so the distance to the capsule bounds the distance
        // to the sac from below. Far from the sac the bound is enough: beyond FAR_M it changes
        // no organ's sign, gap or attachment, and it is much cheaper than the exact distance.
        const FAR_M: f64 = 0.02;
        let bound = capsule(
            p,
            self.fundus,
            self.neck,
            self.gallbladder_radius + GALLBLADDER_WALL_M,
        );
        if bound > FAR_M {
            return bound;
        }
        let profile = |t: f64| self.gallbladder_profile(t);
        revolution(
            p,
            self.fundus,
            self.neck,
            &profile,
            GALLBLADDER_WALL_M / 2.0,
        )
    }

    fn liver(&self, p: &Point3<f64>) -> f64 {
        let lobes = smooth_union(
            ellipsoid(p, self.right_lobe.0, self.right_lobe.1),
            ellipsoid(p, self.left_lobe.0, self.left_lobe.1),
            0.02,
        );
        lobes
            .max(self.posterior_y - p.y)
            .max(self.inferior_z - p.z)
            .max(GAP_M - self.gallbladder_outer(p))
    }

    fn duodenum(&self, p: &Point3<f64>) -> f64 {
        self.duodenum
            .value(p)
            .max(GAP_M - self.gallbladder_outer(p))
            .max(GAP_M - self.liver(p))
    }

    fn pancreas(&self, p: &Point3<f64>) -> f64 {
        let mut shape = ellipsoid(p, self.pancreas_head.0, self.pancreas_head.1);
        for pair in self.pancreas_spine.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            shape = smooth_union(shape, capsule(p, a.0, b.0, a.1.min(b.1)), 0.01);
        }
        shape
            .max(GAP_M - self.duodenum(p))
            .max(GAP_M - self.liver(p))
            .max(GAP_M - self.gallbladder_outer(p))
    }

    /// The implicit function of an organ's final shape (negative inside); the cornea, which
    /// is not in the abdomen, is outside everywhere.
    pub fn value(&self, organ: Organ, p: &Point3<f64>) -> f64 {
        match organ {
            Organ::Liver => self.liver(p),
            Organ::Gallbladder => self.gallbladder_outer(p),
            Organ::Duodenum => self.duodenum(p),
            Organ::Pancreas => self.pancreas(p),
            Organ::Cornea => f64::INFINITY,
        }
    }

    /// Meshes one organ and tags its regions (the cornea stands apart from the abdomen).
    pub fn mesh(&self, organ: Organ, settings: &OrganSettings) -> Result<TetMesh, MeshError> {
        let target = target_nodes(organ, settings);
        let mut mesh = match organ {
            Organ::Cornea => return cornea(settings),
            Organ::Gallbladder => self.gallbladder_mesh(target)?,
            _ => {
                let (min, max) = self.bounds(organ);
                let value = |p: &Point3<f64>| self.value(organ, p);
                stuff_to_node_count(
                    organ.name(),
                    &Implicit {
                        value: &value,
                        min,
                        max,
                    },
                    target,
                )?
            }
        };
        self.tag_regions(organ, &mut mesh)?;
        Ok(mesh)
    }

    fn bounds(&self, organ: Organ) -> (Point3<f64>, Point3<f64>) {
        match organ {
            Organ::Liver => (
                Point3::new(-0.10, -0.045, -0.06),
                Point3::new(0.11, 0.075, 0.085),
            ),
            Organ::Duodenum => {
                let reach = self.duodenum.arc_radius + self.duodenum.tube_radius + 0.005;
                let c = self.duodenum.centre;
                (
                    c - Vector3::new(reach, self.duodenum.tube_radius + 0.005, reach),
                    c + Vector3::new(reach, self.duodenum.tube_radius + 0.005, reach),
                )
            }
            _ => (
                Point3::new(-0.135, -0.075, -0.16),
                Point3::new(0.045, -0.01, -0.06),
            ),
        }
    }

    fn gallbladder_mesh(&self, target_nodes: usize) -> Result<TetMesh, MeshError> {
        // Two rings of vertices per segment keeps the quads near square on this sac.
        let per_layer = target_nodes / (SHELL_LAYERS + 1);
        let segments = ((per_layer as f64 / 1.8).sqrt().round() as usize).max(8);
        let rings = (per_layer / segments).max(3);
        let profile = |t: f64| self.gallbladder_profile(t);
        let surface = revolution_surface(self.fundus, self.neck, &profile, rings, segments);
        extrude(
            Organ::Gallbladder.name(),
            &surface,
            GALLBLADDER_WALL_M,
            SHELL_LAYERS,
        )
    }

    fn tag_regions(&self, organ: Organ, mesh: &mut TetMesh) -> Result<(), MeshError> {
        let surface = Surface::extract(mesh);
        let near = |other: Organ| -> Vec<usize> {
            surface
                .nodes
                .iter()
                .copied()
                .filter(|&n| self.value(other, &mesh.nodes()[n]) <= ATTACHMENT_M)
                .collect()
        };
        let clamped: Vec<usize> = match organ {
            Organ::Liver => surface
                .nodes
                .iter()
                .copied()
                .filter(|&n| mesh.nodes()[n].y <= self.posterior_y + 1e-9)
                .collect(),
            Organ::Duodenum => surface
                .nodes
                .iter()
                .copied()
                .filter(|&n| {
                    let angle = self.duodenum.angle(&mesh.nodes()[n]);
                    !(self.duodenum.from..=self.duodenum.to).contains(&angle)
                })
                .collect(),
            // Held by their attachment to the duodenum (paper 000).
            Organ::Gallbladder | Organ::Pancreas => near(Organ::Duodenum),
            Organ::Cornea => unreachable!("the cornea is not an abdominal organ"),
        };
        let attachments: &[Organ] = match organ {
            Organ::Gallbladder | Organ::Pancreas => &[Organ::Duodenum],
            Organ::Duodenum => &[Organ::Gallbladder, Organ::Pancreas],
            _ => &[],
        };
        let attached: Vec<(String, Vec<usize>)> = attachments
            .iter()
            .map(|&other| {
                (
                    format!("{}{}", region::ATTACHED_PREFIX, other.name()),
                    near(other),
                )
            })
            .collect();
        for (name, nodes) in attached {
            mesh.set_node_set(&name, nodes)?;
        }
        if organ == Organ::Gallbladder {
            // Layer 0 of the extruded wall is its inner side, facing the bile.
            let per_layer = mesh.node_count() / (SHELL_LAYERS + 1);
            let inner: Vec<[usize; 3]> = surface
                .triangles
                .iter()
                .filter(|f| f.iter().all(|&n| n < per_layer))
                .copied()
                .collect();
            mesh.set_face_set(region::PRESSURIZED, inner)?;
        }
        let accessible = outer_faces_without(&surface, &clamped, organ, mesh.node_count());
        mesh.set_node_set(region::CLAMPED, clamped)?;
        mesh.set_face_set(region::ACCESSIBLE, accessible)
    }
}

/// Boundary faces a tool can reach: none of their nodes clamped, and for the gallbladder only
/// its outer wall.
fn outer_faces_without(
    surface: &Surface,
    clamped: &[usize],
    organ: Organ,
    nodes: usize,
) -> Vec<[usize; 3]> {
    let outer_from = match organ {
        Organ::Gallbladder => nodes / (SHELL_LAYERS + 1) * SHELL_LAYERS,
        _ => 0,
    };
    faces_from_without(surface, clamped, outer_from, nodes)
}

/// The surface's faces whose nodes are all numbered from `first` on and none held.
fn faces_from_without(
    surface: &Surface,
    clamped: &[usize],
    first: usize,
    nodes: usize,
) -> Vec<[usize; 3]> {
    let mut held = vec![false; nodes];
    for &n in clamped {
        held[n] = true;
    }
    let outer_from = first;
    surface
        .triangles
        .iter()
        .filter(|f| f.iter().all(|&n| !held[n] && n >= outer_from))
        .copied()
        .collect()
}

/// The cornea of paper 001: a thin spherical cap, rim clamped, anterior face accessible, with
/// `settings.cornea_layers` elements through its thickness (a cut's depth is resolved to one
/// of them). Layer 0 is the posterior face, the last layer the anterior one; the node count
/// per layer is the organ's at `settings` over three, whatever the layers.
fn cornea(settings: &OrganSettings) -> Result<TetMesh, MeshError> {
    let layers = settings.cornea_layers.max(1);
    let per_layer = target_nodes(Organ::Cornea, settings) / (SHELL_LAYERS + 1);
    // A hexagonal disc of r rings has 1 + 3r(r + 1) vertices.
    let rings = (((per_layer as f64 / 3.0).sqrt()).round() as usize).max(2);
    let surface = spherical_cap(CORNEA_CURVATURE_M, CORNEA_RIM_M, rings);
    let mut mesh = extrude(Organ::Cornea.name(), &surface, CORNEA_THICKNESS_M, layers)?;
    let n = surface.points.len();
    let first_rim_vertex = 1 + 3 * rings * (rings - 1);
    let clamped: Vec<usize> = (0..=layers)
        .flat_map(|k| (first_rim_vertex..n).map(move |v| k * n + v))
        .collect();
    let boundary = Surface::extract(&mesh);
    let accessible = faces_from_without(&boundary, &clamped, layers * n, mesh.node_count());
    mesh.set_node_set(region::CLAMPED, clamped)?;
    mesh.set_face_set(region::ACCESSIBLE, accessible)?;
    Ok(mesh)
}

fn target_nodes(organ: Organ, settings: &OrganSettings) -> usize {
    ((organ.default_nodes() as f64 * settings.resolution).round() as usize).max(50)
}

/// A tiny deterministic generator (SplitMix64), enough to vary proportions by seed.
struct SplitMix(u64);

impl SplitMix {
    fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}
