//! `sinsmodel jacobian --model MODEL --at POINT.json`.

use anyhow::{Context, Result};
use clap::Args;
use sinsmodel::model::jacobian::{jacobian, parse_points, Points};
use sinsmodel::model::Model;
use std::path::PathBuf;

/// Arguments of `jacobian`.
#[derive(Args)]
pub struct JacobianArgs {
    /// Model, e.g. P31, P28+kaq_x_xy, P31+vertical.
    #[arg(long)]
    model: String,
    /// Point: JSON object {lat_deg, h_m, v_ned, euler_deg, f_b, w_b}, or an array of them
    /// (then the output is an array).
    #[arg(long)]
    at: PathBuf,
    /// Compose A and H at run time even when the model is a preset.
    #[arg(long)]
    runtime: bool,
}

/// Runs the command.
pub fn run(args: &JacobianArgs) -> Result<()> {
    let model = Model::parse(&args.model)?;
    let text = sinsmodel::io::lines::read_small_text(&args.at, "--at")
        .with_context(|| format!("cannot read {}", args.at.display()))?;
    let at = args.at.display();
    let out = match parse_points(&text).with_context(|| format!("{at}"))? {
        Points::Many(points) => {
            let mut outs = Vec::with_capacity(points.len());
            for (k, p) in points.iter().enumerate() {
                outs.push(
                    jacobian(&model, p, args.runtime)
                        .with_context(|| format!("{at}: point {k}"))?,
                );
            }
            serde_json::to_string(&outs)?
        }
        Points::One(p) => serde_json::to_string(
            &jacobian(&model, &p, args.runtime).with_context(|| format!("{at}"))?,
        )?,
    };
    println!("{out}");
    Ok(())
}
