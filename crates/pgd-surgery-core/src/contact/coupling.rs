//! Everything that ties a scene's organs together in one tick: the master's contact with each
//! pointshell organ and the attachments. The caller hands in each organ's modal
//! coefficients and loads, calls [`Coupling::tick`], and writes each organ's coupling back
//! into its [`Deformation`]. Nothing is allocated once set up.

use std::ops::Range;
use std::path::Path;
use std::sync::Arc;

use nalgebra::Vector3;

use super::modal_rows::{concatenate, step_ranges};
use super::pair::{PairOutput, PairSide, PenaltySettings};
use super::pose::OrganPose;
use super::{
    Attachment, ContactError, ContactPair, ContactSurface, DistanceField, DistanceSettings,
    FieldOrigin, NearField, Pointshell, PointshellDensity, ToolContact, ToolHold,
};
use crate::pgd::{Deformation, PatchLoad, PointLoad, RigidCarry, Vademecum};

/// Which organ is the master, and how the coupling is set up.
#[derive(Clone, Debug, PartialEq)]
pub struct CouplingSettings {
    /// The organ carrying the distance field (paper 000: the gallbladder).
    pub master: String,
    pub distance: DistanceSettings,
    pub pointshell: PointshellDensity,
    pub penalty: PenaltySettings,
}

impl Default for CouplingSettings {
    fn default() -> Self {
        Self {
            master: "gallbladder".into(),
            distance: DistanceSettings::default(),
            pointshell: PointshellDensity::default(),
            penalty: PenaltySettings::default(),
        }
    }
}

/// An attachment by organ names and the carrier's interface positions.
#[derive(Clone, Debug, PartialEq)]
pub struct AttachmentSpec {
    pub carrier: String,
    pub carried: String,
    pub interface: Vec<usize>,
}

#[derive(Clone)]
struct CoupledOrgan {
    steps: Vec<Range<usize>>,
    alpha: Vec<f32>,
    coupling: Vec<f64>,
    coupling_points: Vec<PointLoad>,
    coupling_force_n: Vector3<f64>,
    carry: RigidCarry,
    hold: ToolHold,
}

#[derive(Clone)]
pub struct Coupling {
    pub pairs: Vec<ContactPair>,
    pub attachments: Vec<Attachment>,
    organs: Vec<CoupledOrgan>,
    /// The master's index and its near-field displacement, where it has pairs.
    master: Option<(usize, NearField)>,
}

impl Coupling {
    /// A copy whose buffers have room for what the tick puts in them (a plain clone keeps
    /// only their contents), so that the haptic thread never grows them.
    /// `organs` are the scene's, in the coupling's order.
    pub fn clone_reserved(&self, organs: &[(String, Arc<Vademecum>)]) -> Self {
        let mut coupling = self.clone();
        coupling.pairs.iter_mut().for_each(ContactPair::reserve);
        let shells: usize = coupling.pairs.iter().map(ContactPair::node_count).sum();
        for (organ, (_, vademecum)) in coupling.organs.iter_mut().zip(organs) {
            organ.alpha.reserve(vademecum.total_modes());
            organ.coupling_points.reserve(shells);
            organ.hold.reserve(vademecum);
        }
        coupling
    }

    /// Sets up the coupling of `organs` (names and vademecums, the scene's order): the master's
    /// distance field, a pair with every organ not attached to it whose boundary comes within
    /// the field's lattice, and the attachments. No master in the scene: no contact pairs.
    /// The field is read from `field_file` when it holds this master's (and built and saved
    /// there otherwise: the returned origin says which), or built in memory without one.
    pub fn new(
        organs: &[(String, Arc<Vademecum>)],
        attachments: &[AttachmentSpec],
        settings: &CouplingSettings,
        field_file: Option<&Path>,
    ) -> Result<(Self, Option<FieldOrigin>), ContactError> {
        let index = |name: &str| organs.iter().position(|(n, _)| n == name);
        let attachments: Vec<Attachment> = attachments
            .iter()
            .filter_map(|a| {
                let (carrier, carried) = (index(&a.carrier)?, index(&a.carried)?);
                Attachment::new(carrier, carried, &organs[carrier].1, &a.interface)
            })
            .collect();
        let attached = |x: usize, y: usize| {
            attachments
                .iter()
                .any(|a| (a.carrier, a.carried) == (x, y) || (a.carrier, a.carried) == (y, x))
        };
        let mut pairs = Vec::new();
        let mut origin = None;
        let mut near = None;
        if let Some(master) = index(&settings.master) {
            let master_vademecum = &organs[master].1;
            let surface = ContactSurface::new(master_vademecum)?;
            let field = match field_file {
                Some(path) => {
                    let (field, how) = DistanceField::load_or_build(
                        master_vademecum,
                        &surface,
                        &settings.distance,
                        path,
                    );
                    origin = Some(how);
                    field
                }
                None => DistanceField::build(master_vademecum, &surface, &settings.distance),
            };
            let field = Arc::new(field);
            for (shell, (_, shell_vademecum)) in organs.iter().enumerate() {
                if shell == master || attached(master, shell) {
                    continue;
                }
                let nodes = Pointshell::new(
                    shell_vademecum,
                    master_vademecum,
                    &surface,
                    &field,
                    settings.pointshell,
                );
                if nodes.is_empty() {
                    continue;
                }
                let side = |organ: usize, vademecum: &Arc<Vademecum>| PairSide {
                    organ,
                    vademecum: vademecum.clone(),
                };
                pairs.push(ContactPair::new(
                    side(master, master_vademecum),
                    side(shell, shell_vademecum),
                    field.clone(),
                    nodes,
                    &settings.penalty,
                ));
            }
            if !pairs.is_empty() {
                near = Some((master, NearField::new(master_vademecum.clone())));
            }
        }
        let organs = organs
            .iter()
            .map(|(_, v)| CoupledOrgan {
                steps: step_ranges(v),
                alpha: Vec::with_capacity(v.total_modes()),
                coupling: vec![0.0; v.total_modes()],
                coupling_points: Vec::new(),
                coupling_force_n: Vector3::zeros(),
                carry: RigidCarry::default(),
                hold: ToolHold::default(),
            })
            .collect();
        let coupling = Self {
            pairs,
            attachments,
            organs,
            master: near,
        };
        Ok((coupling, origin))
    }

    /// Whether it couples anything at all.
    pub fn is_empty(&self) -> bool {
        self.pairs.is_empty() && self.attachments.is_empty()
    }

    /// Takes organ `index`'s state for this tick: its coefficients (the coupling of the last
    /// tick included) plus `moved`, what its motion adds to its first load step's coefficients
    /// (empty for an organ that does not move), and the master's loads for their near-field
    /// corrections.
    pub fn read(&mut self, index: usize, deformation: &Deformation, moved: &[f64]) {
        let organ = &mut self.organs[index];
        concatenate(&deformation.coefficients, &mut organ.alpha);
        for (a, &m) in organ.alpha.iter_mut().zip(moved) {
            *a += m as f32;
        }
        if let Some((_, near)) = self.master.as_mut().filter(|(m, _)| *m == index) {
            near.set_loads(&deformation.loads);
        }
    }

    /// Takes how the tool holds organ `index` this tick: it presses as `contact` with `load`,
    /// or not at all.
    pub fn hold(&mut self, index: usize, contact: Option<&ToolContact>, load: &PatchLoad) {
        let hold = &mut self.organs[index].hold;
        match contact {
            Some(contact) => hold.hold(contact, load),
            None => hold.release(),
        }
    }

    /// One tick of every attachment and pair.
    pub fn tick(&mut self) {
        for organ in &mut self.organs {
            organ.coupling.fill(0.0);
            organ.coupling_points.clear();
            organ.coupling_force_n = Vector3::zeros();
            organ.carry = RigidCarry::default();
            organ.hold.moved_m = Vector3::zeros();
        }
        for a in &self.attachments {
            self.organs[a.carried].carry = a.carry(&self.organs[a.carrier].alpha);
        }
        for pair in &mut self.pairs {
            let (master, shell) = two_mut(&mut self.organs, pair.master, pair.shell);
            pair.tick(
                OrganPose {
                    alpha: &master.alpha,
                    carry: &master.carry,
                },
                OrganPose {
                    alpha: &shell.alpha,
                    carry: &shell.carry,
                },
                self.master.as_mut().map(|(_, near)| near),
                PairOutput {
                    master: &mut master.coupling,
                    shell: &mut shell.coupling,
                    master_points: &mut master.coupling_points,
                    shell_points: &mut shell.coupling_points,
                    master_hold: &mut master.hold,
                    shell_hold: &mut shell.hold,
                },
            );
            let force = pair.report().force_on_shell_n;
            shell.coupling_force_n += force;
            master.coupling_force_n -= force;
        }
    }

    /// Organ `index`'s pose this tick: its coefficients as [`Self::read`] took them and, once
    /// [`Self::tick`] has run, the carry of the organ it hangs from.
    pub fn pose(&self, index: usize) -> OrganPose<'_> {
        let organ = &self.organs[index];
        OrganPose {
            alpha: &organ.alpha,
            carry: &organ.carry,
        }
    }

    /// Adds to organ `index`'s coupling of this tick (after [`Self::tick`]) loads another
    /// organ puts on it beyond contact, spread over an area (a bed's ties): the coefficients
    /// of its linear load step, `linear` (one per mode of step 0), and their sum `force_n`.
    /// They have no point load: a traction spread over an area has no dimple of its own for
    /// the near field to draw.
    pub fn add_linear_load(&mut self, index: usize, linear: &[f64], force_n: &Vector3<f64>) {
        let organ = &mut self.organs[index];
        let step = organ.steps[0].clone();
        (organ.coupling[step].iter_mut())
            .zip(linear)
            .for_each(|(c, l)| *c += l);
        organ.coupling_force_n += force_n;
    }

    /// How far (m) this tick's contact forces move the surface under the tool holding organ
    /// `index`: the tool's load follows it in the same tick (`super::hold`).
    pub fn tool_moved_m(&self, index: usize) -> Vector3<f64> {
        self.organs[index].hold.moved_m()
    }

    /// Room in `deformation` (an organ's of this coupling) for every contact load the tick
    /// can hand it.
    pub fn reserve_output(&self, deformation: &mut Deformation) {
        let points: usize = self.pairs.iter().map(ContactPair::node_count).sum();
        deformation.coupling_points.reserve(points);
    }

    /// Hands organ `index` its coupling of this tick.
    pub fn write(&self, index: usize, deformation: &mut Deformation) {
        let organ = &self.organs[index];
        for (step, range) in organ.steps.iter().enumerate() {
            deformation.coupling[step].copy_from_slice(&organ.coupling[range.clone()]);
        }
        deformation
            .coupling_points
            .clone_from(&organ.coupling_points);
        deformation.coupling_force_n = organ.coupling_force_n;
        deformation.carry = organ.carry;
    }
}

/// Two distinct elements of a slice, both mutable.
fn two_mut<T>(items: &mut [T], a: usize, b: usize) -> (&mut T, &mut T) {
    assert_ne!(a, b, "an organ is not coupled to itself");
    if a < b {
        let (low, high) = items.split_at_mut(b);
        (&mut low[a], &mut high[0])
    } else {
        let (low, high) = items.split_at_mut(a);
        (&mut high[0], &mut low[b])
    }
}
