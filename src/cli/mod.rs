//! Subcommands of the `sinsmodel` binary, one module each.

pub mod address_space;
pub mod align;
pub mod allan;
pub mod bench;
pub mod data;
pub mod explain;
pub mod explain_eval;
pub mod filter;
pub mod imu_check;
pub mod jacobian;
pub mod model;
pub mod nav_out;
pub mod navigate;
pub mod reproduce;
pub mod simulate;

/// The command line that started this run, for the provenance header of output files: the
/// arguments joined by spaces, quoted where they hold spaces, control characters shown as `?`.
pub fn command_line() -> String {
    let args: Vec<String> = std::env::args()
        .enumerate()
        .map(|(k, a)| {
            let a: String = if k == 0 {
                "sinsmodel".into()
            } else {
                let a: String = a
                    .chars()
                    .map(|c| if c.is_control() { '?' } else { c })
                    .collect();
                // a header line, not an echo of a 100 kB argument
                if a.chars().count() > 200 {
                    format!("{}…", a.chars().take(200).collect::<String>())
                } else {
                    a
                }
            };
            if a.contains(' ') || a.is_empty() {
                format!("'{a}'")
            } else {
                a
            }
        })
        .collect();
    format!(
        "{} (sinsmodel {})",
        args.join(" "),
        env!("CARGO_PKG_VERSION")
    )
}
