//! Experiments built on the library: the paper's reproduction (`reproduce`), hidden-effect cases
//! end to end (`hidden`) and explain's evaluation campaign (`explain_eval`, its stored cases
//! checked by `eval_check`, its report written by `eval_report`). They use the
//! estimators; the estimators never use them.

pub mod bench;
pub mod bench_stages;
pub mod eval_check;
pub mod eval_report;
pub mod explain_data;
pub mod explain_eval;
pub mod hidden;
pub mod reproduce;
