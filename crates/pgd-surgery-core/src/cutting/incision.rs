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

/// One planar face of a cut: the plane through `origin` with unit `normal`, and the part of
/// it the cut covers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CutFace {
    pub origin: Point3<f64>,
    pub normal: Unit<Vector3<f64>>,
    pub extent: Extent,
}

/// Which part of its plane a face covers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Extent {
    /// Swept by a blade along a straight path: `origin + t · along + s · down` for
    /// `t ∈ [0, length_m]`, `s ∈ [−margin_m, depth_m]`.
    Swept {
        along: Unit<Vector3<f64>>,
        down: Unit<Vector3<f64>>,
        length_m: f64,
        depth_m: f64,
        margin_m: f64,
    },
    /// A radial incision of a spherical shell (the cornea): in the plane through the shell's
    /// axis, from `from_m` to `to_m` away from the axis along `radial`, and from the anterior
    /// sphere (centre `centre`, radius `anterior_m`) down to `depth_m` below it.
    Meridian {
        radial: Unit<Vector3<f64>>,
        from_m: f64,
        to_m: f64,
        centre: Point3<f64>,
        anterior_m: f64,
        depth_m: f64,
        margin_m: f64,
    },
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
        check_depth(depth_m)?;
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
            normal: Unit::new_normalize(along.cross(&down)),
            extent: Extent::Swept {
                along,
                down,
                length_m,
                depth_m,
                margin_m: SURFACE_MARGIN * depth_m,
            },
        })
    }

    /// A radial incision of the spherical shell whose anterior sphere has centre `centre` and
    /// radius `anterior_m`, about the axis through `centre` along `axis`: at `angle_rad` round
    /// the axis (from the direction `axis × ŷ`, or `axis × x̂` for an axis along y), from
    /// `from_m` to `to_m` away from the axis, `depth_m` deep below the anterior surface.
    pub fn meridian(
        centre: Point3<f64>,
        anterior_m: f64,
        axis: Unit<Vector3<f64>>,
        angle_rad: f64,
        from_m: f64,
        to_m: f64,
        depth_m: f64,
    ) -> Result<Self, CutError> {
        check_depth(depth_m)?;
        if !(from_m.is_finite()
            && to_m.is_finite()
            && 0.0 <= from_m
            && from_m + MIN_SEGMENT_M <= to_m)
        {
            return Err(CutError::Degenerate(format!(
                "a radial incision from {:.3} to {:.3} mm off the axis",
                from_m * 1e3,
                to_m * 1e3
            )));
        }
        let x = Unit::new_normalize(
            axis.cross(&Vector3::y())
                .try_normalize(1e-9)
                .unwrap_or_else(|| axis.cross(&Vector3::x())),
        );
        let y = axis.cross(&x);
        let radial = Unit::new_normalize(x.into_inner() * angle_rad.cos() + y * angle_rad.sin());
        Ok(Self {
            origin: centre,
            normal: Unit::new_normalize(axis.cross(&radial)),
            extent: Extent::Meridian {
                radial,
                from_m,
                to_m,
                centre,
                anterior_m,
                depth_m,
                margin_m: SURFACE_MARGIN * depth_m,
            },
        })
    }

    /// Signed distance of `p` to the face's plane (m), positive on the `normal` side.
    pub fn signed_distance(&self, p: &Point3<f64>) -> f64 {
        self.normal.dot(&(p - self.origin))
    }

    /// Whether `p`, projected on the plane, falls inside the face, `tolerance_m` included.
    pub fn covers(&self, p: &Point3<f64>, tolerance_m: f64) -> bool {
        let within = |v: f64, lo: f64, hi: f64| (lo - tolerance_m..=hi + tolerance_m).contains(&v);
        match self.extent {
            Extent::Swept {
                along,
                down,
                length_m,
                depth_m,
                margin_m,
            } => {
                let d = p - self.origin;
                within(along.dot(&d), 0.0, length_m) && within(down.dot(&d), -margin_m, depth_m)
            }
            Extent::Meridian {
                radial,
                from_m,
                to_m,
                centre,
                anterior_m,
                depth_m,
                margin_m,
            } => {
                let below = anterior_m - (p - centre).norm();
                within(radial.dot(&(p - centre)), from_m, to_m) && within(below, -margin_m, depth_m)
            }
        }
    }

    /// Into the tissue along the face at the surface point `p`, and how deep the face
    /// reaches below the surface there (m): the blade's direction for a swept face, towards
    /// the shell's centre for a meridian.
    pub fn inward_at(&self, p: &Point3<f64>) -> (Unit<Vector3<f64>>, f64) {
        match self.extent {
            Extent::Swept { down, depth_m, .. } => (down, depth_m),
            Extent::Meridian {
                centre, depth_m, ..
            } => (
                Unit::try_new(centre - p, 1e-12).unwrap_or(-self.normal),
                depth_m,
            ),
        }
    }

    /// The face's largest dimension (m), for tolerances relative to it.
    pub fn size_m(&self) -> f64 {
        match self.extent {
            Extent::Swept {
                length_m, depth_m, ..
            } => length_m.max(depth_m),
            Extent::Meridian { to_m, depth_m, .. } => to_m.max(depth_m),
        }
    }

    /// The face lengthened along its path to end at `to`, if `to` continues it in a straight
    /// line at the same depth.
    fn continued(&self, to: Point3<f64>, depth: f64) -> Option<Self> {
        let Extent::Swept {
            along,
            length_m,
            depth_m,
            ..
        } = self.extent
        else {
            return None;
        };
        let step = to - (self.origin + along.into_inner() * length_m);
        let straight = step.norm() >= MIN_SEGMENT_M
            && step.normalize().dot(&along) > COLLINEAR_RAD.cos()
            && (depth - depth_m).abs() <= 1e-9 * depth_m;
        let mut longer = *self;
        if let Extent::Swept { length_m, .. } = &mut longer.extent {
            *length_m = (to - self.origin).dot(&along);
        }
        straight.then_some(longer)
    }
}

fn check_depth(depth_m: f64) -> Result<(), CutError> {
    if depth_m.is_finite() && depth_m > 0.0 {
        Ok(())
    } else {
        Err(CutError::Degenerate(format!(
            "a depth of {depth_m} m (positive)"
        )))
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

    /// The blade cuts `depth_m` deep from now on, and the face it is sweeping as deep (the
    /// deeper face covers the shallower one: a cut only grows). Returns that face, or `None`
    /// when `depth_m` is no deeper than the incision already is or no face is swept yet (the
    /// next step then sweeps at the new depth).
    pub fn deepen(&mut self, depth_m: f64) -> Result<Option<CutFace>, CutError> {
        check_depth(depth_m)?;
        if depth_m <= self.depth_m {
            return Ok(None);
        }
        self.depth_m = depth_m;
        let Some(face) = self.faces.last_mut() else {
            return Ok(None);
        };
        if let Extent::Swept {
            depth_m: depth,
            margin_m,
            ..
        } = &mut face.extent
        {
            *depth = depth_m;
            *margin_m = SURFACE_MARGIN * depth_m;
        }
        Ok(Some(*face))
    }

    pub fn faces(&self) -> &[CutFace] {
        &self.faces
    }

    /// The depth (m) the blade cuts.
    pub fn depth_m(&self) -> f64 {
        self.depth_m
    }
}
