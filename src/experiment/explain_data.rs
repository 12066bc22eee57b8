//! `explain` on the data the options name, as the command line runs it: the candidates a run
//! without GNSS can test, explain's options from the data options (candidate priors, noise
//! levels), the data of its passes (the IMU read again from the file on every pass) and the
//! filter set-up of every model it tries.

use crate::data::{DataOptions, PassInputs};
use crate::estimate::filter::FilterConfig;
use crate::explain::restamp::{self, OnFixes};
use crate::explain::{ExplainData, ExplainOptions, Explanation, FileIdentity, ImuInput};
use crate::model::catalog::Sensor;
use crate::model::generated::common;
use crate::model::Model;
use anyhow::Result;

/// The names of the terms of `sensor` among `cands` (the GNSS terms enter the fixes of a GNSS
/// receiver, the reference terms a body-frame velocity reference).
pub fn terms_of(cands: &[usize], sensor: Sensor) -> Vec<&'static str> {
    cands
        .iter()
        .filter(|&&t| common::TERMS[t].sensor == sensor)
        .map(|&t| common::TERMS[t].name)
        .collect()
}

/// Drops the terms of `sensor` from `cands` (a static aid or ZUPTs have no antenna and no
/// receiver clock; without a velocity reference there is no mounting).
pub fn drop_sensor(cands: &mut Vec<usize>, sensor: Sensor) {
    cands.retain(|&t| common::TERMS[t].sensor != sensor);
}

/// `base` with the data options' candidate priors (`--prior`), testing noise levels only with
/// GNSS aiding (a static aid's or a ZUPT's σ is a tuning choice, not a receiver's).
pub fn options(data: &DataOptions, base: &ExplainOptions) -> Result<ExplainOptions> {
    let mut opts = base.clone();
    opts.candidate_sigma = data.term_priors()?;
    opts.noise_levels = data.has_gnss();
    Ok(opts)
}

/// The data of explain's passes over `inputs`: the IMU file read again on every pass (from just
/// after the start), checked to be the file it was when the run began.
pub fn explain_data(inputs: &PassInputs) -> Result<ExplainData<'_>> {
    Ok(ExplainData {
        imu: ImuInput::File {
            path: &inputs.imu,
            format: inputs.imu_format.as_deref(),
            clock_offset: inputs.clock_offset,
            skip_through: inputs.start.t + 1e-9,
            identity: Some(FileIdentity::of(&inputs.imu)?),
        },
        aid: &inputs.aid,
        truth: inputs.truth.as_deref(),
        start: inputs.start,
        tape: None,
    })
}

/// The filter set-up of a model explain tries: the data options' configuration (priors of other
/// models' terms passed over), with what opening the data found (`--init auto`'s σ, the step).
pub fn config_for<'a>(
    data: &'a DataOptions,
    inputs: &'a PassInputs,
) -> impl Fn(&Model) -> Result<FilterConfig> + 'a {
    move |m: &Model| {
        let mut c = data.config(m, true)?;
        crate::data::apply_opened(&mut c, m, inputs.init_sigma, inputs.step_s);
        Ok(c)
    }
}

/// explain on the data `data` names ((baseline, candidates, options)) with a time offset found
/// refitted on fixes re-stamped by it ([`restamp::explain_restamped`]), then tried against an
/// antenna lever arm on the fixes as given ([`restamp::offset_or_lever_arm`]); `note` takes the
/// first load's notes, `progress` (pass, fraction done) every pass's.
pub fn explain_restamped(
    data: &DataOptions,
    (baseline, cands, opts): (&Model, &[usize], &ExplainOptions),
    note: &mut dyn FnMut(&str),
    progress: &mut dyn FnMut(usize, f64),
) -> Result<Explanation> {
    let given = data.gnss_delay_s()?.unwrap_or(0.0);
    let restamped = |shift: f64| {
        let mut d = data.clone();
        // (below 1 ms a re-stamp changes nothing measurable: `--gnss-delay` refuses it)
        d.gnss_delay = (shift.abs() >= 1e-3).then(|| format!("{shift:.9} s"));
        d
    };
    let mut first = true;
    let mut e = restamp::explain_restamped(
        given,
        |shift| {
            let d = restamped(shift);
            let inputs = if std::mem::take(&mut first) {
                d.load_for_passes(note)?
            } else {
                note(&format!(
                    "explain: the GNSS fixes re-stamped by {:.1} ms (the time offset found so far), explain runs again",
                    shift * 1e3
                ));
                d.load_for_passes(&mut |_| {})?
            };
            let x = explain_data(&inputs)?;
            let cfg = config_for(&d, &inputs);
            crate::explain::explain(baseline, cands, &x, &cfg, opts, progress)
        },
        |shift| {
            let d = restamped(shift);
            let inputs = d.load_for_passes(&mut |_| {})?;
            let x = explain_data(&inputs)?;
            let cfg = config_for(&d, &inputs)(baseline)?;
            let dt = common::TERMS
                .iter()
                .position(|t| t.name == "dt_gnss")
                .expect("the spec declares dt_gnss");
            crate::explain::measurement_consistency(baseline, dt, &x, &cfg, opts)
        },
    )?;
    let Some(shift) = e.restamp.as_ref().and_then(|r| r.passes.last()) else {
        return Ok(e);
    };
    let shift = shift.shift_ms * 1e-3;
    let (dg, ds) = (restamped(given), restamped(shift));
    let (ig, is) = (
        dg.load_for_passes(&mut |_| {})?,
        ds.load_for_passes(&mut |_| {})?,
    );
    let (xg, xs) = (explain_data(&ig)?, explain_data(&is)?);
    let (cg, cs) = (config_for(&dg, &ig), config_for(&ds, &is));
    let on = |data, config_for, shift| OnFixes {
        data,
        config_for,
        shift,
    };
    restamp::offset_or_lever_arm(
        &mut e,
        baseline,
        opts,
        (
            &on(&xg, &cg, given),
            &on(&xs, &cs, shift),
            data.lever_arm.is_some(),
        ),
        progress,
    )?;
    Ok(e)
}
