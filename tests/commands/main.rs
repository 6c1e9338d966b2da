//! The commands' own work, apart from the core they call: option values, `pgd fit`'s file,
//! `pgd indent`'s and `pgd validate`'s plots.

/// The pgd tests' small blocks, shared rather than copied.
#[allow(dead_code)]
#[path = "../../crates/pgd-surgery-core/tests/pgd/common.rs"]
mod common;
mod fit;
mod option_values;
mod outputs;
mod shards;
#[path = "../../crates/pgd-surgery-core/tests/support/uniaxial.rs"]
mod uniaxial;
