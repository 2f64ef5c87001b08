//! Fixed-length arrays read exactly: `resolution = [4, 4, 1]` is an error, not `[4, 4]`.
//!
//! serde reads `[T; N]` by taking N values from the sequence and leaves checking that none is
//! left to the deserializer; toml_edit's array deserializer does not check, so the extra
//! values were dropped. Every fixed-length array key of the schema reads through these
//! helpers (`#[serde(deserialize_with = "exact::…")]`), which count every value.

use std::fmt;
use std::marker::PhantomData;

use serde::de::{self, IgnoredAny, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer};

/// `[T; N]` read from an array of exactly N values.
struct Exact<T, const N: usize>([T; N]);

impl<'de, T: Deserialize<'de>, const N: usize> Deserialize<'de> for Exact<T, N> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V<T, const N: usize>(PhantomData<T>);
        impl<'de, T: Deserialize<'de>, const N: usize> Visitor<'de> for V<T, N> {
            type Value = [T; N];
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(f, "an array of {N} values")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<[T; N], A::Error> {
                let mut values = Vec::with_capacity(N);
                while values.len() < N {
                    match seq.next_element::<T>()? {
                        Some(v) => values.push(v),
                        None => break,
                    }
                }
                let mut got = values.len();
                while seq.next_element::<IgnoredAny>()?.is_some() {
                    got += 1;
                }
                let wrong = || de::Error::custom(format!("takes {N} values, got {got}"));
                if got != N {
                    return Err(wrong());
                }
                values.try_into().map_err(|_| wrong())
            }
        }
        d.deserialize_seq(V(PhantomData)).map(Exact)
    }
}

/// A `[T; N]` key.
pub(crate) fn array<'de, D, T, const N: usize>(d: D) -> Result<[T; N], D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    Exact::<T, N>::deserialize(d).map(|e| e.0)
}

/// An optional `[T; N]` key.
pub(crate) fn option<'de, D, T, const N: usize>(d: D) -> Result<Option<[T; N]>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    Option::<Exact<T, N>>::deserialize(d).map(|o| o.map(|e| e.0))
}

/// An optional list of `[T; N]` (e.g. a hull's `points`).
pub(crate) fn option_list<'de, D, T, const N: usize>(d: D) -> Result<Option<Vec<[T; N]>>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    Option::<Vec<Exact<T, N>>>::deserialize(d)
        .map(|o| o.map(|list| list.into_iter().map(|e| e.0).collect()))
}

#[cfg(test)]
mod tests {
    use crate::{DirFiles, from_text};

    /// A scene text whose line 3 sets an array key; `{}` is the array.
    const CASES: &[(&str, &str, usize)] = &[
        ("sim.gravity", "[sim]\ndt = 0.01\ngravity = {}\n", 3),
        ("wind.velocity", "[wind]\ndrag = 0.0\nvelocity = {}\n", 3),
        (
            "cloth.c.resolution",
            "[cloth.c]\nmass = 1.0\nresolution = {}\n",
            2,
        ),
        ("cloth.c.size", "[cloth.c]\nmass = 1.0\nsize = {}\n", 2),
        ("cloth.c.center", "[cloth.c]\nmass = 1.0\ncenter = {}\n", 3),
        (
            "cloth.c.motion",
            "[cloth.c]\nmass = 1.0\nmotion = { kind = \"linear\", velocity = {} }\n",
            3,
        ),
        (
            "cloth.c.motion",
            "[cloth.c]\nmass = 1.0\nmotion = { kind = \"oscillate\", frequency = 1, amplitude = {} }\n",
            3,
        ),
        (
            "cloth.c.motion",
            "[cloth.c]\nmass = 1.0\nmotion = { kind = \"rotate\", angular_velocity = 1, axis = [0, 1, 0], pivot = {} }\n",
            3,
        ),
        (
            "cloth.c.motion",
            "[cloth.c]\nmass = 1.0\nmotion = { kind = \"rotate\", angular_velocity = 1, pivot = [0, 1, 0], axis = {} }\n",
            3,
        ),
        (
            "cloth.c.attach",
            "[cloth.c]\nmass = 1.0\nattach = [{ bone = \"b\", panel = \"p\", edges = {} }]\n",
            2,
        ),
        (
            "cloth.c.attach",
            "[cloth.c]\nmass = 1.0\nattach = [{ bone = \"b\", panel = \"p\", edges = [0, 1], span = {} }]\n",
            2,
        ),
        (
            "collider[0].half_extents",
            "[[collider]]\nshape = \"cuboid\"\nhalf_extents = {}\n",
            3,
        ),
        (
            "collider[0].normal",
            "[[collider]]\nshape = \"plane\"\nnormal = {}\n",
            3,
        ),
        (
            "collider[0].position",
            "[[collider]]\nshape = \"plane\"\nposition = {}\n",
            3,
        ),
        (
            "collider[0].rotation_deg",
            "[[collider]]\nshape = \"plane\"\nrotation_deg = {}\n",
            3,
        ),
        (
            "collider[0].points",
            "[[collider]]\nshape = \"convex-hull\"\npoints = [[0, 0, 0], {}]\n",
            3,
        ),
        (
            "collider[0].parts",
            "[[collider]]\nshape = \"compound\"\nparts = [{ shape = \"sphere\", radius = 1, position = {} }]\n",
            3,
        ),
        (
            "character.position",
            "[character]\nmodel = \"m.glb\"\nposition = {}\n",
            3,
        ),
        (
            "character.rotation_deg",
            "[character]\nmodel = \"m.glb\"\nrotation_deg = {}\n",
            3,
        ),
    ];

    fn array(n: usize) -> String {
        let values: Vec<String> = (0..n).map(|i| i.to_string()).collect();
        format!("[{}]", values.join(", "))
    }

    #[test]
    fn a_fixed_length_array_of_another_length_is_an_error_with_file_line_and_key() {
        for &(key, template, n) in CASES {
            for got in [n - 1, n + 1, n + 5] {
                let text = template.replace("{}", &array(got));
                let err = from_text("s.toml", &text, &[], &DirFiles(".".into()))
                    .expect_err("wrong length")
                    .to_string();
                let want = format!("s.toml:3: {key}: takes {n} values, got {got}");
                assert!(err.contains(&want), "{text}\nwant {want}\ngot  {err}");
            }
            // The right length passes this stage (whatever else the scene lacks).
            let text = template.replace("{}", &array(n));
            if let Err(e) = from_text("s.toml", &text, &[], &DirFiles(".".into())) {
                assert!(!e.to_string().contains("values, got"), "{text}\n{e}");
            }
        }
    }

    #[test]
    fn every_fixed_length_array_field_of_the_schema_reads_exactly() {
        // A new `[T; N]` field must read through this module, or it drops extra values again.
        let sources = [
            include_str!("mod.rs"),
            include_str!("cloth.rs"),
            include_str!("collider.rs"),
            include_str!("character.rs"),
        ];
        let mut fields = 0;
        for text in sources {
            let lines: Vec<&str> = text.lines().map(str::trim).collect();
            for (i, line) in lines.iter().enumerate() {
                let field = line.trim_start_matches("pub ");
                let is_array_field = field.split_once(": ").is_some_and(|(name, ty)| {
                    name.chars().all(|c| c.is_ascii_lowercase() || c == '_')
                        && ty.contains("; ")
                        && (ty.ends_with("],") || ty.ends_with("]>,") || ty.ends_with("]>>,"))
                });
                if !is_array_field {
                    continue;
                }
                fields += 1;
                let attributes = lines[..i]
                    .iter()
                    .rev()
                    .take_while(|l| !l.ends_with(',') || !l.contains(": "))
                    .take_while(|l| !l.starts_with("///"));
                let exact = attributes.clone().any(|l| l.contains("exact::"));
                assert!(exact, "`{line}` does not read through schema::exact");
            }
        }
        assert_eq!(fields, 18, "the schema's fixed-length array fields");
    }
}
