//! Reports: explain's words and Markdown, its HTML page, PNG plots and progress bars (the last
//! three with the `cli` feature). Rendering only; the experiments are in `experiment`.

pub mod align;
pub mod allan;
pub mod explain;
#[cfg(feature = "cli")]
pub mod explain_files;
pub mod explain_notes;
pub mod filter;
#[cfg(feature = "cli")]
pub mod html;
pub mod imu_check;
#[cfg(feature = "cli")]
pub mod plot;
#[cfg(feature = "cli")]
pub mod progress;
pub mod reproduce;

/// Text escaped for HTML (element content and attribute values): `&`, `<`, `>`, `"`.
pub fn html_text(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
