//! The `KEY=VALUE,...` specs of the parametric families (`passage:`, `forest:`, `slot:`,
//! `pipe:`): each family lists its keys once, as a table of [`Key`]s, and the one
//! parser, range check and name writer here serve them all, so that a key's name,
//! range and field stand in one place (the family's module docs give the same table
//! for readers).

use super::ProblemError;

/// A parametric family whose instances are named `family:KEY=VALUE,...`, every key a
/// field of the instance's spec: the spec's parser, range check and name come from its
/// table of keys.
pub trait Family: Default + Copy + 'static {
    /// The family's name, before the `:`.
    const FAMILY: &'static str;
    /// Its keys, in the order names list them and ranges are checked.
    const KEYS: &'static [Key<Self>];

    /// Parses `KEY=VALUE,...` (see the family's module docs): the defaults, with each
    /// key given set in turn, then checked.
    fn parse(text: &str) -> Result<Self, ProblemError> {
        let mut spec = Self::default();
        for (k, v) in key_values(text)? {
            apply(Self::KEYS, &mut spec, k, v)?;
        }
        spec.check()?;
        Ok(spec)
    }

    /// Checks the ranges of the family's module docs.
    fn check(&self) -> Result<(), ProblemError> {
        check(self, Self::KEYS)
    }

    /// The name that builds this instance: the family and every key with its value.
    fn name(&self) -> String {
        let values: Vec<String> = Self::KEYS
            .iter()
            .map(|k| format!("{}={}", k.name, k.get(self)))
            .collect();
        format!("{}:{}", Self::FAMILY, values.join(","))
    }
}

/// What values a key takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Values {
    /// Any number within `lo..=hi`, checked with the spec's other ranges.
    Real(f64, f64),
    /// A whole number within `lo..=hi`, checked as it is parsed (the field holds no
    /// fractions) and again with the spec's other ranges.
    Whole(f64, f64),
    /// A switch: 0 off, any other number on.
    Flag,
}

/// A field of a spec that a key sets, read and written as a number: a length or
/// angle, a count or seed, or a switch (0 or 1).
pub trait Field {
    /// The field as a number.
    fn get(&self) -> f64;
    /// Sets the field from a number (a whole key's already checked to be whole).
    fn set(&mut self, value: f64);
}

/// Lengths, angles, counts and seeds: read as they are, set by `as` (a whole key's
/// value is already whole and within its field's range).
macro_rules! number_field {
    ($($t:ty),*) => {$(
        impl Field for $t {
            fn get(&self) -> f64 {
                *self as f64
            }
            fn set(&mut self, value: f64) {
                *self = value as $t;
            }
        }
    )*};
}

number_field!(f64, u64, u8);

impl Field for bool {
    fn get(&self) -> f64 {
        *self as u8 as f64
    }
    fn set(&mut self, value: f64) {
        *self = value != 0.0;
    }
}

/// One key of a family's spec: its name, its values, and the field of the spec `S`
/// it stands for.
pub struct Key<S> {
    /// The key as written in a spec.
    pub name: &'static str,
    /// What values it takes.
    pub values: Values,
    /// The field. Reading goes through a copy of the spec (specs are a few numbers),
    /// so that one accessor serves reading and writing.
    pub field: fn(&mut S) -> &mut dyn Field,
}

impl<S: Copy> Key<S> {
    /// The key `name` taking `values`, standing for `field`.
    pub const fn new(
        name: &'static str,
        values: Values,
        field: fn(&mut S) -> &mut dyn Field,
    ) -> Self {
        Self {
            name,
            values,
            field,
        }
    }

    /// The key's field of `spec`, as a number.
    fn get(&self, spec: &S) -> f64 {
        let mut copy = *spec;
        (self.field)(&mut copy).get()
    }

    /// Sets the key's field of `spec` to `value` (a whole key's value must be whole
    /// and within its range; other ranges are checked by [`check`]).
    fn apply(&self, spec: &mut S, value: f64) -> Result<(), ProblemError> {
        if let Values::Whole(lo, hi) = self.values {
            whole(self.name, value, lo, hi)?;
        }
        (self.field)(spec).set(value);
        Ok(())
    }
}

/// Sets the key `name` of `keys` on `spec`, or says the family has no such key.
pub(super) fn apply<S: Copy>(
    keys: &[Key<S>],
    spec: &mut S,
    name: String,
    value: f64,
) -> Result<(), ProblemError> {
    match keys.iter().find(|k| k.name == name) {
        Some(key) => key.apply(spec, value),
        None => Err(ProblemError::UnknownKey(name)),
    }
}

/// Checks every ranged key of `spec`, in the table's order (the first out of range
/// is the error).
pub(super) fn check<S: Copy>(spec: &S, keys: &[Key<S>]) -> Result<(), ProblemError> {
    for key in keys {
        if let Values::Real(lo, hi) | Values::Whole(lo, hi) = key.values {
            within(key.name, key.get(spec), lo, hi)?;
        }
    }
    Ok(())
}

/// `KEY=VALUE,...` as pairs, the values numbers.
pub(super) fn key_values(text: &str) -> Result<Vec<(String, f64)>, ProblemError> {
    let mut out = Vec::new();
    for part in text.split(',').filter(|p| !p.trim().is_empty()) {
        let (k, v) = part
            .split_once('=')
            .ok_or_else(|| ProblemError::ExpectedKeyValue(part.into()))?;
        let v: f64 = v.trim().parse().map_err(|_| ProblemError::NotANumber {
            part: part.into(),
            value: v.into(),
        })?;
        out.push((k.trim().to_string(), v));
    }
    Ok(out)
}

/// `Ok` when `value` is finite and within `lo..=hi`.
pub(super) fn within(name: &'static str, value: f64, lo: f64, hi: f64) -> Result<(), ProblemError> {
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(ProblemError::OutOfRange {
            name,
            value,
            lo,
            hi,
        })
    }
}

/// `value` as a whole number within `lo..=hi`.
pub(super) fn whole(name: &'static str, value: f64, lo: f64, hi: f64) -> Result<u64, ProblemError> {
    within(name, value, lo, hi)?;
    if value.fract() != 0.0 {
        return Err(ProblemError::NotWhole { name, value });
    }
    Ok(value as u64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::problem::families::{ForestSpec, SlotSpec};
    use crate::problem::pipes::PipeSpec;

    /// Parses `good` and checks that its name builds it again, and that every spec
    /// of `bad` is refused.
    fn round_trip<F: Family + std::fmt::Debug + PartialEq>(good: &str, bad: &[&str]) {
        let f = F::parse(good).unwrap();
        let name = f.name();
        let (family, text) = name.split_once(':').unwrap();
        assert_eq!((family, F::parse(text).unwrap()), (F::FAMILY, f));
        for bad in bad {
            assert!(F::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn names_round_trip_and_ranges_are_checked() {
        let forest_bad = [
            "spacing=2",
            "res=0.2",
            "seed=-1",
            "seed=1.5",
            "nope=1",
            "seed",
        ];
        round_trip::<ForestSpec>("spacing=1,seed=7,res=0.1", &forest_bad);
        round_trip::<SlotSpec>("tilt=45,angle=-20,res=0.05", &["tilt=70"]);
        let pipe_bad = [
            "d=0.5",
            "bends=3",
            "bends=1.5",
            "radius=0.5",
            "res=0.2",
            "nope=1",
        ];
        round_trip::<PipeSpec>("d=0.9,square=1,bends=2,radius=1.5,res=0.05", &pipe_bad);
    }

    #[test]
    fn names_list_every_key_in_the_tables_order() {
        // The benchmarks write these names into their CSV files.
        assert_eq!(
            ForestSpec::default().name(),
            "forest:spacing=1.25,seed=1,res=0.1"
        );
        assert_eq!(SlotSpec::default().name(), "slot:tilt=30,angle=30,res=0.05");
        let p = PipeSpec {
            square: true,
            ..PipeSpec::default()
        };
        assert_eq!(p.name(), "pipe:d=0.76,square=1,bends=1,radius=1,res=0.05");
    }

    #[test]
    fn whole_keys_are_refused_as_they_are_read_and_ranges_after() {
        // `bends` is read after `d`, but refused first: it is not whole.
        let e = PipeSpec::parse("d=5,bends=1.5").unwrap_err();
        assert_eq!(
            e,
            ProblemError::NotWhole {
                name: "bends",
                value: 1.5
            }
        );
        let e = PipeSpec::parse("radius=5,d=5").unwrap_err();
        assert!(
            matches!(e, ProblemError::OutOfRange { name: "d", .. }),
            "{e}"
        );
        assert_eq!(
            ForestSpec::parse("spacing=1,nope=1").unwrap_err(),
            ProblemError::UnknownKey("nope".into())
        );
        // Any number but 0 switches a switch on.
        assert!(PipeSpec::parse("square=5").unwrap().square);
    }
}
