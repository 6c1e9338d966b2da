//! What can go wrong when a reduced dynamic model is made or stepped.

use crate::fem::Law;

#[derive(Debug, thiserror::Error)]
pub enum DynamicsError {
    #[error("the rest stiffness: {0}")]
    Stiffness(#[from] crate::fem::FemError),
    #[error("the subspace has no vectors left once its dependent ones are dropped")]
    EmptyBasis,
    #[error(
        "the {law} law has no polynomial reduced energy: reduced dynamics take the linear or \
         the Kirchhoff–Saint Venant law"
    )]
    UnsupportedLaw { law: &'static str },
    #[error(
        "the step did not converge in {iterations} iterations (last update {update:.2e} relative)"
    )]
    NotConverged { iterations: usize, update: f64 },
    #[error("the state became non-finite")]
    NonFinite,
}

impl DynamicsError {
    pub(super) fn unsupported(law: Law) -> Self {
        Self::UnsupportedLaw { law: law.name() }
    }
}
