//! The laparoscope: a camera on a straight optic through its own port. The optic pivots about
//! the port like any instrument; its objective looks along the shaft (0°) or at an angle to it
//! (30°, 45°), towards a side set by the optic's roll, so that rolling an angled scope looks
//! around without moving it. The image is round, of the optic's field of view: a point is in
//! view when it lies within half that angle of the viewing direction, in front of the lens.
//!
//! The camera head, held level by the assistant, keeps the image's up towards the patient's
//! front and head whatever the optic's roll, as a camera head on a rolled optic does.

use std::sync::{Mutex, PoisonError, TryLockError};

use nalgebra::{Rotation3, Unit, Vector3};

/// The optic may not be withdrawn closer to the port than this (m): its lens stays inside.
pub const MIN_INSIDE_M: f64 = 0.01;

/// The optic as it is made and where it enters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Laparoscope {
    /// Where the optic crosses the abdominal wall (m, the scene's frame).
    pub port_m: Vector3<f64>,
    /// The angle between the shaft and the viewing direction (rad): 0 or 30° in practice.
    pub angle_rad: f64,
    /// The field of view, across the round image (rad).
    pub fov_rad: f64,
}

/// Where the optic is: its shaft's direction into the body, how far in its lens is, and its
/// roll about the shaft.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScopePose {
    pub axis: Unit<Vector3<f64>>,
    pub inside_m: f64,
    /// The side the angled objective looks towards, about the shaft (rad): 0 towards the
    /// patient's head, growing towards their front's right-hand side of the shaft.
    pub roll_rad: f64,
}

/// What the camera sees from: its eye (the lens), its viewing direction, and the image's up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    pub eye_m: Vector3<f64>,
    pub forward: Unit<Vector3<f64>>,
    pub up: Unit<Vector3<f64>>,
}

/// How the optic is steered in one step: about the port across the image (rad, right and up
/// as the image shows them), in and out along the shaft (m), and rolled (rad).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Steer {
    pub right_rad: f64,
    pub up_rad: f64,
    pub in_m: f64,
    pub roll_rad: f64,
}

/// The scene's head (+z) and front (+y): the references for the roll and the image's up.
const HEAD: Vector3<f64> = Vector3::new(0.0, 0.0, 1.0);
const FRONT: Vector3<f64> = Vector3::new(0.0, 1.0, 0.0);

/// Two unit vectors across `axis`: the first towards the head (or the front when the shaft
/// points at the head), the second completing a right-handed frame with the axis.
fn across(axis: &Unit<Vector3<f64>>) -> (Vector3<f64>, Vector3<f64>) {
    let reference = if axis.dot(&HEAD).abs() < 0.99 {
        HEAD
    } else {
        FRONT
    };
    let first = (reference - axis.into_inner() * axis.dot(&reference)).normalize();
    (first, axis.cross(&first))
}

impl Laparoscope {
    /// The lens's position for `pose`.
    pub fn eye_m(&self, pose: &ScopePose) -> Vector3<f64> {
        self.port_m + pose.axis.into_inner() * pose.inside_m
    }

    /// The viewing direction for `pose`: the shaft tilted by the optic's angle towards its roll.
    pub fn forward(&self, pose: &ScopePose) -> Unit<Vector3<f64>> {
        let (first, second) = across(&pose.axis);
        let side = first * pose.roll_rad.cos() + second * pose.roll_rad.sin();
        let (sin, cos) = self.angle_rad.sin_cos();
        Unit::new_normalize(pose.axis.into_inner() * cos + side * sin)
    }

    /// The camera for `pose`, its image's up the patient's front and head as far as the
    /// viewing direction leaves them across it.
    pub fn view(&self, pose: &ScopePose) -> View {
        let forward = self.forward(pose);
        let reference = (FRONT + HEAD).normalize();
        let up = reference - forward.into_inner() * forward.dot(&reference);
        let up = Unit::try_new(up, 1e-6).unwrap_or_else(|| {
            Unit::new_normalize(HEAD - forward.into_inner() * forward.dot(&HEAD))
        });
        View {
            eye_m: self.eye_m(pose),
            forward,
            up,
        }
    }

    /// The pose whose view is centred on `target_m` from `distance_m` away, the objective
    /// rolled towards `roll_rad` as near as the target allows. In the plane of port, lens and
    /// target the angle at the lens is π − angle, which fixes how deep the lens is
    /// (`D² = L² + d² + 2 L d cos α`) and how far the shaft turns from the target (`sin β =
    /// d sin α / D`). `None` when the target is within `distance_m` of the port.
    pub fn aim(
        &self,
        target_m: &Vector3<f64>,
        distance_m: f64,
        roll_rad: f64,
    ) -> Option<ScopePose> {
        let to_target = target_m - self.port_m;
        let reach_m = to_target.norm();
        let towards = Unit::try_new(to_target, 1e-9)?;
        let (sin_a, cos_a) = self.angle_rad.sin_cos();
        let room = reach_m * reach_m - (distance_m * sin_a).powi(2);
        let inside_m = -distance_m * cos_a + room.max(0.0).sqrt();
        if inside_m < MIN_INSIDE_M {
            return None;
        }
        let (first, second) = across(&towards);
        let side = first * roll_rad.cos() + second * roll_rad.sin();
        let turn = (distance_m * sin_a / reach_m).clamp(-1.0, 1.0).asin();
        let axis = Unit::new_normalize(towards.into_inner() * turn.cos() - side * turn.sin());
        let eye = self.port_m + axis.into_inner() * inside_m;
        Some(ScopePose {
            axis,
            inside_m,
            roll_rad: self.roll_towards(&axis, &(target_m - eye)),
        })
    }

    /// The roll that tilts the objective of a shaft along `axis` towards `direction`.
    fn roll_towards(&self, axis: &Unit<Vector3<f64>>, direction: &Vector3<f64>) -> f64 {
        let (first, second) = across(axis);
        direction.dot(&second).atan2(direction.dot(&first))
    }

    /// Whether `point_m` is in the round image of `pose`'s view.
    pub fn sees(&self, pose: &ScopePose, point_m: &Vector3<f64>) -> bool {
        let from_eye = point_m - self.eye_m(pose);
        let distance = from_eye.norm();
        distance > 0.0 && from_eye.dot(&self.forward(pose)) >= distance * (self.fov_rad / 2.0).cos()
    }

    /// `pose` moved by `steer`: the shaft pivots about the port (the image follows the way
    /// the camera head is turned: a step to the right brings what was right of centre to the
    /// centre), goes in or out (never closer than [`MIN_INSIDE_M`]), and rolls. The roll is
    /// carried over the pivot by the side it looks towards, so pivoting does not swing it.
    pub fn steer(&self, pose: &ScopePose, steer: &Steer) -> ScopePose {
        let view = self.view(pose);
        let right = view.forward.cross(&view.up);
        let pivot = Rotation3::from_axis_angle(&view.up, -steer.right_rad)
            * Rotation3::from_axis_angle(&Unit::new_normalize(right), steer.up_rad);
        let side = self.forward(pose).into_inner() - pose.axis.into_inner();
        let axis = Unit::new_normalize(pivot * pose.axis.into_inner());
        ScopePose {
            axis,
            inside_m: (pose.inside_m + steer.in_m).max(MIN_INSIDE_M),
            roll_rad: self.roll_towards(&axis, &(pivot * side)) + steer.roll_rad,
        }
    }
}

/// The optic's pose, shared between the window that steers it and the haptic loop that scores
/// what is in view. The loop only tries the lock: when the window holds it, the loop keeps the
/// pose it read last, and never waits.
#[derive(Debug)]
pub struct ScopeHandle(Mutex<ScopePose>);

impl ScopeHandle {
    pub fn new(pose: ScopePose) -> Self {
        Self(Mutex::new(pose))
    }

    pub fn set(&self, pose: ScopePose) {
        *self.0.lock().unwrap_or_else(PoisonError::into_inner) = pose;
    }

    pub fn get(&self) -> ScopePose {
        *self.0.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Sets the pose, unless someone holds the lock this instant (the haptic loop moving a
    /// scripted camera: it tries again next tick).
    pub fn try_set(&self, pose: ScopePose) {
        match self.0.try_lock() {
            Ok(mut held) => *held = pose,
            Err(TryLockError::Poisoned(poisoned)) => *poisoned.into_inner() = pose,
            Err(TryLockError::WouldBlock) => {}
        }
    }

    /// The pose, unless someone holds the lock this instant.
    pub fn try_get(&self) -> Option<ScopePose> {
        match self.0.try_lock() {
            Ok(pose) => Some(*pose),
            Err(TryLockError::Poisoned(poisoned)) => Some(*poisoned.into_inner()),
            Err(TryLockError::WouldBlock) => None,
        }
    }
}

/// A camera moved by the scenario rather than the trainee: at each key time the view is
/// centred on a point from a distance, and between keys both go linearly from one key to the
/// next (the optic aimed anew each time, at the script's roll). Before the first key the view
/// is the first's, after the last the last's.
#[derive(Clone, Debug, PartialEq)]
pub struct ScopeScript {
    /// (time s, point looked at m, distance m), in time order.
    pub keys: Vec<(f64, Vector3<f64>, f64)>,
    pub roll_rad: f64,
}

impl ScopeScript {
    /// The point looked at and the distance at `time_s`.
    pub fn look_at(&self, time_s: f64) -> Option<(Vector3<f64>, f64)> {
        let after = self.keys.iter().position(|k| k.0 > time_s);
        let (from, to) = match after {
            Some(0) => (self.keys.first()?, self.keys.first()?),
            Some(k) => (&self.keys[k - 1], &self.keys[k]),
            None => (self.keys.last()?, self.keys.last()?),
        };
        let span = to.0 - from.0;
        let t = if span > 0.0 {
            ((time_s - from.0) / span).clamp(0.0, 1.0)
        } else {
            0.0
        };
        Some((from.1.lerp(&to.1, t), from.2 + (to.2 - from.2) * t))
    }

    /// Where `scope` is at `time_s`; `None` when its port is too near the point looked at.
    pub fn pose_at(&self, scope: &Laparoscope, time_s: f64) -> Option<ScopePose> {
        let (target, distance_m) = self.look_at(time_s)?;
        scope.aim(&target, distance_m, self.roll_rad)
    }
}
