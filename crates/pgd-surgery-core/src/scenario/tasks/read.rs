//! Reading `NAME(field: value, …)` as a [`Task`]: the name picks the registered type, the
//! shared fields go to [`TaskShared`], the others to the type's own serde struct.
//!
//! The type's struct is read through `erased_serde`, since the registry holds a plain function
//! per type and the RON reader's types are generic. An error keeps its kind on the way back
//! (the first one met is kept aside and returned as it was), so the scenario's error still
//! says which field is unknown or missing, and where.

use std::fmt;
use std::sync::Mutex;

use serde::de::{
    self, DeserializeSeed, Deserializer, EnumAccess, IntoDeserializer, MapAccess, VariantAccess,
    Visitor,
};
use serde::{Deserialize, forward_to_deserialize_any};

use super::registry::{self, Entry};
use crate::scenario::task::{Countertraction, Hand, Task, TaskShared};
use crate::scenario::units::{Newtons, Seconds};

impl<'de> Deserialize<'de> for Task {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_enum("Task", &[], TaskVisitor)
    }
}

struct TaskVisitor;

impl<'de> Visitor<'de> for TaskVisitor {
    type Value = Task;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a task, such as ForceControl(…)")
    }

    fn visit_enum<A: EnumAccess<'de>>(self, data: A) -> Result<Task, A::Error> {
        let (name, variant) = data.variant_seed(Name)?;
        let Some(entry) = registry::find(&name) else {
            return Err(de::Error::unknown_variant(
                &name,
                registry::registered_names(),
            ));
        };
        variant.struct_variant(&[], FieldsVisitor { entry })
    }
}

/// A name in the file (a task's or a field's), read as the identifier it is.
struct Name;

impl<'de> DeserializeSeed<'de> for Name {
    type Value = String;

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<String, D::Error> {
        deserializer.deserialize_identifier(self)
    }
}

impl Visitor<'_> for Name {
    type Value = String;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a name")
    }

    fn visit_str<E: de::Error>(self, name: &str) -> Result<String, E> {
        Ok(name.to_owned())
    }
}

/// The fields inside a task's parentheses.
struct FieldsVisitor {
    entry: Entry,
}

impl<'de> Visitor<'de> for FieldsVisitor {
    type Value = Task;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "the fields of {}(…)", self.entry.name)
    }

    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Task, A::Error> {
        let mut shared = SharedFields::default();
        let mut failure = None;
        let own = OwnFields {
            map,
            on_an_organ: self.entry.on_an_organ,
            shared: &mut shared,
            failure: &mut failure,
        };
        let read = (self.entry.read)(&mut <dyn erased_serde::Deserializer>::erase(own));
        let kind = read.map_err(|e| failure.take().unwrap_or_else(|| de::Error::custom(e)))?;
        Ok(Task::from_parts(shared.finish(&self.entry)?, kind))
    }
}

/// The shared fields as read so far.
#[derive(Default)]
struct SharedFields {
    organ: Option<String>,
    max_force_n: Option<Newtons>,
    time_limit_s: Option<Seconds>,
    hand: Option<Hand>,
    countertraction: Option<Countertraction>,
    phase: Option<String>,
    instruments: Option<Vec<String>>,
}

impl SharedFields {
    fn finish<E: de::Error>(self, entry: &Entry) -> Result<TaskShared, E> {
        if entry.on_an_organ && self.organ.is_none() {
            return Err(E::missing_field("organ"));
        }
        if !entry.on_an_organ && self.organ.is_some() {
            return Err(E::custom(format!(
                "{} works among all the organs: it has no `organ` field",
                entry.name
            )));
        }
        Ok(TaskShared {
            organ: self.organ,
            max_force_n: self.max_force_n.ok_or(E::missing_field("max_force_n"))?,
            time_limit_s: self.time_limit_s.ok_or(E::missing_field("time_limit_s"))?,
            hand: self.hand.unwrap_or_default(),
            countertraction: self.countertraction,
            phase: self.phase,
            instruments: self.instruments.unwrap_or_default(),
        })
    }
}

/// The task's fields as a deserializer of the type's own struct, the shared ones taken out.
struct OwnFields<'a, A, E> {
    map: A,
    on_an_organ: bool,
    shared: &'a mut SharedFields,
    failure: &'a mut Option<E>,
}

impl<'de, A: MapAccess<'de>> Deserializer<'de> for OwnFields<'_, A, A::Error> {
    type Error = A::Error;

    fn deserialize_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, A::Error> {
        self.read(&[], visitor)
    }

    /// The type's struct names its fields: a field that is neither one of them nor shared is
    /// refused here, by name, as serde's derive would (its own refusal loses its kind on the
    /// way back through the erased layers).
    fn deserialize_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        fields: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, A::Error> {
        self.read(fields, visitor)
    }

    forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf
        option unit unit_struct newtype_struct seq tuple tuple_struct map enum
        identifier ignored_any
    }
}

impl<'de, A: MapAccess<'de>> OwnFields<'_, A, A::Error> {
    /// Visits the map of the fields, `fields` the type's own (none: any).
    fn read<V: Visitor<'de>>(
        self,
        fields: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, A::Error> {
        let split = Split {
            map: self.map,
            fields,
            on_an_organ: self.on_an_organ,
            shared: self.shared,
            failure: &mut *self.failure,
        };
        visitor
            .visit_map(split)
            .map_err(|e| keep_first(self.failure, e))
    }
}

/// A type's own fields and the shared ones it takes, in one list for an error's "expected":
/// made once per type (serde wants the list `'static`), when a file first misspells one.
fn with_shared(own: &'static [&'static str], on_an_organ: bool) -> &'static [&'static str] {
    type Lists = Vec<(usize, bool, &'static [&'static str])>;
    static LISTS: Mutex<Lists> = Mutex::new(Vec::new());
    let key = own.as_ptr() as usize;
    let mut lists = LISTS.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(&(.., list)) = (lists.iter()).find(|(k, o, _)| *k == key && *o == on_an_organ) {
        return list;
    }
    let shared = ([
        "organ",
        "max_force_n",
        "time_limit_s",
        "hand",
        "countertraction",
        "phase",
        "instruments",
    ]
    .into_iter())
    .filter(|field| on_an_organ || *field != "organ");
    let list: &'static [&'static str] = Vec::leak(own.iter().copied().chain(shared).collect());
    lists.push((key, on_an_organ, list));
    list
}

/// Keeps `error` aside if it is the first, and returns a stand-in for the erased layers.
fn keep_first<E: de::Error>(failure: &mut Option<E>, error: E) -> E {
    let stand_in = E::custom(&error);
    failure.get_or_insert(error);
    stand_in
}

/// The map of a task's fields with the shared ones read on the way.
struct Split<'a, A, E> {
    map: A,
    fields: &'static [&'static str],
    on_an_organ: bool,
    shared: &'a mut SharedFields,
    failure: &'a mut Option<E>,
}

impl<'de, A: MapAccess<'de>> Split<'_, A, A::Error> {
    fn keep<T>(&mut self, read: Result<T, A::Error>) -> Result<T, A::Error> {
        read.map_err(|e| keep_first(self.failure, e))
    }

    /// Reads the value of a shared field into `slot`, once.
    fn shared_value<T: Deserialize<'de>>(
        &mut self,
        field: &'static str,
        slot: fn(&mut SharedFields) -> &mut Option<T>,
    ) -> Result<(), A::Error> {
        if slot(self.shared).is_some() {
            return self.keep(Err(de::Error::duplicate_field(field)));
        }
        let value = self.map.next_value::<T>();
        *slot(self.shared) = Some(self.keep(value)?);
        Ok(())
    }
}

impl<'de, A: MapAccess<'de>> MapAccess<'de> for Split<'_, A, A::Error> {
    type Error = A::Error;

    fn next_key_seed<K: DeserializeSeed<'de>>(
        &mut self,
        seed: K,
    ) -> Result<Option<K::Value>, A::Error> {
        loop {
            let key = self.map.next_key_seed(Name);
            let Some(key) = self.keep(key)? else {
                return Ok(None);
            };
            match key.as_str() {
                "organ" => self.shared_value("organ", |s| &mut s.organ)?,
                "max_force_n" => self.shared_value("max_force_n", |s| &mut s.max_force_n)?,
                "time_limit_s" => self.shared_value("time_limit_s", |s| &mut s.time_limit_s)?,
                "hand" => self.shared_value("hand", |s| &mut s.hand)?,
                "countertraction" => {
                    self.shared_value("countertraction", |s| &mut s.countertraction)?
                }
                "phase" => self.shared_value("phase", |s| &mut s.phase)?,
                "instruments" => self.shared_value("instruments", |s| &mut s.instruments)?,
                own if !self.fields.is_empty() && !self.fields.contains(&own) => {
                    let expected = with_shared(self.fields, self.on_an_organ);
                    return self.keep(Err(de::Error::unknown_field(own, expected)));
                }
                _ => {
                    let key: de::value::StringDeserializer<A::Error> = key.into_deserializer();
                    let field = seed.deserialize(key).map(Some);
                    return self.keep(field);
                }
            }
        }
    }

    fn next_value_seed<V: DeserializeSeed<'de>>(&mut self, seed: V) -> Result<V::Value, A::Error> {
        let value = self.map.next_value_seed(seed);
        self.keep(value)
    }
}
