//! An instrument through a port in the abdominal wall: the fulcrum effect. The shaft pivots
//! at the port, so the tip moves opposite to the hand across the shaft, scaled by how deep
//! the shaft is in over how far the hand is out, and along the shaft one for one. The force
//! the tissue puts on the tip reaches the hand through the same lever, transposed: across the
//! shaft inverted and scaled by the same ratio, along it unchanged. The two maps are each
//! other's transpose, so the port neither makes nor loses energy (the tests check the power
//! balance).

use nalgebra::{Unit, UnitQuaternion, Vector3};

/// The handle is kept at least this far out of the port (m): at the port itself the lever's
/// ratio has no bound.
pub const MIN_OUTSIDE_M: f64 = 0.02;

/// The axis of a handle, in its own frame, from the hand towards the tip: a handle held
/// upright over a supine patient points down (−y, posterior), and its x is a blade's edge.
pub const HANDLE_AXIS: Vector3<f64> = Vector3::new(0.0, -1.0, 0.0);

/// A straight instrument through a port.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fulcrum {
    /// Where the shaft crosses the abdominal wall (m, the scene's frame).
    pub port_m: Vector3<f64>,
    /// From the handle to the tip (m).
    pub shaft_m: f64,
}

/// Where the instrument is for a handle position: its tip, its unit direction (from the
/// handle towards the tip), and how much of the shaft is outside and inside (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    pub tip_m: Vector3<f64>,
    pub along: Vector3<f64>,
    pub outside_m: f64,
    pub inside_m: f64,
}

impl Fulcrum {
    /// The instrument whose handle is at `handle_m`: the shaft from the handle through the
    /// port; the handle held at least [`MIN_OUTSIDE_M`] out, the tip at most at the port
    /// (none of the shaft inside: the instrument withdrawn). `None` for a handle on the port
    /// (the shaft's direction is then unknown).
    pub fn pose(&self, handle_m: &Vector3<f64>) -> Option<Pose> {
        let to_port = self.port_m - handle_m;
        let along = to_port.try_normalize(1e-9)?;
        let outside_m = to_port
            .norm()
            .clamp(MIN_OUTSIDE_M, self.shaft_m.max(MIN_OUTSIDE_M));
        let inside_m = (self.shaft_m - outside_m).max(0.0);
        Some(Pose {
            tip_m: self.port_m + along * inside_m,
            along,
            outside_m,
            inside_m,
        })
    }

    /// Where the handle must be for the tip to be at `tip_m` (a mouse places the tip, as a
    /// trainee's eye leads a hand): the shaft from the tip back through the port. A tip deeper
    /// than the shaft allows is brought back along it; `None` for a tip on the port.
    pub fn handle_for(&self, tip_m: &Vector3<f64>) -> Option<Vector3<f64>> {
        let from_port = tip_m - self.port_m;
        let along = from_port.try_normalize(1e-9)?;
        let inside_m = from_port
            .norm()
            .min((self.shaft_m - MIN_OUTSIDE_M).max(0.0));
        Some(self.port_m - along * (self.shaft_m - inside_m))
    }

    /// The instrument's orientation through the port for a handle held at `handle`: the
    /// handle's, turned the least that lays its axis ([`HANDLE_AXIS`]) along the shaft. The
    /// shaft sets where the instrument points; the hand's roll of the handle about its own axis
    /// is the instrument's roll about the shaft (a blade's edge, a grasper's jaws).
    pub fn instrument_orientation(
        pose: &Pose,
        handle: &UnitQuaternion<f64>,
    ) -> UnitQuaternion<f64> {
        let axis = handle * HANDLE_AXIS;
        let lay = UnitQuaternion::rotation_between(&axis, &pose.along).unwrap_or_else(|| {
            // Pointing straight back: half a turn about an axis across it.
            UnitQuaternion::from_axis_angle(
                &Unit::new_normalize(handle * Vector3::x()),
                std::f64::consts::PI,
            )
        });
        lay * handle
    }

    /// The force the hand feels (N) for the force `tip_n` the instrument's tip feels, the
    /// instrument at `pose`: along the shaft unchanged, across it inverted and scaled by
    /// `inside / outside`.
    pub fn hand_force(pose: &Pose, tip_n: &Vector3<f64>) -> Vector3<f64> {
        let axial = pose.along * tip_n.dot(&pose.along);
        let across = tip_n - axial;
        axial - across * (pose.inside_m / pose.outside_m)
    }
}
