//! The task types a scenario may name: the built-in ones (`scenario::tasks`) and any
//! registered since. The reader looks a task's name up here.

use std::any::TypeId;
use std::sync::{OnceLock, RwLock};

use crate::scenario::task::{AnyTask, TaskType};

/// Reads a task type's own fields out of the fields of its `NAME(…)`.
type ReadFields =
    fn(&mut dyn erased_serde::Deserializer<'_>) -> Result<Box<dyn AnyTask>, erased_serde::Error>;

/// One registered task type.
#[derive(Clone, Copy)]
pub(in crate::scenario) struct Entry {
    pub name: &'static str,
    pub on_an_organ: bool,
    pub read: ReadFields,
    type_id: TypeId,
}

impl Entry {
    pub fn of<T: TaskType>() -> Self {
        Self {
            name: T::NAME,
            on_an_organ: T::ON_AN_ORGAN,
            read: read_as::<T>,
            type_id: TypeId::of::<T>(),
        }
    }
}

fn read_as<T: TaskType>(
    fields: &mut dyn erased_serde::Deserializer<'_>,
) -> Result<Box<dyn AnyTask>, erased_serde::Error> {
    Ok(Box::new(erased_serde::deserialize::<T>(fields)?))
}

struct Registry {
    entries: Vec<Entry>,
    /// The names, in order, for an error's list of what may be written (serde wants them
    /// `'static`: a new list is leaked on each registration, a few words once per type).
    names: &'static [&'static str],
}

impl Registry {
    fn with(entries: Vec<Entry>) -> Self {
        let names = entries.iter().map(|e| e.name).collect::<Vec<_>>();
        Self {
            entries,
            names: Vec::leak(names),
        }
    }
}

fn registry() -> &'static RwLock<Registry> {
    static REGISTRY: OnceLock<RwLock<Registry>> = OnceLock::new();
    REGISTRY.get_or_init(|| RwLock::new(Registry::with(super::built_in())))
}

/// Makes the task type `T` known to the scenario reader under `T::NAME`, from now on. Again
/// for the same type does nothing.
///
/// # Panics
/// If another type is registered under the same name.
pub fn register<T: TaskType>() {
    let mut registry = registry().write().unwrap_or_else(|e| e.into_inner());
    let entry = Entry::of::<T>();
    match registry.entries.iter().find(|e| e.name == entry.name) {
        Some(known) if known.type_id == entry.type_id => {}
        Some(_) => panic!("a task type named `{}` is registered already", T::NAME),
        None => {
            let mut entries = std::mem::take(&mut registry.entries);
            entries.push(entry);
            *registry = Registry::with(entries);
        }
    }
}

/// The task type registered under `name`.
pub(in crate::scenario) fn find(name: &str) -> Option<Entry> {
    let registry = registry().read().unwrap_or_else(|e| e.into_inner());
    registry.entries.iter().find(|e| e.name == name).copied()
}

/// The names a scenario's tasks may have, in the order registered.
pub fn registered_names() -> &'static [&'static str] {
    registry().read().unwrap_or_else(|e| e.into_inner()).names
}
