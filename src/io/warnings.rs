//! The warnings a run says about its data, kept for its report: a warning on stderr scrolls away,
//! while `explain`'s report is what people read (an aiding clock found off, a unit slip let
//! through with --force). Process-wide; the command that reports takes them.

use std::sync::Mutex;

/// Most warnings kept (a run that repeats one does not grow memory).
const KEPT_MAX: usize = 50;

static KEPT: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// Keeps `text` (a warning without its "warning: ") for the run's report, once.
pub fn keep(text: &str) {
    keep_new(text);
}

/// Keeps `text` as [`keep`] does; returns whether it was not kept before.
fn keep_new(text: &str) -> bool {
    let Ok(mut v) = KEPT.lock() else {
        return false;
    };
    let new = v.len() < KEPT_MAX && !v.iter().any(|x| x == text);
    if new {
        v.push(text.to_string());
    }
    new
}

/// Says `text` as a warning on stderr and keeps it for the run's report.
pub fn warn(text: &str) {
    eprintln!("warning: {text}");
    keep(text);
}

/// Says `text` as a warning on stderr and keeps it, unless it is kept already (a run that reads
/// the same file many times says it once).
pub fn warn_once(text: &str) {
    if keep_new(text) {
        eprintln!("warning: {text}");
    }
}

/// The warnings kept so far, in the order said; forgets them.
pub fn take() -> Vec<String> {
    KEPT.lock()
        .map(|mut v| std::mem::take(&mut *v))
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    #[test]
    fn kept_once_in_order_and_taken() {
        super::take();
        super::keep("a");
        super::keep("b");
        super::keep("a");
        assert_eq!(super::take(), ["a", "b"]);
        assert!(super::take().is_empty());
    }
}
