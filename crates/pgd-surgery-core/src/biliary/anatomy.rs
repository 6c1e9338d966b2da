//! The extrahepatic biliary tree of the generated abdomen at published sizes: the cystic duct
//! from the gallbladder's infundibulum to its junction with the common duct, the common duct
//! from the liver's hilum down to the duodenum (the common hepatic duct above the junction,
//! the common bile duct below it), and the cystic artery from the right hepatic artery, behind
//! the common hepatic duct, to the gallbladder. Each is a straight rod at rest, its ends held
//! where it is attached in a body. An [`Anatomy`] varies it within published ranges.

use std::fmt;

use nalgebra::{Point3, Vector3};
use serde::{Deserialize, Serialize};

use super::fat::{Triangle, TriangleFat};
use crate::mesh::organs::{Abdomen, Organ};
use crate::rods::{Rod, RodError, TubeSection};

/// The three tubes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Structure {
    CysticDuct,
    /// The common hepatic duct and the common bile duct, one tube: where the cystic duct
    /// joins it divides the two.
    CommonDuct,
    CysticArtery,
}

impl Structure {
    pub const ALL: [Structure; 3] = [Self::CysticDuct, Self::CommonDuct, Self::CysticArtery];

    pub fn name(self) -> &'static str {
        match self {
            Self::CysticDuct => "the cystic duct",
            Self::CommonDuct => "the common duct",
            Self::CysticArtery => "the cystic artery",
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// What a point of a tube is, anatomically.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Part {
    CysticDuct,
    CommonHepaticDuct,
    CommonBileDuct,
    CysticArtery,
}

impl Part {
    pub fn name(self) -> &'static str {
        match self {
            Self::CysticDuct => "the cystic duct",
            Self::CommonHepaticDuct => "the common hepatic duct",
            Self::CommonBileDuct => "the common bile duct",
            Self::CysticArtery => "the cystic artery",
        }
    }

    /// The bile ducts a clip or a cut must never close or divide: doing so is a bile duct
    /// injury.
    pub fn is_main_bile_duct(self) -> bool {
        matches!(self, Self::CommonHepaticDuct | Self::CommonBileDuct)
    }
}

/// Where the cystic artery runs, seen from the front.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum ArteryCourse {
    /// Above and behind the cystic duct, as usual.
    #[default]
    Behind,
    /// Crossing in front of the cystic duct, to the gallbladder below it.
    InFront,
}

/// The sizes and the variant of one patient's biliary tree.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Anatomy {
    /// The cystic duct's length from the gallbladder to its junction (mm).
    pub cystic_duct_mm: f64,
    /// The cystic duct's outer diameter (mm).
    pub cystic_duct_diameter_mm: f64,
    /// The common duct's outer diameter (mm).
    pub common_duct_diameter_mm: f64,
    /// The cystic artery's outer diameter (mm).
    pub artery_diameter_mm: f64,
    /// Where the cystic duct joins the common duct, as its share of the common duct's length
    /// from the hilum down to the duodenum (above 0.6: a low junction).
    pub junction: f64,
    pub artery: ArteryCourse,
}

impl Default for Anatomy {
    fn default() -> Self {
        Self {
            cystic_duct_mm: 27.0,
            cystic_duct_diameter_mm: 2.8,
            common_duct_diameter_mm: 6.0,
            artery_diameter_mm: 1.2,
            junction: 0.35,
            artery: ArteryCourse::Behind,
        }
    }
}

/// A field's accepted range and where it comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldRange {
    pub field: &'static str,
    pub low: f64,
    pub high: f64,
    pub source: &'static str,
}

/// The ranges [`Anatomy::check`] accepts; `docs/biliary.md` cites each source in full.
pub const RANGES: [FieldRange; 5] = [
    FieldRange {
        field: "cystic_duct_mm",
        low: 16.0,
        high: 40.0,
        source: "2 to 4 cm usually, 0.5 to 9 cm reported; the generated abdomen has room for \
                 16 to 40 mm",
    },
    FieldRange {
        field: "cystic_duct_diameter_mm",
        low: 1.0,
        high: 5.0,
        source: "2 to 3 mm usually, 2.84 mm on average",
    },
    FieldRange {
        field: "common_duct_diameter_mm",
        low: 3.0,
        high: 9.0,
        source: "3 to 9 mm",
    },
    FieldRange {
        field: "artery_diameter_mm",
        low: 0.8,
        high: 3.0,
        source: "1.17 mm on average",
    },
    FieldRange {
        field: "junction",
        low: 0.15,
        high: 0.8,
        source: "the bile duct about twice the hepatic duct's length: 1/3 usually; a low \
                 junction joins in the lower third",
    },
];

/// Why no biliary tree was made.
#[derive(Clone, Debug, PartialEq)]
pub enum AnatomyError {
    OutOfRange {
        range: FieldRange,
        value: f64,
    },
    /// The generated abdomen has no room for this anatomy: what could not be placed.
    Placement(String),
    Rod(RodError),
}

impl fmt::Display for AnatomyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::OutOfRange { range, value } => write!(
                f,
                "{} is {value}: it must be from {} to {} ({})",
                range.field, range.low, range.high, range.source
            ),
            Self::Placement(what) => write!(f, "the biliary tree does not fit: {what}"),
            Self::Rod(e) => write!(f, "a biliary rod was refused: {e}"),
        }
    }
}

impl std::error::Error for AnatomyError {}

impl From<RodError> for AnatomyError {
    fn from(e: RodError) -> Self {
        Self::Rod(e)
    }
}

impl Anatomy {
    fn values(&self) -> [f64; 5] {
        [
            self.cystic_duct_mm,
            self.cystic_duct_diameter_mm,
            self.common_duct_diameter_mm,
            self.artery_diameter_mm,
            self.junction,
        ]
    }

    /// Refuses a size outside its published range, naming the field.
    pub fn check(&self) -> Result<(), AnatomyError> {
        match RANGES
            .iter()
            .zip(self.values())
            .find(|(range, value)| !(value.is_finite() && (range.low..=range.high).contains(value)))
        {
            Some((&range, value)) => Err(AnatomyError::OutOfRange { range, value }),
            None => Ok(()),
        }
    }
}

/// The walls and moduli the tubes are made of (`docs/biliary.md` has their sources): a duct's
/// wall a sixth of its diameter (1 mm for a 6 mm common duct), the artery's an eighth; the
/// ducts' wall 0.3 MPa (the porcine common bile duct distended to 5 kPa), the artery's 1 MPa.
const DUCT_WALL_SHARE: f64 = 1.0 / 6.0;
const ARTERY_WALL_SHARE: f64 = 1.0 / 8.0;
pub const DUCT_YOUNG_PA: f64 = 0.3e6;
pub const ARTERY_YOUNG_PA: f64 = 1.0e6;

/// The rods' segments are about this long (m).
const SEGMENT_M: f64 = 2e-3;

/// One tube: its node 0 is its patient end (the junction, the hilum, the right hepatic
/// artery), its last node the gallbladder's or the duodenum's.
#[derive(Clone, Debug)]
pub struct Tube {
    pub structure: Structure,
    pub section: TubeSection,
    pub rod: Rod,
    /// Whether its last node enters the gallbladder.
    pub enters_gallbladder: bool,
}

impl Tube {
    fn new(
        structure: Structure,
        from_m: Vector3<f64>,
        to_m: Vector3<f64>,
        segments: usize,
        section: TubeSection,
        young_pa: f64,
        enters_gallbladder: bool,
    ) -> Result<Self, AnatomyError> {
        let mut rod = Rod::straight(from_m, to_m, segments, section, young_pa)?;
        rod.hold(0)?;
        rod.hold(segments)?;
        Ok(Self {
            structure,
            section,
            rod,
            enters_gallbladder,
        })
    }

    /// Its length at rest (m).
    pub fn length_m(&self) -> f64 {
        self.rod.segment_m() * (self.rod.nodes() - 1) as f64
    }

    /// Its segments where they are now, with each one's first node.
    pub fn segments(&self) -> impl Iterator<Item = (usize, super::geometry::Segment)> + '_ {
        (self.rod.positions.windows(2).enumerate())
            .map(|(i, w)| (i, super::geometry::Segment::new(w[0], w[1])))
    }

    /// The point at `arc_length_m` from its patient end, where it is now.
    pub fn point_at(&self, arc_length_m: f64) -> Vector3<f64> {
        let (segment, along) = self.locate(arc_length_m);
        let p = &self.rod.positions;
        p[segment] + (p[segment + 1] - p[segment]) * along
    }

    /// The segment holding `arc_length_m` and the share of it before the point.
    fn locate(&self, arc_length_m: f64) -> (usize, f64) {
        let last = self.rod.nodes() - 2;
        let s = (arc_length_m / self.rod.segment_m()).max(0.0);
        let segment = (s.floor() as usize).min(last);
        (segment, (s - segment as f64).min(1.0))
    }
}

/// The biliary tree of one patient in the generated abdomen.
#[derive(Clone, Debug)]
pub struct BiliaryTree {
    pub anatomy: Anatomy,
    /// In [`Structure::ALL`]'s order.
    pub tubes: [Tube; 3],
    /// The common duct's node where the cystic duct joins it.
    pub junction_node: usize,
    pub fat: TriangleFat,
}

/// Where the generator starts its search for the liver's hilum in the generated abdomen's
/// frame (m; x towards the patient's right, y to the front, z to the head): a point inside
/// the liver above it. The common duct's other end is on the duodenum's front wall, this far
/// to the left of the hilum (m).
const ABOVE_HILUM_M: [f64; 3] = [-0.012, -0.015, -0.01];
const DUODENUM_LEFT_OF_HILUM_M: f64 = 0.012;
/// The common duct meets the duodenum's front wall.
const TO_DUODENUM_WALL: [f64; 3] = [0.0, 1.0, 0.0];
/// Along the gallbladder's axis, from fundus (0) to neck (1): where the cystic duct leaves
/// the infundibulum, and where the artery reaches the wall when it runs behind the duct and
/// when it crosses in front of it.
const DUCT_EXIT_T: f64 = 0.85;
const ARTERY_ENTRY_T: [f64; 2] = [0.72, 0.88];
/// How far the common duct may move sideways to give the cystic duct its length (m).
const COMMON_DUCT_SHIFT_M: f64 = 0.025;
/// Clearance kept between the artery and the common hepatic duct it passes (m).
const ARTERY_CLEARANCE_M: f64 = 1e-3;
/// The artery leaves the right hepatic artery at least this far below the hilum, beyond its
/// radius (m).
const ARTERY_BELOW_HILUM_M: f64 = 5e-3;

impl BiliaryTree {
    /// The tree of `anatomy` in `abdomen`, after [`Anatomy::check`].
    pub fn generate(anatomy: &Anatomy, abdomen: &Abdomen) -> Result<Self, AnatomyError> {
        anatomy.check()?;
        let cystic = duct_section(anatomy.cystic_duct_diameter_mm);
        let common = duct_section(anatomy.common_duct_diameter_mm);
        let artery = TubeSection {
            outer_radius_m: anatomy.artery_diameter_mm * 0.5e-3,
            wall_m: anatomy.artery_diameter_mm * 1e-3 * ARTERY_WALL_SHARE,
        };
        let layout = Layout::new(anatomy, abdomen, common.outer_radius_m)?;
        let cystic_tube = Tube::new(
            Structure::CysticDuct,
            layout.junction_m,
            layout.duct_exit_m,
            segments_along(layout.junction_m, layout.duct_exit_m),
            cystic,
            DUCT_YOUNG_PA,
            true,
        )?;
        let (hilum_m, junction_node, segments) = layout.common_duct_nodes();
        let common_tube = Tube::new(
            Structure::CommonDuct,
            hilum_m,
            layout.duodenum_m,
            segments,
            common,
            DUCT_YOUNG_PA,
            false,
        )?;
        let origin = layout.artery_origin_m(anatomy, &common_tube, artery.outer_radius_m);
        let entry = layout.artery_entry_m(anatomy, abdomen)?;
        let artery_tube = Tube::new(
            Structure::CysticArtery,
            origin,
            entry,
            segments_along(origin, entry),
            artery,
            ARTERY_YOUNG_PA,
            true,
        )?;
        let triangle = Triangle {
            junction_m: layout.junction_m,
            cystic_end_m: layout.duct_exit_m,
            hilum_m,
        };
        let fat = TriangleFat::wrapping(&triangle, common.outer_radius_m, layout.anterior);
        Ok(Self {
            anatomy: *anatomy,
            tubes: [cystic_tube, common_tube, artery_tube],
            junction_node,
            fat,
        })
    }

    pub fn tube(&self, structure: Structure) -> &Tube {
        &self.tubes[structure.index()]
    }

    pub fn tube_mut(&mut self, structure: Structure) -> &mut Tube {
        &mut self.tubes[structure.index()]
    }

    /// The common duct's arc length from the hilum to the junction (m).
    pub fn junction_arc_m(&self) -> f64 {
        self.junction_node as f64 * self.tube(Structure::CommonDuct).rod.segment_m()
    }

    /// What the point `arc_length_m` along `structure` is.
    pub fn part_at(&self, structure: Structure, arc_length_m: f64) -> Part {
        match structure {
            Structure::CysticDuct => Part::CysticDuct,
            Structure::CysticArtery => Part::CysticArtery,
            Structure::CommonDuct if arc_length_m < self.junction_arc_m() => {
                Part::CommonHepaticDuct
            }
            Structure::CommonDuct => Part::CommonBileDuct,
        }
    }
}

/// Segments of about [`SEGMENT_M`] from `from_m` to `to_m`, at least two.
fn segments_along(from_m: Vector3<f64>, to_m: Vector3<f64>) -> usize {
    (((to_m - from_m).norm() / SEGMENT_M).round() as usize).max(2)
}

fn duct_section(diameter_mm: f64) -> TubeSection {
    TubeSection {
        outer_radius_m: diameter_mm * 0.5e-3,
        wall_m: diameter_mm * 1e-3 * DUCT_WALL_SHARE,
    }
}

/// Where the tubes' ends go in one abdomen.
struct Layout {
    hilum_m: Vector3<f64>,
    duodenum_m: Vector3<f64>,
    junction_m: Vector3<f64>,
    duct_exit_m: Vector3<f64>,
    /// Towards the front, across the hepatocystic triangle.
    anterior: Vector3<f64>,
    gallbladder: (Point3<f64>, Point3<f64>),
}

impl Layout {
    fn new(
        anatomy: &Anatomy,
        abdomen: &Abdomen,
        common_radius_m: f64,
    ) -> Result<Self, AnatomyError> {
        let gallbladder = abdomen.gallbladder_axis_m();
        let common_duct = |shift_m: f64| -> Result<(Vector3<f64>, Vector3<f64>), AnatomyError> {
            let shift = Vector3::x() * shift_m;
            let hilum = surface_along(
                abdomen,
                Organ::Liver,
                Point3::from(Vector3::from(ABOVE_HILUM_M) + shift),
                -Vector3::z(),
            )
            .ok_or_else(|| AnatomyError::Placement("no hilum under the liver".into()))?;
            let duodenum = surface_along(
                abdomen,
                Organ::Duodenum,
                abdomen
                    .duodenum_axis_above_m(ABOVE_HILUM_M[0] + shift_m - DUODENUM_LEFT_OF_HILUM_M),
                Vector3::from(TO_DUODENUM_WALL).normalize(),
            )
            .ok_or_else(|| AnatomyError::Placement("no duodenal wall to reach".into()))?;
            let hilum = hilum.coords - Vector3::z() * common_radius_m;
            Ok((hilum, duodenum.coords))
        };
        let junction_of = |(hilum, duodenum): (Vector3<f64>, Vector3<f64>)| {
            hilum + (duodenum - hilum) * anatomy.junction
        };
        let nominal = junction_of(common_duct(0.0)?);
        let duct_exit = wall_towards(abdomen, gallbladder, DUCT_EXIT_T, nominal)?;
        let length_m = anatomy.cystic_duct_mm * 1e-3;
        let excess = |shift_m: f64| -> Result<f64, AnatomyError> {
            Ok((duct_exit - junction_of(common_duct(shift_m)?)).norm() - length_m)
        };
        // Moving the common duct towards the gallbladder (+x) shortens the cystic duct.
        let (mut near, mut far) = (COMMON_DUCT_SHIFT_M, -COMMON_DUCT_SHIFT_M);
        if excess(near)? > 0.0 || excess(far)? < 0.0 {
            return Err(AnatomyError::Placement(format!(
                "no place for the common duct gives a cystic duct of {} mm",
                anatomy.cystic_duct_mm
            )));
        }
        for _ in 0..50 {
            let mid = 0.5 * (near + far);
            if excess(mid)? > 0.0 {
                far = mid;
            } else {
                near = mid;
            }
        }
        let (hilum_m, duodenum_m) = common_duct(0.5 * (near + far))?;
        let junction_m = junction_of((hilum_m, duodenum_m));
        let anterior = {
            let normal = (duct_exit - junction_m).cross(&(hilum_m - junction_m));
            let normal = normal.normalize();
            if normal.y < 0.0 { -normal } else { normal }
        };
        Ok(Self {
            hilum_m,
            duodenum_m,
            junction_m,
            duct_exit_m: duct_exit,
            anterior,
            gallbladder,
        })
    }

    /// The common duct's nodes with the junction on one of them: its segments as long as the
    /// common bile duct's whole number of them sets, its hilum end moved along it by less
    /// than half a segment to bring the junction onto a node. Returns the hilum end, the
    /// junction's node and the segments.
    fn common_duct_nodes(&self) -> (Vector3<f64>, usize, usize) {
        let below = segments_along(self.junction_m, self.duodenum_m);
        let segment_m = (self.duodenum_m - self.junction_m).norm() / below as f64;
        let up = self.hilum_m - self.junction_m;
        let above = ((up.norm() / segment_m).round() as usize).max(1);
        let hilum_m = self.junction_m + up.normalize() * (above as f64 * segment_m);
        (hilum_m, above, above + below)
    }

    /// The right hepatic artery's point the cystic artery leaves: beside the common hepatic
    /// duct halfway down it, behind it, or in front of it when the artery crosses in front;
    /// at least [`ARTERY_BELOW_HILUM_M`] below the hilum, clear of the liver.
    fn artery_origin_m(&self, anatomy: &Anatomy, common: &Tube, radius_m: f64) -> Vector3<f64> {
        let beside = common.section.outer_radius_m + radius_m + ARTERY_CLEARANCE_M;
        let side = match anatomy.artery {
            ArteryCourse::Behind => -self.anterior,
            ArteryCourse::InFront => self.anterior,
        };
        let down = self.junction_m - self.hilum_m;
        let below_m = (0.5 * down.norm()).max(ARTERY_BELOW_HILUM_M + radius_m);
        self.hilum_m + down.normalize() * below_m + side * beside
    }

    /// Where the artery reaches the gallbladder: on the wall facing its origin, above the
    /// duct when it runs behind it, below the duct when it crosses in front.
    fn artery_entry_m(
        &self,
        anatomy: &Anatomy,
        abdomen: &Abdomen,
    ) -> Result<Vector3<f64>, AnatomyError> {
        let (t, towards) = match anatomy.artery {
            ArteryCourse::Behind => (ARTERY_ENTRY_T[0], self.hilum_m - self.anterior * 0.006),
            ArteryCourse::InFront => (
                ARTERY_ENTRY_T[1],
                self.junction_m + self.anterior * 0.012 - Vector3::z() * 0.004,
            ),
        };
        wall_towards(abdomen, self.gallbladder, t, towards)
    }
}

/// The gallbladder's outer wall at `t` along its axis, on the side facing `towards`.
fn wall_towards(
    abdomen: &Abdomen,
    (fundus, neck): (Point3<f64>, Point3<f64>),
    t: f64,
    towards: Vector3<f64>,
) -> Result<Vector3<f64>, AnatomyError> {
    let axis = (neck - fundus).normalize();
    let on_axis = fundus + (neck - fundus) * t;
    let out = towards - on_axis.coords;
    let across = (out - axis * out.dot(&axis)).normalize();
    surface_along(abdomen, Organ::Gallbladder, on_axis, across)
        .map(|p| p.coords)
        .ok_or_else(|| AnatomyError::Placement("no gallbladder wall where a tube enters".into()))
}

/// Stepping from `from` along the unit `direction`, the first point past where `organ` was
/// entered where it is left again (its implicit value back to zero, to a micrometre), within
/// 10 cm.
fn surface_along(
    abdomen: &Abdomen,
    organ: Organ,
    from: Point3<f64>,
    direction: Vector3<f64>,
) -> Option<Point3<f64>> {
    const STEP_M: f64 = 2.5e-4;
    const REACH_M: f64 = 0.1;
    let value = |s: f64| abdomen.value(organ, &(from + direction * s));
    let mut entered = value(0.0) < 0.0;
    let mut s = 0.0;
    while s < REACH_M {
        let next = s + STEP_M;
        let inside = value(next) < 0.0;
        if entered && !inside {
            let (mut a, mut b) = (s, next);
            while b - a > 1e-6 {
                let mid = 0.5 * (a + b);
                if value(mid) < 0.0 { a = mid } else { b = mid }
            }
            return Some(from + direction * b);
        }
        entered |= inside;
        s = next;
    }
    None
}
