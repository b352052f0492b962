//! Facts, origins, numbers and nail lists in the words the explanations print.

use crate::logic::provenance::Explanation;
use crate::logic::tokens::{Kind, map_tokens};
use crate::logic::{Origin, Value};

/// A fact as `relation(a, b, …)`, numbers shortened.
pub fn fact(e: &Explanation) -> String {
    let args: Vec<String> = e.tuple.iter().map(short_value).collect();
    format!("{}({})", e.relation, args.join(", "))
}

/// Where a fact comes from: the IFC entity, the cell file and key, the rule file and line,
/// the simulation event.
pub fn origin_text(relation: &str, tuple: &[Value], origin: &Origin) -> String {
    match origin {
        Origin::Entity(n) => format!("IFC #{n}"),
        Origin::File { file, line: 0 } if relation.starts_with("cell_") => {
            let key = tuple.first().and_then(Value::as_symbol).unwrap_or("");
            format!("cell {file}, key {key}")
        }
        Origin::File { file, line } => format!("{file}:{line}"),
        Origin::Event(e) => format!("simulation: {e}"),
        Origin::Rust => "input".to_string(),
    }
}

/// A value as a person reads it: numbers to 0.1 mm / 6 digits.
pub fn short_value(v: &Value) -> String {
    match v {
        Value::Symbol(s) => format!("{:?}", &**s),
        Value::Float(x) => short_float(x.0),
        Value::Vec3(_) | Value::Iso(_) | Value::Box(_) => shorten_numbers(&v.to_string()),
        other => other.to_string(),
    }
}

fn short_float(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let digits = (6 - x.abs().log10().floor() as i32).clamp(0, 9) as usize;
    let t = format!("{x:.digits$}");
    let t = if t.contains('.') {
        t.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        t
    };
    if t == "-0" { "0".into() } else { t }
}

/// Floats with more than 7 significant digits, outside quotes, shortened.
pub fn shorten_numbers(text: &str) -> String {
    map_tokens(text, |kind, word, _| {
        if kind != Kind::Number || !(word.contains('.') || word.contains('e')) {
            return None;
        }
        word.parse::<f64>().ok().map(short_float)
    })
}

/// Nails listed compactly: `A -> B #1, #2; A -> C #1`.
pub fn fold_ids(ids: &[String]) -> String {
    let mut groups: Vec<(&str, Vec<&str>)> = Vec::new();
    for id in ids {
        let (pair, k) = id.rsplit_once(" #").unwrap_or((id, ""));
        match groups.iter_mut().find(|(p, _)| *p == pair) {
            Some((_, ks)) => ks.push(k),
            None => groups.push((pair, vec![k])),
        }
    }
    groups
        .iter()
        .map(|(pair, ks)| {
            let ks: Vec<String> = ks
                .iter()
                .filter(|k| !k.is_empty())
                .map(|k| format!("#{k}"))
                .collect();
            if ks.is_empty() {
                pair.to_string()
            } else {
                format!("{pair} {}", ks.join(", "))
            }
        })
        .collect::<Vec<_>>()
        .join("; ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_shortened_outside_quotes() {
        assert_eq!(
            shorten_numbers("x(0.10000000000000001, \"1.23456789\")"),
            "x(0.1, \"1.23456789\")"
        );
        assert_eq!(shorten_numbers("a < 2.3526750000000002"), "a < 2.352675");
        assert_eq!(shorten_numbers("p_2(-1e-17, 12)"), "p_2(0, 12)");
        assert_eq!(short_float(1234.56789), "1234.568");
        assert_eq!(short_float(-0.0000001), "-0.0000001");
    }

    #[test]
    fn nails_fold_by_pair() {
        let ids: Vec<String> = ["A -> B #1", "A -> B #2", "A -> C #1"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        assert_eq!(fold_ids(&ids), "A -> B #1, #2; A -> C #1");
    }
}
