//! An incision as data: the surface the blade sweeps, built segment by segment as the blade
//! advances. A segment runs along the organ's surface from one point to the next, and the
//! blade reaches `depth_m` into the tissue along its direction: the segment sweeps a planar
//! quadrilateral, the *cut face*. A straight incision is one face that grows as segments are
//! added; a path that turns starts a new face at each turn.

use nalgebra::{Point3, Unit, Vector3};

use super::CutError;

/// Shortest segment a blade step may make (m): below it the cut face's plane is not defined.
pub const MIN_SEGMENT_M: f64 = 1e-5;

/// How far the cut face reaches past the surface it starts on (a fraction of its depth), so
/// that the surface nodes on the incision's line lie inside the face rather than on its edge.
const SURFACE_MARGIN: f64 = 0.05;

/// Two segments whose directions differ by less than this (radians) lie on one face.
const COLLINEAR_RAD: f64 = 1e-6;

/// One planar face of a cut: points `origin + t · along + s · down` for `t ∈ [0, length_m]`,
/// `s ∈ [−margin_m, depth_m]`, with `normal = along × down`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CutFace {
    pub origin: Point3<f64>,
    pub along: Unit<Vector3<f64>>,
    pub down: Unit<Vector3<f64>>,
    pub normal: Unit<Vector3<f64>>,
    pub length_m: f64,
    pub depth_m: f64,
    pub margin_m: f64,
}

impl CutFace {
    /// The face a blade sweeps from `from` to `to`, reaching `depth_m` along `blade` (which
    /// need not be square to the path: its part along the path is dropped).
    pub fn swept(
        from: Point3<f64>,
        to: Point3<f64>,
        blade: Vector3<f64>,
        depth_m: f64,
    ) -> Result<Self, CutError> {
        let path = to - from;
        let length_m = path.norm();
        if !(length_m.is_finite() && length_m >= MIN_SEGMENT_M) {
            return Err(CutError::Degenerate(format!(
                "a segment of {:.3} mm (at least {} mm)",
                length_m * 1e3,
                MIN_SEGMENT_M * 1e3
            )));
        }
        if !(depth_m.is_finite() && depth_m > 0.0) {
            return Err(CutError::Degenerate(format!(
                "a depth of {depth_m} m (positive)"
            )));
        }
        let along = Unit::new_normalize(path);
        let square = blade - along.into_inner() * blade.dot(&along);
        let finite = blade.iter().all(|c| c.is_finite());
        if !finite || square.norm() <= 1e-6 * blade.norm().max(f64::MIN_POSITIVE) {
            return Err(CutError::Degenerate(
                "a blade along its own path: the cut face has no plane".into(),
            ));
        }
        let down = Unit::new_normalize(square);
        Ok(Self {
            origin: from,
            along,
            down,
            normal: Unit::new_normalize(along.cross(&down)),
            length_m,
            depth_m,
            margin_m: SURFACE_MARGIN * depth_m,
        })
    }

    /// Signed distance of `p` to the face's plane (m), positive on the `normal` side.
    pub fn signed_distance(&self, p: &Point3<f64>) -> f64 {
        self.normal.dot(&(p - self.origin))
    }

    /// Whether `p`, projected on the plane, falls inside the face, `tolerance_m` included.
    pub fn covers(&self, p: &Point3<f64>, tolerance_m: f64) -> bool {
        let d = p - self.origin;
        let t = self.along.dot(&d);
        let s = self.down.dot(&d);
        (-tolerance_m..=self.length_m + tolerance_m).contains(&t)
            && (-self.margin_m - tolerance_m..=self.depth_m + tolerance_m).contains(&s)
    }

    /// The face lengthened along its path to end at `to`, if `to` continues it in a straight
    /// line at the same depth.
    fn continued(&self, to: Point3<f64>, depth_m: f64) -> Option<Self> {
        let step = to - (self.origin + self.along.into_inner() * self.length_m);
        let straight = step.norm() >= MIN_SEGMENT_M
            && step.normalize().dot(&self.along) > COLLINEAR_RAD.cos()
            && (depth_m - self.depth_m).abs() <= 1e-9 * self.depth_m;
        straight.then(|| Self {
            length_m: (to - self.origin).dot(&self.along),
            ..*self
        })
    }
}

/// An incision: the faces its blade has swept so far, and where the blade is.
#[derive(Clone, Debug, PartialEq)]
pub struct Incision {
    faces: Vec<CutFace>,
    tip: Point3<f64>,
    blade: Vector3<f64>,
    depth_m: f64,
}

impl Incision {
    /// The blade set on the surface at `start`, pointing along `blade` into the tissue, cutting
    /// `depth_m` deep. Nothing is cut until it moves.
    pub fn start(start: Point3<f64>, blade: Vector3<f64>, depth_m: f64) -> Self {
        Self {
            faces: Vec::new(),
            tip: start,
            blade,
            depth_m,
        }
    }

    /// One straight incision from `from` to `to`.
    pub fn straight(
        from: Point3<f64>,
        to: Point3<f64>,
        blade: Vector3<f64>,
        depth_m: f64,
    ) -> Result<Self, CutError> {
        let mut incision = Self::start(from, blade, depth_m);
        incision.advance(to)?;
        Ok(incision)
    }

    /// The blade moves on to `to`: a straight continuation lengthens the last face, a turn
    /// starts a new one. A step too short to define a plane is refused and changes nothing.
    pub fn advance(&mut self, to: Point3<f64>) -> Result<(), CutError> {
        if let Some(longer) = self
            .faces
            .last()
            .and_then(|face| face.continued(to, self.depth_m))
        {
            *self.faces.last_mut().expect("checked") = longer;
        } else {
            let face = CutFace::swept(self.tip, to, self.blade, self.depth_m)?;
            self.faces.push(face);
        }
        self.tip = to;
        Ok(())
    }

    pub fn faces(&self) -> &[CutFace] {
        &self.faces
    }
}
