//! Typed reads of the glTF JSON: each field is checked for its JSON type and range, and every
//! index against the array it points into, before anything uses it. Numbers the glTF schema
//! types as float are rounded to f32 as glTF stores them; `null` counts as absent.
use serde_json::{Map, Value};

/// A JSON object.
pub type Obj = Map<String, Value>;

/// `v` as an object, or a problem naming `what`.
pub fn object<'a>(v: &'a Value, what: &str) -> Result<&'a Obj, String> {
    v.as_object().ok_or_else(|| format!("{what} must be a JSON object, got {}", short(v)))
}

/// The array at `key` (empty when absent).
pub fn array<'a>(o: &'a Obj, key: &str, what: &str) -> Result<&'a [Value], String> {
    match o.get(key) {
        None | Some(Value::Null) => Ok(&[]),
        Some(Value::Array(a)) => Ok(a),
        Some(v) => Err(lead(what, format!("`{key}` must be an array, got {}", short(v)))),
    }
}

/// A non-negative integer at `key`, if present.
pub fn opt_uint(o: &Obj, key: &str, what: &str) -> Result<Option<u64>, String> {
    match o.get(key) {
        None | Some(Value::Null) => Ok(None),
        Some(v) => v
            .as_u64()
            .map(Some)
            .ok_or_else(|| lead(what, format!("`{key}` must be a non-negative integer, got {}", short(v)))),
    }
}

/// A required non-negative integer at `key`.
pub fn uint(o: &Obj, key: &str, what: &str) -> Result<u64, String> {
    opt_uint(o, key, what)?.ok_or_else(|| missing(what, key))
}

/// An optional index at `key` into an array of `len` `things`.
pub fn opt_index(o: &Obj, key: &str, len: usize, things: &str, what: &str) -> Result<Option<usize>, String> {
    match opt_uint(o, key, what)? {
        None => Ok(None),
        Some(i) => in_range(i, len, things).map(Some).map_err(|e| lead(what, format!("`{key}` {e}"))),
    }
}

/// A required index at `key` into an array of `len` `things`.
pub fn index(o: &Obj, key: &str, len: usize, things: &str, what: &str) -> Result<usize, String> {
    opt_index(o, key, len, things, what)?.ok_or_else(|| missing(what, key))
}

/// Checks an index value `v` against an array of `len` `things`.
pub fn index_value(v: &Value, len: usize, things: &str, what: &str) -> Result<usize, String> {
    let i = v.as_u64().ok_or_else(|| format!("{what} must be a non-negative integer, got {}", short(v)))?;
    in_range(i, len, things).map_err(|e| format!("{what} {e}"))
}

/// `problem` about a field of `what` (nothing to prefix when `what` is empty: the caller's
/// context already names the object).
fn lead(what: &str, problem: String) -> String {
    if what.is_empty() {
        problem
    } else {
        format!("{what}: {problem}")
    }
}

fn missing(what: &str, key: &str) -> String {
    if what.is_empty() {
        format!("`{key}` is missing, and glTF requires it")
    } else {
        format!("{what} has no `{key}`, which glTF requires")
    }
}

fn in_range(i: u64, len: usize, things: &str) -> Result<usize, String> {
    if i < len as u64 {
        Ok(i as usize)
    } else {
        Err(format!("is {i}, but the file has {len} {things}"))
    }
}

/// An optional string at `key`.
pub fn opt_str<'a>(o: &'a Obj, key: &str, what: &str) -> Result<Option<&'a str>, String> {
    match o.get(key) {
        None | Some(Value::Null) => Ok(None),
        Some(Value::String(s)) => Ok(Some(s)),
        Some(v) => Err(lead(what, format!("`{key}` must be a string, got {}", short(v)))),
    }
}

/// An optional boolean at `key`.
pub fn opt_bool(o: &Obj, key: &str, what: &str) -> Result<Option<bool>, String> {
    match o.get(key) {
        None | Some(Value::Null) => Ok(None),
        Some(Value::Bool(b)) => Ok(Some(*b)),
        Some(v) => Err(lead(what, format!("`{key}` must be true or false, got {}", short(v)))),
    }
}

/// An optional array of exactly `N` numbers at `key`, each rounded to f32 as glTF stores it.
pub fn opt_floats<const N: usize>(o: &Obj, key: &str, what: &str) -> Result<Option<[f64; N]>, String> {
    let v = match o.get(key) {
        None | Some(Value::Null) => return Ok(None),
        Some(v) => v,
    };
    let bad = || lead(what, format!("`{key}` must be an array of {N} numbers, got {}", short(v)));
    let a = v.as_array().filter(|a| a.len() == N).ok_or_else(bad)?;
    let mut out = [0.0; N];
    for (x, e) in out.iter_mut().zip(a) {
        *x = f64::from(e.as_f64().ok_or_else(bad)? as f32);
    }
    Ok(Some(out))
}

/// At most this many characters of a value are quoted in a message.
const QUOTE_MAX: usize = 40;

/// A value as short JSON text for messages.
pub fn short(v: &Value) -> String {
    let s = v.to_string();
    if s.chars().count() <= QUOTE_MAX {
        s
    } else {
        format!("{}…", s.chars().take(QUOTE_MAX).collect::<String>())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn typed_reads_refuse_wrong_types_and_ranges() {
        let v = json!({"a": 3, "neg": -1, "big": 1099511627776u64, "f": 1.5, "s": "x", "v": [1, 2, 3],
                       "n": null, "t": true});
        let o = object(&v, "thing").unwrap();
        assert_eq!(opt_uint(o, "a", "x"), Ok(Some(3)));
        assert_eq!(opt_uint(o, "n", "x"), Ok(None));
        assert!(opt_uint(o, "neg", "x").unwrap_err().contains("non-negative integer, got -1"));
        assert!(opt_uint(o, "f", "x").unwrap_err().contains("got 1.5"));
        assert!(uint(o, "missing", "accessor 2").unwrap_err().contains("accessor 2 has no `missing`"));
        let e = opt_index(o, "big", 4, "buffer views", "accessor 0").unwrap_err();
        assert!(e.contains("`big` is 1099511627776, but the file has 4 buffer views"), "{e}");
        assert_eq!(index(o, "a", 4, "nodes", "x"), Ok(3));
        assert!(index(o, "a", 3, "nodes", "x").is_err());
        assert_eq!(opt_floats::<3>(o, "v", "x"), Ok(Some([1.0, 2.0, 3.0])));
        assert!(opt_floats::<4>(o, "v", "x").unwrap_err().contains("array of 4 numbers"));
        assert_eq!(opt_str(o, "s", "x"), Ok(Some("x")));
        assert!(opt_str(o, "a", "x").is_err() && opt_bool(o, "a", "x").is_err());
        assert_eq!(opt_bool(o, "t", "x"), Ok(Some(true)));
        assert!(array(o, "a", "x").is_err() && array(o, "missing", "x").unwrap().is_empty());
        assert!(object(&json!([1]), "the node").unwrap_err().contains("the node must be a JSON object"));
        assert!(short(&json!("x".repeat(100))).ends_with('…'));
    }
}
