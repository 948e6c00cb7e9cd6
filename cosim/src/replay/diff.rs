//! A replayed answer against the recorded one: byte for byte (the run id and the nodes' own compute time aside), or
//! every number within a tolerance; the first field that differs is named with its index and both values.

use std::fmt;

use cosim_proto::envelope::Envelope;
use cosim_proto::trace::RawEnvelope;
use serde::de::DeserializeOwned;
use serde::Serialize;
use serde_json::Value;

/// `|replayed − recorded| ≤ atol + rtol·|recorded|`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// Relative.
    pub rtol: f64,
    /// Absolute.
    pub atol: f64,
}

/// The first difference between two messages.
#[derive(Clone, Debug, PartialEq)]
pub struct Divergence {
    /// The field (dotted path of names; `envelope.t` for the header).
    pub field: String,
    /// The index inside it (`[12][1]`), empty for a scalar; what else of it differs (`[3] (length)`, `(length)`,
    /// `byte 40`).
    pub index: String,
    /// Recorded value.
    pub recorded: String,
    /// Replayed value.
    pub replayed: String,
}

impl fmt::Display for Divergence {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // "index" before an index proper only: a top-level array's length read "field corrections index  (length)"
        // (found 2026-12-06 by the sweep of damaged traces, D25).
        let index = match self.index.as_str() {
            "" => String::new(),
            i if i.starts_with('[') => format!(" index {i}"),
            other => format!(" {other}"),
        };
        write!(
            f,
            "field {}{index}: recorded {}, replayed {}",
            self.field, self.recorded, self.replayed
        )
    }
}

fn diverged(field: &str, index: &str, recorded: impl ToString, replayed: impl ToString) -> Option<Divergence> {
    Some(Divergence {
        field: field.into(),
        index: index.into(),
        recorded: recorded.to_string(),
        replayed: replayed.to_string(),
    })
}

/// Compare two encoded envelopes of body `B` (topic `what`). `mask` clears what may differ between two correct runs
/// (a node's own compute time). `Err` when a recorded message does not decode (a damaged trace).
pub fn compare<B: DeserializeOwned + Serialize>(
    what: &'static str,
    recorded: &[u8],
    replayed: &[u8],
    tolerance: Option<Tolerance>,
    mask: fn(&mut B),
) -> anyhow::Result<Option<Divergence>> {
    let rec = RawEnvelope::split(recorded).ok_or_else(|| anyhow::anyhow!("a recorded {what} is not an envelope"))?;
    let Some(rep) = RawEnvelope::split(replayed) else {
        return Ok(diverged(
            "envelope",
            "",
            "an envelope",
            format!("{} bytes that are not one", replayed.len()),
        ));
    };
    if rec.protocol_version != rep.protocol_version {
        return Ok(diverged(
            "envelope.protocol_version",
            "",
            rec.protocol_version,
            rep.protocol_version,
        ));
    }
    if rec.step != rep.step {
        return Ok(diverged("envelope.step", "", rec.step, rep.step));
    }
    let mut a = Envelope::<B>::decode(recorded, rec.run, what)?.body;
    let mut b = match Envelope::<B>::decode(replayed, rep.run, what) {
        Ok(env) => env.body,
        Err(e) => return Ok(diverged("envelope.body", "", "a valid body", e)),
    };
    mask(&mut a);
    mask(&mut b);
    let header = (Value::from(rec.t), Value::from(rep.t));
    if let Some(d) = walk("envelope.t", "", &header.0, &header.1, tolerance) {
        return Ok(Some(d));
    }
    let bytes = |body: &B| Envelope::new("", 0, 0.0, body).encode();
    let (ea, eb) = (bytes(&a), bytes(&b));
    if tolerance.is_none() && ea == eb {
        return Ok(None);
    }
    let (va, vb) = (serde_json::to_value(&a)?, serde_json::to_value(&b)?);
    if let Some(d) = walk("", "", &va, &vb, tolerance) {
        return Ok(Some(d));
    }
    // Byte-for-byte asked, and the bytes differ where the numbers compare equal (a NaN's payload).
    match tolerance {
        Some(_) => Ok(None),
        None => {
            let at = ea
                .iter()
                .zip(&eb)
                .position(|(x, y)| x != y)
                .unwrap_or(ea.len().min(eb.len()));
            Ok(diverged(
                "body",
                &format!("byte {at}"),
                format!("{} bytes", ea.len()),
                format!("{} bytes", eb.len()),
            ))
        }
    }
}

/// The first place where `b` differs from `a`: object fields in their (alphabetical) order, arrays item by item.
fn walk(field: &str, index: &str, a: &Value, b: &Value, tol: Option<Tolerance>) -> Option<Divergence> {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            for (k, va) in x {
                let name = match field.is_empty() {
                    true => k.clone(),
                    false => format!("{field}.{k}"),
                };
                let vb = y.get(k).unwrap_or(&Value::Null);
                if let Some(d) = walk(&name, index, va, vb, tol) {
                    return Some(d);
                }
            }
            None
        }
        (Value::Array(x), Value::Array(y)) => {
            if x.len() != y.len() {
                let at = match index.is_empty() {
                    true => "(length)".to_string(),
                    false => format!("{index} (length)"),
                };
                return diverged(field, &at, x.len(), y.len());
            }
            x.iter()
                .zip(y)
                .enumerate()
                .find_map(|(i, (va, vb))| walk(field, &format!("{index}[{i}]"), va, vb, tol))
        }
        (Value::Number(x), Value::Number(y)) => match same_number(x, y, tol) {
            true => None,
            false => diverged(field, index, x, y),
        },
        _ if a == b => None,
        // Null is a NaN or an infinity (JSON has none), or a missing optional part.
        _ => diverged(field, index, describe(a), describe(b)),
    }
}

fn same_number(x: &serde_json::Number, y: &serde_json::Number, tol: Option<Tolerance>) -> bool {
    if let (Some(i), Some(j)) = (x.as_u64(), y.as_u64()) {
        if tol.is_none() || i == j {
            return i == j;
        }
    }
    let (Some(a), Some(b)) = (x.as_f64(), y.as_f64()) else {
        return x == y;
    };
    match tol {
        None => a.to_bits() == b.to_bits(),
        Some(t) => (b - a).abs() <= t.atol + t.rtol * a.abs(),
    }
}

fn describe(v: &Value) -> String {
    match v {
        Value::Null => "null (NaN, infinity or nothing)".into(),
        Value::Array(a) => format!("{} items", a.len()),
        Value::Object(_) => "a value".into(),
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cosim_proto::messages::{Correction, StepCommand};

    fn cmd(dx: f64) -> StepCommand {
        StepCommand {
            dt: 1e-4,
            corrections: vec![Correction {
                id: 3,
                dx: [0.0, dx],
                dv: [0.0; 2],
                face: None,
            }],
            roi: None,
            want_interface: true,
            want_snapshot: false,
            stop: false,
        }
    }

    fn enc(run: &str, c: StepCommand) -> Vec<u8> {
        Envelope::new(run, 7, 0.5, c).encode()
    }

    #[test]
    fn same_body_under_another_run_id_matches() {
        let d = compare::<StepCommand>("c", &enc("a", cmd(1.0)), &enc("bb", cmd(1.0)), None, |_| {}).unwrap();
        assert_eq!(d, None);
    }

    #[test]
    fn one_ulp_is_named_with_field_and_index() {
        let off = f64::from_bits(1.0f64.to_bits() + 1);
        let d = compare::<StepCommand>("c", &enc("a", cmd(1.0)), &enc("a", cmd(off)), None, |_| {})
            .unwrap()
            .unwrap();
        assert_eq!((d.field.as_str(), d.index.as_str()), ("corrections.dx", "[0][1]"));
        assert_eq!(
            (d.recorded.as_str(), d.replayed.as_str()),
            ("1.0", "1.0000000000000002")
        );
        let tol = Some(Tolerance { rtol: 1e-12, atol: 0.0 });
        assert_eq!(
            compare::<StepCommand>("c", &enc("a", cmd(1.0)), &enc("a", cmd(off)), tol, |_| {}).unwrap(),
            None
        );
    }

    /// A top-level list of another length: one space, no "index" with nothing after it ("field corrections index
    /// (length)" with two spaces before, D25 of the 2026-12-06 sweep); a nested one keeps its index.
    #[test]
    fn a_length_is_named_without_an_empty_index() {
        let mut two = cmd(1.0);
        two.corrections.push(two.corrections[0]);
        let d = compare::<StepCommand>("c", &enc("a", cmd(1.0)), &enc("a", two), None, |_| {})
            .unwrap()
            .unwrap();
        assert_eq!(d.to_string(), "field corrections (length): recorded 1, replayed 2");
        let nested = Divergence {
            field: "x".into(),
            index: "[3] (length)".into(),
            recorded: "2".into(),
            replayed: "3".into(),
        };
        assert_eq!(nested.to_string(), "field x index [3] (length): recorded 2, replayed 3");
    }

    #[test]
    fn a_masked_field_is_not_compared() {
        let mask: fn(&mut StepCommand) = |c| c.dt = 0.0;
        let mut other = cmd(1.0);
        other.dt = 2e-4;
        let d = compare::<StepCommand>("c", &enc("a", cmd(1.0)), &enc("a", other), None, mask).unwrap();
        assert_eq!(d, None);
    }
}
