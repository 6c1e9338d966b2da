//! The hook's energy on an organ's wall instead of the ties: burn marks that stay, each as
//! deep as its energy boils the tissue under the hook's zone ([`TissueHeat::burned_depth_m`]).
//! A burn through a hollow organ's wall is a perforation (bile spills from the gallbladder);
//! a burn past a solid organ's capsule is a capsule injury. Both are errors of the published
//! cholecystectomy scores (a gallbladder injury with bile spilled, a liver injury).

use nalgebra::Vector3;

use super::cautery::{CauteryMode, TissueHeat};
use crate::mesh::organs::Organ;
use crate::pgd::SurfacePoint;

/// The most marks kept; a burn beyond them adds to the nearest mark on its organ, so that
/// the haptic tick never allocates.
pub const MAX_BURN_MARKS: usize = 256;

/// What the hook burns through on an organ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Wall {
    /// A hollow organ's wall (m): burned through, it is perforated.
    Hollow { thickness_m: f64 },
    /// A solid organ's capsule (m): burned past, the organ is injured.
    Capsule { thickness_m: f64 },
}

impl Wall {
    /// The gallbladder's wall: 2 mm, within the normal 1–3 mm measured by ultrasound.
    pub const GALLBLADDER: Wall = Wall::Hollow { thickness_m: 2e-3 };
    /// The duodenum's wall, taken as 2 mm (1.5–3 mm normally).
    pub const DUODENUM: Wall = Wall::Hollow { thickness_m: 2e-3 };
    /// Glisson's capsule and a solid organ's serosa, taken as 0.1 mm (tens of micrometres
    /// to a tenth of a millimetre): any burn that chars the surface injures it.
    pub const CAPSULE: Wall = Wall::Capsule { thickness_m: 1e-4 };

    /// The wall of a generated organ (a solid organ's capsule for another).
    pub fn of(organ: Option<Organ>) -> Wall {
        match organ {
            Some(Organ::Gallbladder) => Wall::GALLBLADDER,
            Some(Organ::Duodenum) => Wall::DUODENUM,
            _ => Wall::CAPSULE,
        }
    }

    /// The wall of a scene's organ by its name (a generated organ's own).
    pub fn of_name(name: &str) -> Wall {
        Wall::of(Organ::from_name(name))
    }

    pub fn thickness_m(self) -> f64 {
        match self {
            Wall::Hollow { thickness_m } | Wall::Capsule { thickness_m } => thickness_m,
        }
    }
}

/// A burn the hook left on an organ's surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BurnMark {
    /// The organ, in the scene's order.
    pub organ: usize,
    /// Where it is on the organ's surface, which carries it as the organ deforms.
    pub at: SurfacePoint,
    /// Where it is on the organ at rest (m): a burn within a zone's width of it adds to it.
    pub at_rest_m: Vector3<f64>,
    /// The area of the zone that took the energy (m²), as the first burn here set it.
    pub area_m2: f64,
    pub energy_j: f64,
    pub depth_m: f64,
    /// Burned through the wall (hollow) or past the capsule.
    pub through: bool,
}

/// What one tick's burn did on a wall.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WallBurn {
    /// The mark it made or deepened, in [`WallBurns::marks`].
    pub mark: usize,
    /// A mark of its own, not one deepened.
    pub new: bool,
    /// The wall gave way in this tick.
    pub through_now: bool,
}

/// Every burn mark of a scene, with each organ's wall.
#[derive(Clone, Debug, PartialEq)]
pub struct WallBurns {
    pub tissue: TissueHeat,
    walls: Vec<Wall>,
    marks: Vec<BurnMark>,
}

/// Where a burn lands: the organ, its surface point and that point at rest (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BurnSite {
    pub organ: usize,
    pub at: SurfacePoint,
    pub at_rest_m: Vector3<f64>,
}

impl WallBurns {
    /// No burns yet, on organs with these walls (in the scene's order).
    pub fn new(walls: Vec<Wall>, tissue: TissueHeat) -> Self {
        Self {
            tissue,
            walls,
            marks: Vec::with_capacity(MAX_BURN_MARKS),
        }
    }

    /// No burns, for another attempt (the list keeps its room).
    pub fn clear(&mut self) {
        self.marks.clear();
    }

    pub fn marks(&self) -> &[BurnMark] {
        &self.marks
    }

    pub fn wall(&self, organ: usize) -> Option<Wall> {
        self.walls.get(organ).copied()
    }

    /// The hook's energy of one tick, `energy_j` in `mode`, burned into the wall at `site`:
    /// added to the mark within a zone's width there, or to a new mark (to the nearest on
    /// the organ once [`MAX_BURN_MARKS`] are kept). `None` for an organ the scene lacks.
    pub fn burn(&mut self, site: &BurnSite, energy_j: f64, mode: CauteryMode) -> Option<WallBurn> {
        let wall = self.wall(site.organ)?;
        let nearest = self.nearest(site);
        let within = |(_, d): &(usize, f64)| *d <= mode.zone_width_m();
        let (mark, new) = match nearest {
            Some(near) if within(&near) || self.marks.len() == MAX_BURN_MARKS => (near.0, false),
            _ => {
                self.marks.push(BurnMark {
                    organ: site.organ,
                    at: site.at,
                    at_rest_m: site.at_rest_m,
                    area_m2: mode.zone_area_m2(),
                    energy_j: 0.0,
                    depth_m: 0.0,
                    through: false,
                });
                (self.marks.len() - 1, true)
            }
        };
        let per_m3 = self.tissue.burn_j_per_m3();
        let burned = &mut self.marks[mark];
        burned.energy_j += energy_j;
        burned.depth_m = burned.energy_j / (per_m3 * burned.area_m2);
        let through_now = !burned.through && burned.depth_m >= wall.thickness_m();
        burned.through |= through_now;
        Some(WallBurn {
            mark,
            new,
            through_now,
        })
    }

    /// The mark on the site's organ nearest its point, and how far it is (m).
    fn nearest(&self, site: &BurnSite) -> Option<(usize, f64)> {
        (self.marks.iter().enumerate())
            .filter(|(_, m)| m.organ == site.organ)
            .map(|(i, m)| (i, (m.at_rest_m - site.at_rest_m).norm()))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn site(organ: usize, x_m: f64) -> BurnSite {
        BurnSite {
            organ,
            at: SurfacePoint {
                triangle: 0,
                barycentric: [1.0, 0.0, 0.0],
            },
            at_rest_m: Vector3::new(x_m, 0.0, 0.0),
        }
    }

    fn scene() -> WallBurns {
        let walls = vec![Wall::GALLBLADDER, Wall::CAPSULE];
        WallBurns::new(walls, TissueHeat::SOFT_TISSUE)
    }

    /// Held on the gallbladder at 30 W in cut, the hook goes through its 2 mm wall when the
    /// energy has boiled a column as deep under its 1 mm zone: E = 2 mm × π (0.5 mm)² ×
    /// 2.03 GJ/m³ ≈ 3.2 J, about 0.106 s. The liver's capsule gives way in a twentieth of it.
    #[test]
    fn a_wall_is_burned_through_when_its_column_has_boiled() {
        let per_m3 = 1060.0 * (3600.0 * 63.0 + 0.75 * 2.257e6);
        let area = std::f64::consts::PI * 0.25e-6;
        let (power_w, tick_s) = (30.0, 1e-3);
        for (organ, thickness_m) in [(0, 2e-3), (1, 1e-4)] {
            let mut burns = scene();
            let expected_s = thickness_m * area * per_m3 / power_w;
            let mut through_at = None;
            for tick in 1..=1000 {
                let burn = burns
                    .burn(&site(organ, 0.0), power_w * tick_s, CauteryMode::Cut)
                    .unwrap();
                assert_eq!(burn.new, tick == 1);
                if burn.through_now {
                    assert!(through_at.is_none(), "through twice");
                    through_at = Some(tick as f64 * tick_s);
                }
            }
            let through_at = through_at.expect("burned through");
            assert!(
                (through_at - expected_s).abs() <= tick_s,
                "organ {organ}: {through_at} s against {expected_s} s"
            );
            assert_eq!(burns.marks().len(), 1);
            let through = |o: usize| {
                burns
                    .marks()
                    .iter()
                    .filter(move |m| m.organ == o && m.through)
            };
            assert_eq!(through(organ).count(), 1);
            assert_eq!(through(1 - organ).count(), 0);
        }
    }

    /// A burn a zone's width away from a mark makes a mark of its own; one within it, on
    /// another organ, too; once the marks are all kept, a burn deepens the nearest.
    #[test]
    fn burns_apart_make_marks_of_their_own_and_the_list_never_grows_past_its_room() {
        let mut burns = scene();
        let mode = CauteryMode::Coagulate;
        assert!(burns.burn(&site(0, 0.0), 0.01, mode).unwrap().new);
        assert!(!burns.burn(&site(0, 2.9e-3), 0.01, mode).unwrap().new);
        assert!(
            burns
                .burn(&site(0, 3.1e-3 + 2.9e-3), 0.01, mode)
                .unwrap()
                .new
        );
        assert!(burns.burn(&site(1, 0.0), 0.01, mode).unwrap().new);
        assert!(burns.burn(&site(2, 0.0), 0.01, mode).is_none());
        for k in 0..2 * MAX_BURN_MARKS {
            burns.burn(&site(1, 1.0 + 0.01 * k as f64), 0.01, mode);
        }
        assert_eq!(burns.marks().len(), MAX_BURN_MARKS);
        assert_eq!(burns.marks.capacity(), MAX_BURN_MARKS);
        let total: f64 = burns.marks().iter().map(|m| m.energy_j).sum();
        assert!((total - 0.01 * (4 + 2 * MAX_BURN_MARKS) as f64).abs() < 1e-9);
    }
}
