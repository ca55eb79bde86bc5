//! A tiny JSON object writer for `--stats` output.
//!
//! Design: the statistics are a small, mostly flat object of counters, times
//! and names, so a full serialisation framework is not needed. [`JsonObject`]
//! keeps its fields in insertion order (so the output is stable and easy to
//! diff) and renders either compactly ([`std::fmt::Display`]) or indented
//! ([`JsonObject::to_pretty_string`]). Strings are escaped per RFC 8259;
//! non-finite floats, which JSON cannot express, are written as `null`.
//! Duplicate keys are not checked: the caller owns the key set.

use std::fmt::{self, Write};

#[derive(Clone, Debug, PartialEq)]
enum Value {
    U64(u64),
    I64(i64),
    F64(f64),
    Bool(bool),
    Str(String),
    Obj(JsonObject),
}

/// An ordered JSON object under construction.
///
/// ```
/// use microraster_host::json::JsonObject;
/// let mut inner = JsonObject::new();
/// inner.field_u64("drawn", 12);
/// let mut o = JsonObject::new();
/// o.field_str("scene", "cubes").field_f64("ms", 1.5).field_obj("tris", &inner);
/// assert_eq!(o.to_string(), r#"{"scene":"cubes","ms":1.5,"tris":{"drawn":12}}"#);
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JsonObject {
    fields: Vec<(String, Value)>,
}

impl JsonObject {
    /// An empty object.
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of fields added so far.
    pub fn len(&self) -> usize {
        self.fields.len()
    }

    /// Whether no field has been added.
    pub fn is_empty(&self) -> bool {
        self.fields.is_empty()
    }

    fn push(&mut self, key: &str, value: Value) -> &mut Self {
        self.fields.push((key.to_owned(), value));
        self
    }

    /// Adds an unsigned integer field.
    pub fn field_u64(&mut self, key: &str, value: u64) -> &mut Self {
        self.push(key, Value::U64(value))
    }

    /// Adds a signed integer field.
    pub fn field_i64(&mut self, key: &str, value: i64) -> &mut Self {
        self.push(key, Value::I64(value))
    }

    /// Adds a floating-point field; NaN and infinities are written as `null`.
    pub fn field_f64(&mut self, key: &str, value: f64) -> &mut Self {
        self.push(key, Value::F64(value))
    }

    /// Adds a boolean field.
    pub fn field_bool(&mut self, key: &str, value: bool) -> &mut Self {
        self.push(key, Value::Bool(value))
    }

    /// Adds a string field (escaped on output).
    pub fn field_str(&mut self, key: &str, value: &str) -> &mut Self {
        self.push(key, Value::Str(value.to_owned()))
    }

    /// Adds a nested object field (a copy of `value`).
    pub fn field_obj(&mut self, key: &str, value: &JsonObject) -> &mut Self {
        self.push(key, Value::Obj(value.clone()))
    }

    /// Renders the object over several lines, indented by two spaces.
    pub fn to_pretty_string(&self) -> String {
        let mut out = String::new();
        self.write_to(&mut out, Some(0));
        out
    }

    /// `indent`: `None` for compact output, `Some(level)` for pretty output.
    fn write_to(&self, out: &mut String, indent: Option<usize>) {
        if self.fields.is_empty() {
            out.push_str("{}");
            return;
        }
        out.push('{');
        for (i, (key, value)) in self.fields.iter().enumerate() {
            if i > 0 {
                out.push(',');
            }
            if let Some(level) = indent {
                out.push('\n');
                push_indent(out, level + 1);
            }
            write_string(out, key);
            out.push(':');
            if indent.is_some() {
                out.push(' ');
            }
            match value {
                Value::U64(v) => {
                    let _ = write!(out, "{v}");
                }
                Value::I64(v) => {
                    let _ = write!(out, "{v}");
                }
                Value::F64(v) if v.is_finite() => {
                    // `Debug` gives the shortest round-trip form and uses an
                    // exponent for very large/small values ("1e300", "1e-7"),
                    // both valid JSON numbers.
                    let _ = write!(out, "{v:?}");
                }
                Value::F64(_) => out.push_str("null"),
                Value::Bool(v) => out.push_str(if *v { "true" } else { "false" }),
                Value::Str(s) => write_string(out, s),
                Value::Obj(o) => o.write_to(out, indent.map(|l| l + 1)),
            }
        }
        if let Some(level) = indent {
            out.push('\n');
            push_indent(out, level);
        }
        out.push('}');
    }
}

impl fmt::Display for JsonObject {
    /// Compact, single-line JSON.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut out = String::new();
        self.write_to(&mut out, None);
        f.write_str(&out)
    }
}

fn push_indent(out: &mut String, level: usize) {
    for _ in 0..level {
        out.push_str("  ");
    }
}

/// Writes `s` as a quoted, escaped JSON string.
fn write_string(out: &mut String, s: &str) {
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            '\u{8}' => out.push_str("\\b"),
            '\u{c}' => out.push_str("\\f"),
            c if u32::from(c) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", u32::from(c));
            }
            c => out.push(c),
        }
    }
    out.push('"');
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::Value as J;

    fn parse(s: &str) -> J {
        serde_json::from_str(s).unwrap_or_else(|e| panic!("invalid JSON {s:?}: {e}"))
    }

    #[test]
    fn empty_object() {
        let o = JsonObject::new();
        assert!(o.is_empty());
        assert_eq!(o.to_string(), "{}");
        assert_eq!(o.to_pretty_string(), "{}");
    }

    #[test]
    fn all_value_kinds_parse_back() {
        let mut inner = JsonObject::new();
        inner
            .field_u64("a", 1)
            .field_obj("empty", &JsonObject::new());
        let mut o = JsonObject::new();
        o.field_u64("u", u64::MAX)
            .field_i64("i", i64::MIN)
            .field_f64("f", 0.1)
            .field_f64("big", 1e300)
            .field_f64("small", -1e-7)
            .field_f64("whole", 2.0)
            .field_f64("nan", f64::NAN)
            .field_f64("inf", f64::NEG_INFINITY)
            .field_bool("t", true)
            .field_bool("f2", false)
            .field_str("s", "cubes")
            .field_obj("inner", &inner);
        assert_eq!(o.len(), 12);
        for text in [o.to_string(), o.to_pretty_string()] {
            let v = parse(&text);
            assert_eq!(v["u"].as_u64(), Some(u64::MAX));
            assert_eq!(v["i"].as_i64(), Some(i64::MIN));
            assert_eq!(v["f"].as_f64(), Some(0.1));
            assert_eq!(v["big"].as_f64(), Some(1e300));
            assert_eq!(v["small"].as_f64(), Some(-1e-7));
            assert_eq!(v["whole"].as_f64(), Some(2.0));
            assert!(v["nan"].is_null());
            assert!(v["inf"].is_null());
            assert_eq!(v["t"], J::Bool(true));
            assert_eq!(v["f2"], J::Bool(false));
            assert_eq!(v["s"], J::String("cubes".into()));
            assert_eq!(v["inner"]["a"].as_u64(), Some(1));
            assert!(v["inner"]["empty"].as_object().unwrap().is_empty());
        }
    }

    #[test]
    fn field_order_is_kept() {
        let mut o = JsonObject::new();
        o.field_u64("z", 1).field_u64("a", 2).field_u64("m", 3);
        assert_eq!(o.to_string(), r#"{"z":1,"a":2,"m":3}"#);
        assert_eq!(
            o.to_pretty_string(),
            "{\n  \"z\": 1,\n  \"a\": 2,\n  \"m\": 3\n}"
        );
    }

    #[test]
    fn strings_are_escaped() {
        let nasty = "q\"b\\s/n\nr\rt\tb\u{8}f\u{c}nul\u{0}us\u{1f}é😀\u{2028}";
        let mut o = JsonObject::new();
        o.field_str(nasty, nasty);
        let text = o.to_string();
        assert!(!text.contains('\n'));
        assert!(text.contains("\\u0000") && text.contains("\\u001f"));
        let v = parse(&text);
        assert_eq!(v[nasty], J::String(nasty.into()));
    }

    #[test]
    fn nested_pretty_indentation() {
        let mut inner = JsonObject::new();
        inner.field_u64("x", 1);
        let mut o = JsonObject::new();
        o.field_obj("in", &inner);
        assert_eq!(o.to_pretty_string(), "{\n  \"in\": {\n    \"x\": 1\n  }\n}");
    }
}
