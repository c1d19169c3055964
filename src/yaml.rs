//! YAML with positions, for scenes and model specs: typed values with typed, placed errors, and
//! the place of any field by its path, all from one maintained parser that carries spans
//! (serde-saphyr, on granit-parser).
//!
//! - serde-saphyr deserializes; each of its errors is a typed value with the parser's own
//!   location (a syntax error, a duplicate key, an unknown or missing field, a wrong type), and
//!   serde_path_to_error names the field serde was in when it failed.
//! - A field found invalid after parsing (an undefined symbol, a value out of range) is placed
//!   by its path in a tree of the document whose every key and value is a `Spanned` node
//!   (serde-saphyr's span-aware wrapper), at its key or its value, whatever the layout (block
//!   or flow, quoted keys, anchors: a value reached through an alias is placed where it is
//!   defined, as the parser places its own errors). The schema's own structs stay plain.
//! - [`excerpt`] turns a place into an annotate-snippets snippet (the line with the token
//!   underlined), which scenes and specs render under their one-line headlines.
//!
//! Reading is two steps: [`Document::parse`] reads every node (once to report a syntax error, a
//! duplicate key or a tag anywhere, named by its field, before any schema is checked; once into
//! the tree), then [`Document::deserialize`] reads the typed value. serde-saphyr bounds nesting
//! depth, document size and alias expansion, so the tree's recursion is bounded too, and no
//! text makes any pass panic (`tests/fuzz_properties.rs`).

use annotate_snippets::{Annotation, AnnotationKind, Snippet};
use serde::de::{
    self, Deserialize, DeserializeOwned, Deserializer, IgnoredAny, MapAccess, SeqAccess, Visitor,
};
use serde_saphyr::{Error as SaphyrError, MessageFormatter, Spanned, Tagged, UserMessageFormatter};
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

/// A place in YAML text: where a token starts and how wide it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Mark {
    /// 1-based line.
    pub line: usize,
    /// 1-based column, in characters.
    pub column: usize,
    /// Characters the token covers on its line (at least 1).
    pub width: usize,
}

impl Mark {
    /// The start of the text, where a problem with no better place is put.
    pub const START: Mark = Mark {
        line: 1,
        column: 1,
        width: 1,
    };
}

/// What a [`ReadError`] is about.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Problem {
    /// Not YAML (or more than one document, or nested past the parser's limits).
    Syntax,
    /// A key given a second time in one mapping; the error is at the second one.
    DuplicateKey(String),
    /// A YAML tag (`!name value`; the tag as the parser resolved it), which no file here uses.
    /// The error is at the tagged value.
    Tag(String),
    /// A key the schema does not have.
    UnknownField(String),
    /// A key the schema requires that the mapping does not have; the error is at the mapping.
    MissingField(String),
    /// A value of the wrong type, shape or length for its field.
    Type,
}

/// A problem reading YAML text into a typed value, at the parser's own mark.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReadError {
    /// What is wrong.
    pub problem: Problem,
    /// The path serde was at (`parameters.m1`, `bodies[0]`): for a key problem the mapping's,
    /// empty at the top of the document.
    pub path: String,
    /// Where.
    pub mark: Mark,
    /// The parser's message, without its place.
    pub message: String,
}

impl ReadError {
    /// The path of the field itself: [`ReadError::path`] joined with the key for a key
    /// problem (`parameters.m1` for a duplicate `m1` in `parameters`).
    pub fn field(&self) -> String {
        match &self.problem {
            Problem::DuplicateKey(key)
            | Problem::UnknownField(key)
            | Problem::MissingField(key) => join_key(&self.path, key),
            _ => self.path.clone(),
        }
    }
}

/// YAML text read once, with the place of every key and value in it.
pub struct Document<'a> {
    text: &'a str,
    root: Option<Item>,
}

impl<'a> Document<'a> {
    /// Reads every node of `text`: YAML syntax errors, duplicate keys, nesting past the
    /// parser's limits and tags, each at its mark, in the whole document before any type is
    /// checked. Types and schemas are not checked.
    pub fn parse(text: &'a str) -> Result<Document<'a>, ReadError> {
        // Every node, with the path of a failure. (The tree below cannot give it: the path
        // would run through its span-aware wrappers.)
        let mut path = Vec::new();
        serde_saphyr::with_deserializer_from_str_with_options(text, options(), |de| {
            serde_path_to_error::deserialize::<_, IgnoredAny>(de).map_err(|e| {
                path = parts(e.path());
                e.into_inner()
            })
        })
        .map_err(|e| {
            let problem = match unwrap(&e) {
                SaphyrError::DuplicateMappingKey { key, .. } => {
                    Problem::DuplicateKey(key.clone().unwrap_or_default())
                }
                _ => Problem::Syntax,
            };
            read_error(text, &e, problem, &path)
        })?;
        // The same text again as a tree of spanned nodes. It fails only on a key that is not
        // a scalar, which no schema here has: the typed pass reports that at its place.
        let root: Option<Item> = serde_saphyr::from_str_with_options(text, options()).ok();
        if let Some((path, item)) = root.as_ref().and_then(|r| first_tag(r, &mut Vec::new())) {
            let tag = printable(item.value.1.as_deref().unwrap_or_default());
            return Err(ReadError {
                problem: Problem::Tag(tag.clone()),
                path,
                mark: mark_of(item),
                message: format!("YAML tags (`{tag}`) are not used here"),
            });
        }
        Ok(Document { text, root })
    }

    /// The document of `text` for placing fields, or, if `text` is not YAML that
    /// [`Document::parse`] accepts, an empty one that places everything at [`Mark::START`].
    pub fn index(text: &'a str) -> Document<'a> {
        Document::parse(text).unwrap_or(Document { text, root: None })
    }

    /// The typed value of the document. A wrong type is placed at the value, an unknown key at
    /// the key, a missing key at the mapping that lacks it.
    pub fn deserialize<T: DeserializeOwned>(&self) -> Result<T, ReadError> {
        let mut path = Vec::new();
        serde_saphyr::with_deserializer_from_str_with_options(self.text, options(), |de| {
            serde_path_to_error::deserialize(de).map_err(|e| {
                path = parts(e.path());
                e.into_inner()
            })
        })
        .map_err(|e| {
            let problem = match unwrap(&e) {
                SaphyrError::SerdeUnknownField { field, .. } => {
                    // serde_path_to_error has already stepped onto the unknown key.
                    if let Some(Part::Key(k)) = path.last()
                        && k == field
                    {
                        path.pop();
                    }
                    Problem::UnknownField(field.clone())
                }
                SaphyrError::SerdeMissingField { field, .. } => {
                    Problem::MissingField(field.to_string())
                }
                SaphyrError::DuplicateMappingKey { key, .. } => {
                    Problem::DuplicateKey(key.clone().unwrap_or_default())
                }
                _ => Problem::Type,
            };
            let mut err = read_error(self.text, &e, problem, &path);
            if let Problem::MissingField(_) = err.problem {
                let steps: Vec<Step<'_>> = path.iter().map(Part::step).collect();
                err.mark = self.locate_nearest(&steps, At::Key);
            }
            err
        })
    }

    /// The key or value at `path` (`at` matters only when the path ends in a key; a sequence
    /// item has only its value); the empty path is the whole document. `None` if the path is
    /// not in the text.
    pub fn locate(&self, path: &[Step<'_>], at: At) -> Option<Mark> {
        let mut node = self.root.as_ref()?;
        let mut key = None;
        for step in path {
            let (k, v) = child(node, *step)?;
            key = k;
            node = v;
        }
        Some(match (at, key) {
            (At::Key, Some(k)) => mark_of(k),
            _ => mark_of(node),
        })
    }

    /// Like [`Document::locate`], but a field that is not in the text (a missing key, an index
    /// past the end) is placed at its nearest ancestor that is (at that ancestor's key), a path
    /// with no ancestor in the text at the document's first node, and anything in a text with
    /// no node at [`Mark::START`].
    pub fn locate_nearest(&self, path: &[Step<'_>], at: At) -> Mark {
        (0..=path.len())
            .rev()
            .find_map(|n| {
                let here = if n == path.len() { at } else { At::Key };
                self.locate(&path[..n], here)
            })
            .unwrap_or(Mark::START)
    }

    /// The text of 1-based line `line` (empty past the end).
    pub fn line_text(&self, line: usize) -> &'a str {
        line_text(self.text, line)
    }

    /// The text read.
    pub fn text(&self) -> &'a str {
        self.text
    }

    /// What kind of node is at `path` (the empty path is the whole document), if it is in the
    /// text.
    pub fn shape(&self, path: &[Step<'_>]) -> Option<Shape> {
        let mut node = self.root.as_ref()?;
        for step in path {
            node = child(node, *step)?.1;
        }
        Some(match node.value.0 {
            Node::Scalar => Shape::Scalar,
            Node::Sequence(_) => Shape::Sequence,
            Node::Mapping(_) => Shape::Mapping,
        })
    }
}

/// The kind of a YAML node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// A single value (or null).
    Scalar,
    /// A list.
    Sequence,
    /// A mapping of keys to values.
    Mapping,
}

impl fmt::Display for Shape {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Shape::Scalar => "a single value",
            Shape::Sequence => "a list",
            Shape::Mapping => "a mapping",
        })
    }
}

/// The mark of `path` in `text` as [`Document::locate_nearest`] finds it, with the text of
/// its line: for errors found long after the text was read. Text that is not YAML places
/// everything at [`Mark::START`].
pub fn locate_nearest(text: &str, path: &[Step<'_>], at: At) -> (Mark, String) {
    let doc = Document::index(text);
    let mark = doc.locate_nearest(path, at);
    (mark, doc.line_text(mark.line).to_string())
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
    if parent.is_empty() {
        key.to_string()
    } else {
        format!("{parent}.{key}")
    }
}

/// The text of 1-based line `line` of `text` (empty past the end).
pub fn line_text(text: &str, line: usize) -> &str {
    line.checked_sub(1)
        .and_then(|i| text.lines().nth(i))
        .unwrap_or("")
}

/// An annotate-snippets snippet of one line of text, numbered `line`, with the `width`
/// characters from 1-based `column` underlined (a column past the end is kept by padding the
/// line, so that the snippet's own `line:column` is the mark's).
pub fn excerpt(
    text: &str,
    line: usize,
    column: usize,
    width: usize,
) -> Snippet<'static, Annotation<'static>> {
    let mut text = text.to_string();
    let start = column.max(1) - 1;
    let len = text.chars().count();
    if start > len {
        // A mark is at most one past its line's end; the cap only bounds a bad one.
        text.extend(std::iter::repeat_n(' ', (start - len).min(1 << 12)));
    }
    let byte = |chars: usize| {
        text.char_indices()
            .nth(chars)
            .map_or(text.len(), |(i, _)| i)
    };
    let span = byte(start)..byte(start + width.max(1));
    Snippet::source(text.clone())
        .line_start(line)
        .annotation(AnnotationKind::Primary.span(span))
}

// ---------------------------------------------------------------------------------------------

/// The deserializer's options: NaN and infinities pass as numbers (scenes and specs refuse them
/// with a message of their own), no snippet in errors (the caller renders its own), and only
/// YAML 1.2's `true` and `false` are booleans: `y`, `n`, `yes`, `no`, `on` and `off` are names
/// (a coordinate `y`, a mass ratio `n`), which YAML 1.1 would have read as booleans.
fn options() -> serde_saphyr::Options {
    serde_saphyr::options! {
        non_finite_float_policy: serde_saphyr::NonFiniteFloatPolicy::PassThrough,
        with_snippet: false,
        strict_booleans: true,
    }
}

/// One step of a path as serde_path_to_error recorded it.
#[derive(Debug, Clone)]
enum Part {
    Key(String),
    Index(usize),
}

impl Part {
    fn step(&self) -> Step<'_> {
        match self {
            Part::Key(k) => Step::Key(k),
            Part::Index(i) => Step::Index(*i),
        }
    }
}

/// The keys and indices of a serde_path_to_error path (enum variants and unknown steps,
/// such as a key not yet read, are not places in the text).
fn parts(path: &serde_path_to_error::Path) -> Vec<Part> {
    path.iter()
        .filter_map(|s| match s {
            serde_path_to_error::Segment::Map { key } => Some(Part::Key(key.clone())),
            serde_path_to_error::Segment::Seq { index } => Some(Part::Index(*index)),
            _ => None,
        })
        .collect()
}

/// `parameters.m1`, `bodies[0].position[1]`.
fn path_text(parts: &[Part]) -> String {
    let mut s = String::new();
    for p in parts {
        match p {
            Part::Key(k) => s = join_key(&s, k),
            Part::Index(i) => s.push_str(&format!("[{i}]")),
        }
    }
    s
}

/// The error itself, without the wrappers that add a snippet or the alias it was reached by.
fn unwrap(mut e: &SaphyrError) -> &SaphyrError {
    loop {
        match e.without_snippet() {
            SaphyrError::AliasError { error, .. } => e = error,
            inner if std::ptr::eq(inner, e) => return e,
            inner => e = inner,
        }
    }
}

/// A serde-saphyr error as a [`ReadError`]: at the failing node's own location (inside an
/// anchor for a value reached through an alias), with a message that shows the token read.
fn read_error(text: &str, e: &SaphyrError, problem: Problem, path: &[Part]) -> ReadError {
    let inner = unwrap(e);
    let location = inner
        .location()
        .or_else(|| e.location())
        .filter(|l| l.line() > 0);
    let mark = location.map_or(Mark::START, |l| Mark {
        line: usize::try_from(l.line()).unwrap_or(usize::MAX),
        column: usize::try_from(l.column()).unwrap_or(usize::MAX).max(1),
        width: usize::try_from(l.span().len()).unwrap_or(1).max(1),
    });
    // The token at the location, when it is a plain piece of one line.
    let token = location
        .and_then(|l| {
            let span = l.span();
            let from = usize::try_from(span.byte_offset()?).ok()?;
            let len = usize::try_from(span.byte_len()?).ok()?;
            text.get(from..from.checked_add(len)?)
        })
        .filter(|t| !t.is_empty() && t.chars().count() <= 60 && !t.contains(['\n', '\r']));
    let message = match (inner, token) {
        (SaphyrError::InvalidScalar { ty, .. }, Some(t)) => {
            format!("expected {ty}, found `{}`", printable(t))
        }
        (SaphyrError::Unexpected { expected, .. }, Some(t)) => {
            format!("expected {expected}, found `{}`", printable(t))
        }
        _ => printable(&UserMessageFormatter.format_message(inner)),
    };
    ReadError {
        problem,
        path: path_text(path),
        mark,
        message,
    }
}

/// `s` with control characters escaped (`\u{1b}`), so that text from a file never reaches a
/// terminal as a control sequence.
fn printable(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_control() {
                c.escape_debug().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// The document as a tree of spanned nodes, read by serde-saphyr itself.

/// A node with its place (where it is defined, for a value reached through an alias) and its
/// tag.
type Item = Spanned<Tagged<Node>>;

/// A YAML node: what a path can step into.
enum Node {
    Scalar,
    Sequence(Vec<Item>),
    Mapping(Vec<(Spanned<Key>, Item)>),
}

/// A mapping key as written (`None` for a null key).
struct Key(Option<String>);

impl<'de> Deserialize<'de> for Node {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Node, D::Error> {
        d.deserialize_any(NodeVisitor)
    }
}

struct NodeVisitor;

impl<'de> Visitor<'de> for NodeVisitor {
    type Value = Node;
    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("any YAML node")
    }
    fn visit_bool<E: de::Error>(self, _: bool) -> Result<Node, E> {
        Ok(Node::Scalar)
    }
    fn visit_i64<E: de::Error>(self, _: i64) -> Result<Node, E> {
        Ok(Node::Scalar)
    }
    fn visit_u64<E: de::Error>(self, _: u64) -> Result<Node, E> {
        Ok(Node::Scalar)
    }
    fn visit_i128<E: de::Error>(self, _: i128) -> Result<Node, E> {
        Ok(Node::Scalar)
    }
    fn visit_u128<E: de::Error>(self, _: u128) -> Result<Node, E> {
        Ok(Node::Scalar)
    }
    fn visit_f64<E: de::Error>(self, _: f64) -> Result<Node, E> {
        Ok(Node::Scalar)
    }
    fn visit_str<E: de::Error>(self, _: &str) -> Result<Node, E> {
        Ok(Node::Scalar)
    }
    fn visit_bytes<E: de::Error>(self, _: &[u8]) -> Result<Node, E> {
        Ok(Node::Scalar)
    }
    fn visit_unit<E: de::Error>(self) -> Result<Node, E> {
        Ok(Node::Scalar)
    }
    fn visit_none<E: de::Error>(self) -> Result<Node, E> {
        Ok(Node::Scalar)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Node, A::Error> {
        let mut items = Vec::new();
        while let Some(item) = seq.next_element()? {
            items.push(item);
        }
        Ok(Node::Sequence(items))
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Node, A::Error> {
        let mut entries = Vec::new();
        while let Some(key) = map.next_key()? {
            entries.push((key, map.next_value()?));
        }
        Ok(Node::Mapping(entries))
    }
}

impl<'de> Deserialize<'de> for Key {
    /// As written: read as a string (as serde reads a schema's keys), or null.
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Key, D::Error> {
        d.deserialize_option(KeyVisitor)
    }
}

struct KeyVisitor;

impl<'de> Visitor<'de> for KeyVisitor {
    type Value = Key;
    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a scalar mapping key")
    }
    fn visit_none<E: de::Error>(self) -> Result<Key, E> {
        Ok(Key(None))
    }
    fn visit_unit<E: de::Error>(self) -> Result<Key, E> {
        Ok(Key(None))
    }
    fn visit_some<D: Deserializer<'de>>(self, d: D) -> Result<Key, D::Error> {
        d.deserialize_str(self)
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<Key, E> {
        Ok(Key(Some(v.to_string())))
    }
}

/// Where a spanned value is defined, and how much of its line it covers: a scalar or a key
/// whole, a collection its opening token; a block mapping, which has none, its first key.
fn mark_of<T>(item: &Spanned<T>) -> Mark
where
    T: AsNode,
{
    let at = item.defined;
    let mut width = usize::try_from(at.span().len()).unwrap_or(1);
    if width == 0
        && let Some(Node::Mapping(entries)) = item.value.node()
        && let Some((first, _)) = entries.first()
        && first.defined.line() == at.line()
        && first.defined.column() == at.column()
    {
        width = usize::try_from(first.defined.span().len()).unwrap_or(1);
    }
    Mark {
        line: usize::try_from(at.line()).unwrap_or(usize::MAX).max(1),
        column: usize::try_from(at.column()).unwrap_or(usize::MAX).max(1),
        width: width.max(1),
    }
}

/// What a spanned value holds, for [`mark_of`]: a node (behind its tag) or a key.
trait AsNode {
    fn node(&self) -> Option<&Node>;
}

impl AsNode for Tagged<Node> {
    fn node(&self) -> Option<&Node> {
        Some(&self.0)
    }
}

impl AsNode for Key {
    fn node(&self) -> Option<&Node> {
        None
    }
}

/// The (key, value) one step below `item`; a sequence item has no key.
fn child<'n>(item: &'n Item, step: Step<'_>) -> Option<(Option<&'n Spanned<Key>>, &'n Item)> {
    match (step, &item.value.0) {
        (Step::Key(want), Node::Mapping(entries)) => entries
            .iter()
            .find(|(k, _)| k.value.0.as_deref() == Some(want))
            .map(|(k, v)| (Some(k), v)),
        (Step::Index(i), Node::Sequence(items)) => items.get(i).map(|v| (None, v)),
        _ => None,
    }
}

/// The first tagged node in document order, with its path (`path` is the walk's stack). The
/// tree's depth is bounded by serde-saphyr's budget.
fn first_tag<'n>(item: &'n Item, path: &mut Vec<Part>) -> Option<(String, &'n Item)> {
    if item.value.1.is_some() {
        return Some((path_text(path), item));
    }
    match &item.value.0 {
        Node::Scalar => None,
        Node::Sequence(items) => items.iter().enumerate().find_map(|(i, v)| {
            path.push(Part::Index(i));
            let found = first_tag(v, path);
            path.pop();
            found
        }),
        Node::Mapping(entries) => entries.iter().find_map(|(k, v)| {
            path.push(Part::Key(k.value.0.clone().unwrap_or_else(|| "~".into())));
            let found = first_tag(v, path);
            path.pop();
            found
        }),
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

    fn at(doc: &Document<'_>, path: &[Step<'_>], at: At) -> Option<(usize, usize)> {
        doc.locate(path, at).map(|m| (m.line, m.column))
    }

    #[test]
    fn locates_keys_and_values_in_block_and_flow_layouts() {
        let doc = Document::parse(DOC).unwrap();
        let p = |s| parse_path(s);
        assert_eq!(at(&doc, &p("model"), At::Key), Some((2, 1)));
        assert_eq!(at(&doc, &p("model"), At::Value), Some((2, 8)));
        assert_eq!(at(&doc, &p("parameters.m1"), At::Key), Some((4, 3)));
        assert_eq!(at(&doc, &p("parameters.m2"), At::Key), Some((5, 3)));
        assert_eq!(at(&doc, &p("parameters.m2"), At::Value), Some((5, 9)));
        assert_eq!(at(&doc, &p("want[2]"), At::Value), Some((7, 3)));
        assert_eq!(at(&doc, &p("flow.y.z"), At::Value), Some((8, 21)));
        assert_eq!(at(&doc, &p("parameters.g"), At::Key), None);
        assert_eq!(at(&doc, &p("want[5]"), At::Value), None);
        // The empty path is the document.
        assert_eq!(at(&doc, &[], At::Key), Some((2, 1)));
        // Widths cover the token: a quoted key with its quotes, a value.
        let m2 = doc.locate(&p("parameters.m2"), At::Key).unwrap();
        assert_eq!(m2.width, 4);
        assert_eq!(doc.locate(&p("model"), At::Value).unwrap().width, 8);
    }

    #[test]
    fn locates_keys_and_items_in_sequences_of_mappings() {
        let doc = Document::parse(SPEC).unwrap();
        assert_eq!(at(&doc, &[Key("name")], At::Key), Some((1, 1)));
        assert_eq!(at(&doc, &[Key("name")], At::Value), Some((1, 7)));
        assert_eq!(
            at(&doc, &[Key("parameters"), Index(1)], At::Key),
            Some((4, 5))
        );
        let unit = |i| [Key("parameters"), Index(i), Key("unit")];
        assert_eq!(at(&doc, &unit(1), At::Key), Some((5, 5)));
        assert_eq!(at(&doc, &unit(0), At::Key), Some((3, 16)));
        let pos = [Key("bodies"), Index(0), Key("position"), Index(1)];
        assert_eq!(at(&doc, &pos, At::Key), Some((8, 28)));
        assert_eq!(at(&doc, &[Key("values"), Key("a")], At::Key), Some((9, 19)));
    }

    #[test]
    fn aliases_are_placed_where_they_are_defined() {
        let doc = Document::parse("base: &b {x: 1}\nuse: *b\n").unwrap();
        assert_eq!(at(&doc, &[Key("use")], At::Key), Some((2, 1)));
        assert_eq!(at(&doc, &[Key("use")], At::Value), Some((1, 10)));
        assert_eq!(at(&doc, &[Key("use"), Key("x")], At::Value), Some((1, 14)));
        // As the parser places its own errors.
        #[derive(Debug, serde::Deserialize)]
        #[allow(dead_code)]
        struct Uses {
            base: std::collections::BTreeMap<String, String>,
            r#use: std::collections::BTreeMap<String, f64>,
        }
        let doc = Document::parse("base: &b {x: y}\nuse: *b\n").unwrap();
        let e = doc.deserialize::<Uses>().err().unwrap();
        assert_eq!(
            (e.path.as_str(), e.mark.line, e.mark.column),
            ("use.x", 1, 14)
        );
    }

    #[test]
    fn tabs_separate_tokens_within_a_line() {
        // Valid YAML (tabs are refused only as indentation), which some parsers refuse.
        let doc = Document::parse("model:\trod_cube\nlist: [a,\tb]\n").unwrap();
        assert_eq!(at(&doc, &[Key("model")], At::Value), Some((1, 8)));
        assert_eq!(at(&doc, &[Key("list"), Index(1)], At::Value), Some((2, 11)));
        let e = Document::parse("model: rod_cube\nparameters:\n\tm1: 1.0\n")
            .err()
            .unwrap();
        assert_eq!((e.problem, e.mark.line), (Problem::Syntax, 3));
    }

    #[test]
    fn nearest_falls_back_to_the_deepest_ancestor_found() {
        let doc = Document::parse(SPEC).unwrap();
        let pos = |m: Mark| (m.line, m.column);
        assert_eq!(
            pos(doc.locate_nearest(&[Key("bodies"), Index(3)], At::Value)),
            (6, 1)
        );
        let missing = [Key("parameters"), Index(1), Key("dimension")];
        assert_eq!(pos(doc.locate_nearest(&missing, At::Key)), (4, 5));
        assert_eq!(pos(doc.locate_nearest(&[Key("nothing")], At::Key)), (1, 1));
        let (mark, line) = locate_nearest("", &[Key("nothing")], At::Key);
        assert_eq!((mark, line.as_str()), (Mark::START, ""));
        let (mark, line) = locate_nearest("a: [1\n", &[Key("a")], At::Key);
        assert_eq!((mark, line.as_str()), (Mark::START, "a: [1"));
    }

    #[test]
    fn the_first_pass_finds_syntax_errors_duplicates_and_tags() {
        assert!(Document::parse(DOC).is_ok());
        let e = Document::parse("a: 1\nb:\n  c: 2\n  c: 3\n").err().unwrap();
        assert_eq!(e.problem, Problem::DuplicateKey("c".into()));
        assert_eq!((e.path.as_str(), e.field().as_str()), ("b", "b.c"));
        assert_eq!((e.mark.line, e.mark.column), (4, 3));
        let e = Document::parse("a: 1\nb: [x, !tag 1]\n").err().unwrap();
        assert_eq!(
            (e.problem, e.path.as_str()),
            (Problem::Tag("!tag".into()), "b[1]")
        );
        // At the tagged value.
        assert_eq!((e.mark.line, e.mark.column), (2, 13));
        let e = Document::parse("a: [1, 2\n").err().unwrap();
        assert_eq!((e.problem, e.path.as_str()), (Problem::Syntax, "a"));
        let e = Document::parse("a: 1\n---\nb: 2\n").err().unwrap();
        assert_eq!(e.problem, Problem::Syntax);
        // Nesting past the parser's depth limit is refused before any tree is built.
        let deep = "[".repeat(10_000);
        assert_eq!(
            Document::parse(&deep).err().unwrap().problem,
            Problem::Syntax
        );
    }

    #[derive(Debug, serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Item {
        name: String,
        size: f64,
    }

    #[derive(Debug, serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Top {
        items: Vec<Item>,
    }

    fn typed_error(text: &str) -> ReadError {
        Document::parse(text)
            .unwrap()
            .deserialize::<Top>()
            .err()
            .unwrap()
    }

    #[test]
    fn typed_errors_name_their_field_and_place() {
        let e = typed_error("items:\n  - name: a\n    size: big\n");
        assert_eq!(
            (e.problem.clone(), e.path.as_str()),
            (Problem::Type, "items[0].size")
        );
        assert_eq!((e.mark.line, e.mark.column, e.mark.width), (3, 11, 3));
        assert!(e.message.contains("`big`"), "{}", e.message);
        let e = typed_error("items:\n  - {name: a, size: 1, colour: red}\n");
        assert_eq!(e.problem, Problem::UnknownField("colour".into()));
        assert_eq!(
            (e.path.as_str(), e.field().as_str()),
            ("items[0]", "items[0].colour")
        );
        assert_eq!((e.mark.line, e.mark.column), (2, 24));
        let e = typed_error("items:\n  - name: a\n  - name: b\n    size: 2\n");
        assert_eq!(e.problem, Problem::MissingField("size".into()));
        assert_eq!(e.field(), "items[0].size");
        // At the mapping that lacks it.
        assert_eq!((e.mark.line, e.mark.column), (2, 5));
        let e = typed_error("items: 3\n");
        assert_eq!(
            (e.problem.clone(), e.path.as_str()),
            (Problem::Type, "items")
        );
        assert_eq!((e.mark.line, e.mark.column), (1, 8));
        let doc = Document::parse("items: 3\nlist: [a]\n").unwrap();
        assert_eq!(doc.shape(&[Key("items")]), Some(Shape::Scalar));
        assert_eq!(doc.shape(&[Key("list")]), Some(Shape::Sequence));
        assert_eq!(doc.shape(&[]), Some(Shape::Mapping));
        assert_eq!(doc.shape(&[Key("none")]), None);
    }

    #[test]
    fn excerpts_underline_the_token_and_keep_the_column() {
        let render = |s| {
            annotate_snippets::Renderer::plain().render(&[annotate_snippets::Level::ERROR
                .primary_title("t")
                .element(s)])
        };
        let shown = render(excerpt("  m1: -1.0  # c", 3, 7, 4).path("f.yaml"));
        assert!(shown.contains("--> f.yaml:3:7"), "{shown}");
        assert!(
            shown.contains("3 |   m1: -1.0  # c\n  |       ^^^^"),
            "{shown}"
        );
        // Past the end of the line, the column is still the mark's.
        let shown = render(excerpt("ab", 2, 6, 1).path("f.yaml"));
        assert!(shown.contains("--> f.yaml:2:6"), "{shown}");
        let shown = render(excerpt("é: ü", 1, 4, 1).path("f.yaml"));
        assert!(shown.contains("--> f.yaml:1:4"), "{shown}");
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
