//! What each organ brings to a contact pair's tick: its modal coefficients and the rigid carry
//! of the organ it hangs from. Read by the pair's solve and by the clearance alike.

use crate::pgd::RigidCarry;

/// What an organ brings to the contact stage this tick.
#[derive(Clone, Copy, Debug)]
pub struct OrganPose<'a> {
    /// Modal coefficients, all load steps concatenated.
    pub alpha: &'a [f32],
    pub carry: &'a RigidCarry,
}
