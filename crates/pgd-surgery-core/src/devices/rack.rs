//! The instruments a trainee works with, one in the device's hand at a time: a laparoscopic
//! scenario may give each port its own (a grasper to hold, a scalpel to cut), and the device's
//! second button puts the one in hand down and takes up the next, as a surgeon changes hands
//! or instruments. Changing is allowed only while the instrument touches nothing, so the hand
//! never feels a step of force. A device has one workspace for all of them, so the change
//! re-indexes it (as a haptic device's clutch does): the taken instrument's handle starts where
//! it was put down, and the device's motion from where the hand is moves it from there.

use nalgebra::Vector3;

use super::Fulcrum;

/// The device button (its bit in `DeviceSample::buttons`) that changes the instrument.
pub const CHANGE_BUTTON: u32 = 1 << 1;

/// The most instruments a scenario may give the trainee.
pub const MAX_INSTRUMENTS: usize = 4;

/// How far (m) an instrument taken up for the first time reaches into the abdomen from its port.
const FIRST_REACH_M: f64 = 0.03;

/// What an instrument does besides pressing.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Action {
    #[default]
    Press,
    /// Its jaws close on the device's first button.
    Grasp,
    /// Its blade parts the tissue it presses.
    Cut,
    /// An electrocautery hook: the device's first button applies its energy.
    Cauterize(crate::dissection::Cautery),
    /// A clip applier whose jaws, this long (m), close on the device's first button and
    /// leave a clip across the tube between them.
    Clip { jaw_m: f64 },
    /// Scissors whose blades, this long (m), close on the device's first button and divide
    /// the tube between them.
    Divide { blade_m: f64 },
}

/// An instrument: what it does, and the port it goes through (none: open surgery, the device
/// moves its tip).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Instrument {
    pub action: Action,
    pub port: Option<Fulcrum>,
}

/// The instruments and the one in hand.
#[derive(Clone, Debug, PartialEq)]
pub struct Rack {
    instruments: Vec<Instrument>,
    in_hand: usize,
    /// Where each instrument's handle was put down (m, the scene's frame); none: never taken
    /// up, or in hand.
    put_down: [Option<Vector3<f64>>; MAX_INSTRUMENTS],
    /// Added to the device's position (in the scene) to place the handle in hand (m).
    offset_m: Vector3<f64>,
    /// The device's buttons at the last tick, to see the change button go down.
    buttons: u32,
}

impl Default for Rack {
    /// One probe, for open surgery.
    fn default() -> Self {
        Self::new(&[])
    }
}

impl Rack {
    /// The instruments, the first in hand. At most [`MAX_INSTRUMENTS`] are kept (a scenario
    /// that loaded has no more), and an empty list is one probe for open surgery.
    pub fn new(instruments: &[Instrument]) -> Self {
        let mut instruments: Vec<Instrument> =
            instruments.iter().take(MAX_INSTRUMENTS).copied().collect();
        if instruments.is_empty() {
            instruments.push(Instrument::default());
        }
        Self {
            instruments,
            in_hand: 0,
            put_down: [None; MAX_INSTRUMENTS],
            offset_m: Vector3::zeros(),
            buttons: 0,
        }
    }

    /// The instrument in hand, and its place in the list.
    pub fn in_hand(&self) -> (usize, &Instrument) {
        (self.in_hand, &self.instruments[self.in_hand])
    }

    /// Where the device's position in the scene, `device_m`, puts the handle in hand.
    pub fn handle_m(&self, device_m: &Vector3<f64>) -> Vector3<f64> {
        device_m + self.offset_m
    }

    /// Added to the device's position to place the handle in hand (m).
    pub fn offset_m(&self) -> Vector3<f64> {
        self.offset_m
    }

    /// Where instrument `index` was put down (its handle, m), unless it is in hand or was never
    /// taken up.
    pub fn put_down(&self, index: usize) -> Option<Vector3<f64>> {
        self.put_down.get(index).copied().flatten()
    }

    /// Takes the device's buttons and position (in the scene) at one tick. When the change
    /// button goes down while the instrument in hand is `free` (touching and holding nothing;
    /// asked only then), puts it down where its handle is and takes up the next, whose tip aims
    /// from its port at `tip_m` (the one put down) the first time. Returns whether the
    /// instrument changed.
    pub fn take(
        &mut self,
        buttons: u32,
        device_m: &Vector3<f64>,
        tip_m: &Vector3<f64>,
        free: impl FnOnce() -> bool,
    ) -> bool {
        let pressed = buttons & CHANGE_BUTTON != 0 && self.buttons & CHANGE_BUTTON == 0;
        self.buttons = buttons;
        if !pressed || self.instruments.len() < 2 || !free() {
            return false;
        }
        self.put_down[self.in_hand] = Some(self.handle_m(device_m));
        self.in_hand = (self.in_hand + 1) % self.instruments.len();
        let next = &self.instruments[self.in_hand];
        let handle = self.put_down[self.in_hand]
            .take()
            .or_else(|| next.port.and_then(|port| first_handle(&port, tip_m)))
            .unwrap_or(*device_m);
        self.offset_m = handle - device_m;
        true
    }
}

/// The handle of an instrument first taken up through `port`: its tip [`FIRST_REACH_M`] in,
/// towards `aim_m`.
fn first_handle(port: &Fulcrum, aim_m: &Vector3<f64>) -> Option<Vector3<f64>> {
    let towards = (aim_m - port.port_m).try_normalize(1e-9)?;
    port.handle_for(&(port.port_m + towards * FIRST_REACH_M))
}
