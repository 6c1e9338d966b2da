//! Freeing one organ from another: the connective tissue between them as cohesive ties that
//! hold, give and tear ([`cohesive`]), placed where the two organs' surfaces face each other
//! ([`bed`]), their forces each tick answered with the organs' own give ([`solve`]), between
//! two organs of a scene's contact stage ([`tied`]); the hook's energy and the ties it burns
//! ([`cautery`]), and the burns it leaves on the organs' walls instead ([`wall`]); a grasper's
//! pull carried by the freed organ's wall to the ties near its jaws ([`wall_pull`]).
//! `docs/dissection.md` has the model and its sources.

pub mod bed;
pub mod cautery;
pub mod cohesive;
pub mod solve;
pub mod tied;
pub mod wall;
pub mod wall_pull;

pub use bed::{Bed, BedError, FreedSurface, Tie, TieEnds};
pub use cautery::{Cautery, CauteryMode, POWER_RANGE_W, PowerOutOfRange, TieBurns, TissueHeat};
pub use cohesive::{CohesiveError, CohesiveLaw, CohesiveTie};
pub use solve::{TieCompliance, TieConvergence, TieSolve};
pub use tied::{HookOnTies, TiedOrgans, TiedReport};
pub use wall::{BurnMark, BurnSite, MAX_BURN_MARKS, Wall, WallBurn, WallBurns};
pub use wall_pull::{WALL_REACH_M, WallPull, WallPullReport};
