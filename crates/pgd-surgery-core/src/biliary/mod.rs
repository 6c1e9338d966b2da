//! The extrahepatic biliary tree of a cholecystectomy: the cystic duct, the common duct and
//! the cystic artery generated at published sizes as rods ([`anatomy`]), wrapped in the fat
//! of the hepatocystic triangle ([`fat`]); clips closed across them ([`clip`]), their
//! division by scissors ([`division`]) and what an open stump lets out ([`leak`]); and the
//! critical view of safety judged from the scene ([`critical_view`]), and what it was judged on
//! kept for the debrief ([`view_record`]). `docs/biliary.md` has
//! the model and its sources.

pub mod anatomy;
pub mod clip;
pub mod critical_view;
pub mod division;
pub mod fat;
pub mod geometry;
pub mod leak;
pub mod view_record;

pub use anatomy::{Anatomy, AnatomyError, ArteryCourse, BiliaryTree, Part, Structure, Tube};
pub use clip::{Clip, Crossing};
pub use critical_view::{CriticalView, CriticalViewRule, Entering};
pub use division::{Division, DivisionOutcome};
pub use fat::{FatStrand, Triangle, TriangleFat};
pub use geometry::Segment;
pub use leak::{FlowLaw, Fluid, Leak, Side};
pub use view_record::{Judging, OrganPatch, ViewRecord};
