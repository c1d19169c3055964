//! Positions in YAML text from the parser's own marks: the line and column of any key or value
//! by path, and syntax errors and duplicate keys in one walk.
//!
//! serde_yaml_ng reports a mark only for errors, and fixes it to the innermost node being
//! deserialized. So to place a field, [`locate`] walks the text with serde and fails on purpose
//! inside that field's own `deserialize_*` call: the error then carries the field's mark,
//! whatever the layout (block or flow, quoted keys, anchors). Errors are rare, so reading the
//! text once more per message costs nothing that matters.
//!
//! Used by scenes (`scene.rs`) and by the derivation tool's spec checks (`derive/`), for
//! problems found after parsing (an undefined symbol, a bad value), which serde cannot place.

use serde::de::{self, DeserializeSeed, Deserializer, IgnoredAny, MapAccess, SeqAccess, Visitor};
use std::collections::HashSet;
use std::fmt;

/// One step of a path into a YAML document.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step<'a> {
    /// A mapping key.
    Key(&'a str),
    /// A sequence index (0-based).
    Index(usize),
}

/// Which part of a mapping entry to point at (a sequence item has only its value).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum At {
    /// The entry's key.
    Key,
    /// The entry's value.
    Value,
}

/// 1-based (line, column) of the field at `path`: the key of a mapping entry, the start of a
/// sequence item. `None` if the path is not in the text (or is empty).
pub fn locate(text: &str, path: &[Step<'_>]) -> Option<(usize, usize)> {
    locate_at(text, path, At::Key)
}

/// 1-based (line, column) of the key or value at `path` (`at` matters only when the path ends
/// in a key), from the YAML parser's own marks: the text is walked again and made to fail
/// exactly there. `None` if the path is not in the text (or is empty).
pub fn locate_at(text: &str, path: &[Step<'_>], at: At) -> Option<(usize, usize)> {
    if path.is_empty() {
        return None;
    }
    let de = serde_yaml_ng::Deserializer::from_str(text);
    match (Seek { path, at }).deserialize(de) {
        Err(e) => e.location().map(|l| (l.line(), l.column())),
        Ok(()) => None,
    }
}

/// Like [`locate_at`], but a field that is not in the text (a missing key, an index past the
/// end) is placed at its nearest ancestor that is (at that ancestor's key), and a path with no
/// ancestor in the text at the start of the document, (1, 1).
pub fn locate_nearest(text: &str, path: &[Step<'_>], at: At) -> (usize, usize) {
    (1..=path.len())
        .rev()
        .find_map(|n| {
            let here = if n == path.len() { at } else { At::Key };
            locate_at(text, &path[..n], here)
        })
        .unwrap_or((1, 1))
}

/// `parameters.m1` → [Key(parameters), Key(m1)]; `want[2]` → [Key(want), Index(2)].
pub fn parse_path(field: &str) -> Vec<Step<'_>> {
    let mut out = Vec::new();
    for part in field.split('.').filter(|p| !p.is_empty()) {
        let mut it = part.split('[');
        if let Some(key) = it.next()
            && !key.is_empty()
        {
            out.push(Step::Key(key));
        }
        for idx in it {
            if let Ok(i) = idx.trim_end_matches(']').parse() {
                out.push(Step::Index(i));
            }
        }
    }
    out
}

/// The path `key` inside `parent` as text (`parameters` + `m1` → `parameters.m1`).
pub fn join_key(parent: &str, key: &str) -> String {
    if parent.is_empty() || parent == "." {
        key.to_string()
    } else {
        format!("{parent}.{key}")
    }
}

/// Whether `s` looks like a serde_yaml_ng path (`parameters.m1`, `want[2]`).
pub fn is_path(s: &str) -> bool {
    !s.is_empty()
        && s.chars()
            .all(|c| c.is_alphanumeric() || matches!(c, '_' | '.' | '[' | ']' | '-' | '?'))
}

/// Removes serde_yaml_ng's " at line L column C" / " at position N" from a message.
pub fn strip_marks(message: &str) -> String {
    let mut out = String::with_capacity(message.len());
    let mut rest = message;
    while let Some(i) = rest.find(" at ") {
        out.push_str(&rest[..i]);
        let after = &rest[i + 4..];
        let skip = mark_len(after);
        if skip == 0 {
            out.push_str(" at ");
            rest = after;
        } else {
            rest = &after[skip..];
        }
    }
    out.push_str(rest);
    out
}

/// The first "line L column C" in `s`.
pub fn first_mark(s: &str) -> Option<(usize, usize)> {
    let i = s.find("line ")?;
    let rest = &s[i + 5..];
    let l: String = rest.chars().take_while(char::is_ascii_digit).collect();
    let rest = rest[l.len()..].strip_prefix(" column ")?;
    let c: String = rest.chars().take_while(char::is_ascii_digit).collect();
    Some((l.parse().ok()?, c.parse().ok()?))
}

/// Length of a leading "line L column C" or "position N", or 0.
fn mark_len(s: &str) -> usize {
    fn digits(s: &str) -> usize {
        s.bytes().take_while(u8::is_ascii_digit).count()
    }
    if let Some(r) = s.strip_prefix("line ") {
        let a = digits(r);
        if a > 0
            && let Some(r2) = r[a..].strip_prefix(" column ")
        {
            let b = digits(r2);
            if b > 0 {
                return 5 + a + 8 + b;
            }
        }
    } else if let Some(r) = s.strip_prefix("position ") {
        let a = digits(r);
        if a > 0 {
            return 9 + a;
        }
    }
    0
}

/// What [`check_syntax`] found wrong, at the parser's mark.
#[derive(Debug)]
pub enum SyntaxError {
    /// A key given a second time in one mapping; the position is the second occurrence's.
    DuplicateKey {
        /// The key's path (`parameters.m1`).
        field: String,
        /// The key itself (`m1`).
        key: String,
        /// 1-based line and column of the second occurrence.
        position: (usize, usize),
    },
    /// A YAML tag (`!name value`), which no file here uses.
    Tag {
        /// 1-based line and column of the tagged node.
        position: (usize, usize),
    },
    /// Anything else the parser rejects, with its message and mark.
    Yaml(serde_yaml_ng::Error),
}

/// Reads every node of `text`: YAML syntax errors, duplicate keys and tags, each with the
/// parser's own mark. Types and schemas are not checked.
pub fn check_syntax(text: &str) -> Result<(), SyntaxError> {
    let walk = Walk {
        path: String::new(),
    }
    .deserialize(serde_yaml_ng::Deserializer::from_str(text));
    let Err(e) = walk else {
        return Ok(());
    };
    let position = e
        .location()
        .map(|l| (l.line(), l.column()))
        .unwrap_or((1, 1));
    let raw = e.to_string();
    // Our markers: "\u{1}path\u{1}key" for a duplicate key, "\u{2}" for a tag.
    if let Some(idx) = raw.find(DUP) {
        let rest = strip_marks(&raw[idx + DUP.len()..]);
        let (path, key) = rest.split_once(DUP).unwrap_or((&rest, ""));
        return Err(SyntaxError::DuplicateKey {
            field: join_key(path, key),
            key: key.to_string(),
            position,
        });
    }
    if raw.contains(TAG) {
        return Err(SyntaxError::Tag { position });
    }
    Err(SyntaxError::Yaml(e))
}

// ---------------------------------------------------------------------------------------------
// Walking the YAML with serde to get the parser's own marks.

/// Separator of the duplicate-key marker in error messages.
const DUP: &str = "\u{1}";
/// The tag marker in error messages.
const TAG: &str = "\u{2}";

/// Implements the scalar `visit_*` methods as "accept and ignore".
macro_rules! accept_scalars {
    () => {
        fn visit_bool<E: de::Error>(self, _: bool) -> Result<Self::Value, E> {
            Ok(Default::default())
        }
        fn visit_i64<E: de::Error>(self, _: i64) -> Result<Self::Value, E> {
            Ok(Default::default())
        }
        fn visit_u64<E: de::Error>(self, _: u64) -> Result<Self::Value, E> {
            Ok(Default::default())
        }
        fn visit_i128<E: de::Error>(self, _: i128) -> Result<Self::Value, E> {
            Ok(Default::default())
        }
        fn visit_u128<E: de::Error>(self, _: u128) -> Result<Self::Value, E> {
            Ok(Default::default())
        }
        fn visit_f64<E: de::Error>(self, _: f64) -> Result<Self::Value, E> {
            Ok(Default::default())
        }
        fn visit_str<E: de::Error>(self, _: &str) -> Result<Self::Value, E> {
            Ok(Default::default())
        }
        fn visit_unit<E: de::Error>(self) -> Result<Self::Value, E> {
            Ok(Default::default())
        }
        fn visit_none<E: de::Error>(self) -> Result<Self::Value, E> {
            Ok(Default::default())
        }
    };
}

/// Visits every node; fails at the second occurrence of a key in a mapping, and at a tag.
struct Walk {
    path: String,
}

impl<'de> DeserializeSeed<'de> for Walk {
    type Value = ();
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> Visitor<'de> for Walk {
    type Value = ();
    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("any YAML value")
    }
    accept_scalars!();
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
        let mut i = 0;
        while seq
            .next_element_seed(Walk {
                path: format!("{}[{i}]", self.path),
            })?
            .is_some()
        {
            i += 1;
        }
        Ok(())
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
        let mut seen = HashSet::new();
        while let Some(key) = map.next_key_seed(UniqueKey {
            seen: &seen,
            parent: &self.path,
        })? {
            let path = join_key(&self.path, key.as_deref().unwrap_or("?"));
            map.next_value_seed(Walk { path })?;
            if let Some(k) = key {
                seen.insert(k);
            }
        }
        Ok(())
    }
    fn visit_enum<A: de::EnumAccess<'de>>(self, _: A) -> Result<(), A::Error> {
        Err(de::Error::custom(TAG))
    }
}

/// A mapping key as text (None for a collection used as a key), failing if already seen.
struct UniqueKey<'a> {
    seen: &'a HashSet<String>,
    parent: &'a str,
}

impl<'de> DeserializeSeed<'de> for UniqueKey<'_> {
    type Value = Option<String>;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Option<String>, D::Error> {
        // The check runs inside the visitor, so the error carries the key's own mark.
        d.deserialize_any(self)
    }
}

impl UniqueKey<'_> {
    fn check<E: de::Error>(&self, key: String) -> Result<Option<String>, E> {
        if self.seen.contains(&key) {
            Err(E::custom(format!("{DUP}{}{DUP}{key}", self.parent)))
        } else {
            Ok(Some(key))
        }
    }
}

impl<'de> Visitor<'de> for UniqueKey<'_> {
    type Value = Option<String>;
    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a mapping key")
    }
    fn visit_bool<E: de::Error>(self, v: bool) -> Result<Self::Value, E> {
        self.check(v.to_string())
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Self::Value, E> {
        self.check(v.to_string())
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Self::Value, E> {
        self.check(v.to_string())
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Self::Value, E> {
        self.check(v.to_string())
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<Self::Value, E> {
        self.check(v.to_string())
    }
    fn visit_unit<E: de::Error>(self) -> Result<Self::Value, E> {
        self.check("null".to_string())
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        while seq.next_element::<IgnoredAny>()?.is_some() {}
        Ok(None)
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
        while map.next_entry::<IgnoredAny, IgnoredAny>()?.is_some() {}
        Ok(None)
    }
}

/// Follows `path`; fails at the target so that the error carries the target's mark.
struct Seek<'a> {
    path: &'a [Step<'a>],
    at: At,
}

impl<'de> DeserializeSeed<'de> for Seek<'_> {
    type Value = ();
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        if self.path.is_empty() {
            // Every visit of `Found` fails inside this node's own `deserialize_any`.
            d.deserialize_any(Found)
        } else {
            d.deserialize_any(self)
        }
    }
}

impl<'de> Visitor<'de> for Seek<'_> {
    type Value = ();
    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("any YAML value")
    }
    accept_scalars!();
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
        let target = match self.path.first() {
            Some(Step::Index(i)) => Some(*i),
            _ => None,
        };
        let mut i = 0;
        loop {
            if Some(i) == target {
                let next = Seek {
                    path: &self.path[1..],
                    at: self.at,
                };
                if seq.next_element_seed(next)?.is_none() {
                    return Ok(());
                }
            } else if seq.next_element::<IgnoredAny>()?.is_none() {
                return Ok(());
            }
            i += 1;
        }
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
        let want = match self.path.first() {
            Some(Step::Key(k)) => Some(*k),
            _ => None,
        };
        let fail_on_key = self.path.len() == 1 && self.at == At::Key;
        while let Some(hit) = map.next_key_seed(KeyMatch {
            want,
            fail: fail_on_key,
        })? {
            if hit {
                map.next_value_seed(Seek {
                    path: &self.path[1..],
                    at: self.at,
                })?;
            } else {
                map.next_value::<IgnoredAny>()?;
            }
        }
        Ok(())
    }
    fn visit_enum<A: de::EnumAccess<'de>>(self, _: A) -> Result<(), A::Error> {
        Ok(())
    }
}

/// Fails on whatever it visits (the default `visit_*` methods all return errors).
struct Found;

impl<'de> Visitor<'de> for Found {
    type Value = ();
    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("the located field")
    }
}

/// Reads a key; reports whether it is the one wanted, or fails on it if `fail`.
struct KeyMatch<'a> {
    want: Option<&'a str>,
    fail: bool,
}

impl<'de> DeserializeSeed<'de> for KeyMatch<'_> {
    type Value = bool;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<bool, D::Error> {
        d.deserialize_any(self)
    }
}

impl KeyMatch<'_> {
    fn check<E: de::Error>(&self, key: &str) -> Result<bool, E> {
        match self.want {
            Some(w) if w == key && self.fail => Err(E::custom("located")),
            Some(w) => Ok(w == key),
            None => Ok(false),
        }
    }
}

impl<'de> Visitor<'de> for KeyMatch<'_> {
    type Value = bool;
    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a mapping key")
    }
    fn visit_bool<E: de::Error>(self, v: bool) -> Result<bool, E> {
        self.check(&v.to_string())
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<bool, E> {
        self.check(&v.to_string())
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<bool, E> {
        self.check(&v.to_string())
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<bool, E> {
        self.check(&v.to_string())
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<bool, E> {
        self.check(v)
    }
    fn visit_unit<E: de::Error>(self) -> Result<bool, E> {
        self.check("null")
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<bool, A::Error> {
        while seq.next_element::<IgnoredAny>()?.is_some() {}
        Ok(false)
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<bool, A::Error> {
        while map.next_entry::<IgnoredAny, IgnoredAny>()?.is_some() {}
        Ok(false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Step::{Index, Key};

    const DOC: &str = "\
# a comment
model: rod_cube
parameters:
  m1: 1.0
  \"m2\": 3.0
want: [a, b,
  c]
flow: {x: 1, y: {z: 2}}
";

    /// A derivation spec's layouts: compact block sequences, flow items, nested flow lists.
    const SPEC: &str = "\
name: rod_cube
parameters:
  - {name: m1, unit: kg}
  - name: m2
    unit: kg
bodies:
  - name: rod
    position: [\"x1 + ell\", \"ell/2*sin(theta)\"]
values: {m1: 1.0, a: 0.25}
";

    #[test]
    fn locates_keys_and_values_in_block_and_flow_layouts() {
        let p = |s| parse_path(s);
        assert_eq!(locate_at(DOC, &p("model"), At::Key), Some((2, 1)));
        assert_eq!(locate_at(DOC, &p("model"), At::Value), Some((2, 8)));
        assert_eq!(locate_at(DOC, &p("parameters.m1"), At::Key), Some((4, 3)));
        assert_eq!(locate_at(DOC, &p("parameters.m2"), At::Key), Some((5, 3)));
        assert_eq!(locate_at(DOC, &p("parameters.m2"), At::Value), Some((5, 9)));
        assert_eq!(locate_at(DOC, &p("want[2]"), At::Value), Some((7, 3)));
        assert_eq!(locate_at(DOC, &p("flow.y.z"), At::Value), Some((8, 21)));
        assert_eq!(locate_at(DOC, &p("parameters.g"), At::Key), None);
        assert_eq!(locate_at(DOC, &p("want[5]"), At::Value), None);
        assert_eq!(locate(DOC, &[]), None);
    }

    #[test]
    fn locates_keys_and_items_in_sequences_of_mappings() {
        assert_eq!(locate(SPEC, &[Key("name")]), Some((1, 1)));
        assert_eq!(locate_at(SPEC, &[Key("name")], At::Value), Some((1, 7)));
        assert_eq!(locate(SPEC, &[Key("parameters"), Index(1)]), Some((4, 5)));
        let unit = |i| [Key("parameters"), Index(i), Key("unit")];
        assert_eq!(locate(SPEC, &unit(1)), Some((5, 5)));
        assert_eq!(locate(SPEC, &unit(0)), Some((3, 16)));
        let pos = [Key("bodies"), Index(0), Key("position"), Index(1)];
        assert_eq!(locate(SPEC, &pos), Some((8, 28)));
        assert_eq!(locate(SPEC, &[Key("values"), Key("a")]), Some((9, 19)));
    }

    #[test]
    fn nearest_falls_back_to_the_deepest_ancestor_found() {
        assert_eq!(
            locate_nearest(SPEC, &[Key("bodies"), Index(3)], At::Value),
            (6, 1)
        );
        let missing = [Key("parameters"), Index(1), Key("dimension")];
        assert_eq!(locate_nearest(SPEC, &missing, At::Key), (4, 5));
        assert_eq!(locate_nearest(SPEC, &[Key("nothing")], At::Key), (1, 1));
        assert_eq!(locate_nearest("", &[Key("nothing")], At::Key), (1, 1));
    }

    #[test]
    fn syntax_check_finds_duplicates_and_tags() {
        assert!(check_syntax(DOC).is_ok());
        match check_syntax("a: 1\nb:\n  c: 2\n  c: 3\n") {
            Err(SyntaxError::DuplicateKey {
                field,
                key,
                position,
            }) => {
                assert_eq!(
                    (field.as_str(), key.as_str(), position),
                    ("b.c", "c", (4, 3))
                );
            }
            other => panic!("{other:?}"),
        }
        assert!(matches!(
            check_syntax("a: !tag 1\n"),
            Err(SyntaxError::Tag { position: (1, 4) })
        ));
        assert!(matches!(
            check_syntax("a: [1, 2\n"),
            Err(SyntaxError::Yaml(_))
        ));
    }

    #[test]
    fn strips_marks_but_keeps_other_text() {
        assert_eq!(
            strip_marks(
                "did not find expected key at line 3 column 1, while parsing at line 1 column 1"
            ),
            "did not find expected key, while parsing"
        );
        assert_eq!(strip_marks("look at this at position 4"), "look at this");
        assert_eq!(first_mark("x at line 3 column 7, y"), Some((3, 7)));
    }

    #[test]
    fn paths_parse() {
        assert_eq!(parse_path("want[2]"), vec![Key("want"), Index(2)]);
        assert_eq!(
            parse_path("parameters.m1"),
            vec![Key("parameters"), Key("m1")]
        );
        assert_eq!(join_key("", "m1"), "m1");
        assert_eq!(join_key("parameters", "m1"), "parameters.m1");
    }
}
