//! The edits of a saved file's every field, for the tests that a plant refuses an edited state
//! or writes what the untouched one gives (issue 40 item 4): each number set to a few hostile
//! values, each string and boolean changed, a long array's entries sampled deterministically.

use serde_json::Value;

/// One edit: where (a dotted path with `[i]` indices), what it was set to, and the document.
pub struct Edit {
    /// The field, e.g. `adaptive.h` or `state[3]`.
    pub path: String,
    /// The value written there.
    pub value: Value,
    /// The whole document with the edit.
    pub doc: Value,
}

/// The hostile values for a number `v`: zero, −1, huge of both signs, `u64::MAX`, and a small
/// change (the next integer, or a relative 1e-6).
pub fn hostile(v: &serde_json::Number) -> Vec<Value> {
    let mut out = vec![Value::from(0), Value::from(-1), Value::from(1e300), Value::from(-1e300), Value::from(u64::MAX)];
    if let Some(u) = v.as_u64() {
        out.push(Value::from(u.saturating_add(1)));
    } else if let Some(f) = v.as_f64() {
        out.push(Value::from(if f == 0.0 { 1e-9 } else { f * (1.0 + 1e-6) }));
    }
    out
}

/// Every edit of `doc`: each number (in arrays longer than `keep_whole` entries, those at the
/// first, middle and last index, unless the array's path is in `whole`) set to each [`hostile`]
/// value, each string set to `"0"` and suffixed with `x`, each boolean flipped.
pub fn edits(doc: &Value, whole: &[&str]) -> Vec<Edit> {
    let mut leaves = Vec::new();
    walk(doc, "", whole, &mut leaves);
    let mut out = Vec::new();
    for (path, pointer, leaf) in leaves {
        let values: Vec<Value> = match &leaf {
            Value::Number(n) => hostile(n),
            Value::String(s) => vec![Value::from("0"), Value::from(format!("{s}x"))],
            Value::Bool(b) => vec![Value::from(!b)],
            _ => vec![],
        };
        for value in values {
            let mut edited = doc.clone();
            if let Some(slot) = edited.pointer_mut(&pointer) {
                *slot = value.clone();
            }
            out.push(Edit { path: path.clone(), value, doc: edited });
        }
    }
    out
}

/// Collects `(path, JSON pointer, value)` of the leaves under `v`.
fn walk(v: &Value, at: &str, whole: &[&str], out: &mut Vec<(String, String, Value)>) {
    walk_at(v, at, "", whole, out)
}

fn walk_at(v: &Value, at: &str, pointer: &str, whole: &[&str], out: &mut Vec<(String, String, Value)>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                let path = if at.is_empty() { k.clone() } else { format!("{at}.{k}") };
                walk_at(x, &path, &format!("{pointer}/{k}"), whole, out);
            }
        }
        Value::Array(a) => {
            let n = a.len();
            let picked: Vec<usize> =
                if n <= 3 || whole.contains(&at) { (0..n).collect() } else { vec![0, n / 2, n - 1] };
            for i in picked {
                walk_at(&a[i], &format!("{at}[{i}]"), &format!("{pointer}/{i}"), whole, out);
            }
        }
        leaf => out.push((at.to_owned(), pointer.to_owned(), leaf.clone())),
    }
}

/// Runs `job` over `items` on two threads (the machine's cores are shared), the results in
/// the items' order.
pub fn on_two_threads<T: Sync, R: Send>(items: &[T], job: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results: std::sync::Mutex<Vec<Option<R>>> = std::sync::Mutex::new((0..items.len()).map(|_| None).collect());
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some(item) = items.get(i) else { break };
                let r = job(item);
                results.lock().unwrap()[i] = Some(r);
            });
        }
    });
    results.into_inner().unwrap().into_iter().map(|r| r.expect("every item ran")).collect()
}

/// One edit's verdict: `Ok(Some(message))` refused with that message, `Ok(None)` harmless (the
/// untouched file's outputs), `Err(why)` neither.
pub type Verdict = Result<Option<String>, String>;

/// Fails naming every edit (`(what, verdict)`) that was neither refused nor harmless.
pub fn assert_refused_or_harmless(results: &[(String, Verdict)]) {
    let failures: Vec<String> =
        results.iter().filter_map(|(what, v)| v.as_ref().err().map(|e| format!("{what}: {e}"))).collect();
    assert!(
        failures.is_empty(),
        "{} of {} edits neither refused nor harmless:\n{}",
        failures.len(),
        results.len(),
        failures.join("\n")
    );
}

/// What the edit `what` was refused with (empty: it was harmless, or not made).
pub fn refusal(results: &[(String, Verdict)], what: &str) -> String {
    results.iter().find(|(w, _)| w == what).and_then(|(_, v)| v.as_ref().ok().cloned().flatten()).unwrap_or_default()
}
