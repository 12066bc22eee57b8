//! Subcommands of the `sinsmodel` binary, one module each.

pub mod align;
pub mod allan;
pub mod bench;
pub mod data;
pub mod explain;
pub mod explain_eval;
pub mod filter;
pub mod jacobian;
pub mod model;
pub mod navigate;
pub mod reproduce;
pub mod simulate;
