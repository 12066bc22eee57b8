//! The paper's experiments (§3, Fig. 1) with the settings of DESIGN §6: each case simulated,
//! navigated and filtered with P28 and P31 (open loop), the model error e = φ̂ − φ reported as
//! RMS over the second hour (second half in quick mode), in arcsec.

use crate::filter::{self, AidingEpoch, FilterConfig, FilterRun, Mode};
use crate::model::Model;
use crate::rng::Rng;
use crate::scenario::Scenario;
use crate::simulator::{simulate, SimOutput};
use crate::units;
use nalgebra::Vector3;
use serde::Serialize;
use std::collections::BTreeMap;

/// The paper's sensor errors (DESIGN §6) as a scenario `[errors]` table.
pub const PAPER_ERRORS: &str = "[errors]\neps_x = \"0.01 deg/h\"\neps_y = \"0.01 deg/h\"\neps_z = \"0.01 deg/h\"\n\
nabla_x = \"50 ug\"\nnabla_y = \"50 ug\"\nnabla_z = \"50 ug\"\n\
kg_11 = \"10 ppm\"\nkg_21 = \"-10 ppm\"\nkg_31 = \"10 ppm\"\nkg_22 = \"10 ppm\"\nkg_32 = \"-10 ppm\"\nkg_33 = \"10 ppm\"\n\
ka_11 = \"50 ppm\"\nka_21 = \"-10 ppm\"\nka_31 = \"10 ppm\"\nka_12 = \"10 ppm\"\nka_22 = \"50 ppm\"\nka_32 = \"-10 ppm\"\n\
ka_13 = \"-10 ppm\"\nka_23 = \"10 ppm\"\nka_33 = \"50 ppm\"\n\
d_x = \"5e-5 s^2/m\"\nd_y = \"5e-5 s^2/m\"\nd_z = \"5e-5 s^2/m\"\n";

/// The paper's noise read as densities (DESIGN §6).
pub const PAPER_NOISE: &str = "[noise]\narw = \"0.01 deg/sqrt(h)\"\nvrw = \"10 ug/sqrt(Hz)\"\n";

/// Filter priors of a case (1-σ, with units), reported with every result.
#[derive(Debug, Clone, Serialize)]
pub struct Priors {
    /// Initial attitude σ (north/east).
    pub phi0: String,
    /// Accelerometer bias σ.
    pub nabla: String,
    /// Quadratic coefficient σ.
    pub d: String,
    /// Velocity measurement σ (0 = no velocity updates).
    pub sigma_v: String,
    /// Position measurement σ.
    pub sigma_p: String,
}

impl Default for Priors {
    fn default() -> Priors {
        Priors {
            phi0: "60 arcsec".into(),
            nabla: "100 ug".into(),
            d: "1000 ug/g^2".into(),
            sigma_v: "0.01 m/s".into(),
            sigma_p: "0.5 m".into(),
        }
    }
}

/// One case of the reproduction.
#[derive(Debug, Clone)]
pub struct Case {
    /// `static`, `sine`, `sine_random`, `onoff`, `fig1`.
    pub name: &'static str,
    /// Scenario text.
    pub scenario: String,
    /// Velocity updates as well as position.
    pub velocity_updates: bool,
    /// Window of the model-error RMS [s].
    pub window: (f64, f64),
}

fn rest_scenario(
    name: &str,
    rate: f64,
    seconds: f64,
    seed: u64,
    vib: &str,
    errors: &str,
) -> String {
    format!(
        "name = \"{name}\"\nimu_rate_hz = {rate}\ntruth_rate_hz = 1.0\nseed = {seed}\n[start]\nlat_deg = 28.22\nlon_deg = 112.99\n\
         euler_deg = [0.0, 0.0, 0.0]\n[[segment]]\nkind = \"rest\"\nduration_s = {seconds}\n{vib}{errors}{PAPER_NOISE}"
    )
}

fn sine3(amp_g: f64, schedule: &str) -> String {
    ["n", "e", "d"]
        .iter()
        .map(|a| {
            format!("[[vibration]]\nkind = \"sine\"\naxis = \"{a}\"\namplitude = \"{amp_g} g\"\nfreq_hz = 90.0\n{schedule}")
        })
        .collect()
}

/// The cases, full length (2 h; 4 h for fig1) or shortened for CI (`quick`).
pub fn cases(quick: bool, seed: u64) -> Vec<Case> {
    let (t2h, t4h) = if quick {
        (600.0, 600.0)
    } else {
        (7200.0, 14_400.0)
    };
    let second_half = |t: f64| {
        if quick {
            (t / 2.0, t)
        } else {
            (3600.0, 7200.0)
        }
    };
    let random = "[[vibration]]\nkind = \"random\"\naxis = \"x\"\npsd = \"0.01 g^2/Hz\"\nband_hz = [20.0, 500.0]\ncomponents = 100\n\
                  [[vibration]]\nkind = \"random\"\naxis = \"y\"\npsd = \"0.01 g^2/Hz\"\nband_hz = [20.0, 500.0]\ncomponents = 100\n\
                  [[vibration]]\nkind = \"random\"\naxis = \"z\"\npsd = \"0.01 g^2/Hz\"\nband_hz = [20.0, 500.0]\ncomponents = 100\n";
    // on/off: vibration in whole-second windows (90 Hz: whole cycles), 6 g then 3 g
    let period = t2h / 6.0;
    let onoff = format!(
        "schedule = [[{:.1}, {:.1}, 1.0], [{:.1}, {:.1}, 0.5], [{:.1}, {:.1}, 1.0]]\n",
        period,
        2.0 * period,
        3.0 * period,
        4.0 * period,
        5.0 * period,
        6.0 * period
    );
    vec![
        Case {
            name: "static",
            scenario: rest_scenario("static", 100.0, t2h, seed, "", PAPER_ERRORS),
            velocity_updates: true,
            window: second_half(t2h),
        },
        Case {
            name: "sine",
            scenario: rest_scenario("sine", 2000.0, t2h, seed, &sine3(6.0, ""), PAPER_ERRORS),
            velocity_updates: true,
            window: second_half(t2h),
        },
        Case {
            name: "sine_random",
            scenario: rest_scenario(
                "sine_random",
                2000.0,
                t2h,
                seed,
                &(sine3(6.0, "") + random),
                PAPER_ERRORS,
            ),
            velocity_updates: false,
            window: second_half(t2h),
        },
        Case {
            name: "onoff",
            scenario: rest_scenario(
                "onoff",
                2000.0,
                t2h,
                seed,
                &sine3(6.0, &onoff),
                PAPER_ERRORS,
            ),
            velocity_updates: true,
            window: second_half(t2h),
        },
        Case {
            name: "fig1",
            scenario: rest_scenario(
                "fig1",
                2000.0,
                t4h,
                seed,
                &sine3(8.0, ""),
                "[errors]\nd_x = \"5e-5 s^2/m\"\nd_y = \"5e-5 s^2/m\"\nd_z = \"5e-5 s^2/m\"\n",
            ),
            velocity_updates: true,
            window: if quick {
                (t4h / 2.0, t4h)
            } else {
                (3600.0, t4h)
            },
        },
    ]
}

/// Aiding epochs from the truth (1 Hz), with Gaussian noise of the priors' σ.
pub fn aiding_from_truth(
    sim: &SimOutput,
    priors: &Priors,
    velocity: bool,
    seed: u64,
) -> anyhow::Result<Vec<AidingEpoch>> {
    let sv = units::parse_quantity_as(&priors.sigma_v, "m/s")?;
    let sp = units::parse_quantity_as(&priors.sigma_p, "m")?;
    let mut rng = Rng::new(seed ^ 0xa1d);
    let mut out = Vec::new();
    for row in sim.truth.iter().skip(1) {
        let rm = crate::earth::radius_meridian(row.lat) + row.h;
        let rn = crate::earth::radius_transverse(row.lat) + row.h;
        let vel = velocity.then(|| {
            (
                row.v + Vector3::new(rng.normal(), rng.normal(), rng.normal()) * sv,
                sv,
            )
        });
        let pos = Some((
            row.lat + sp * rng.normal() / rm,
            row.lon + sp * rng.normal() / (rn * row.lat.cos()),
            row.h,
            [sp, sp, sp],
        ));
        out.push(AidingEpoch { t: row.t, vel, pos });
    }
    Ok(out)
}

/// Filter configuration for a case: the model's defaults with the case priors and the paper's noise.
pub fn config(model: &Model, priors: &Priors) -> anyhow::Result<FilterConfig> {
    let arw = units::parse_quantity_as("0.01 deg/sqrt(h)", "rad/sqrt(s)")?;
    let vrw = units::parse_quantity_as("10 ug/sqrt(Hz)", "m/s/sqrt(s)")?;
    let mut cfg = FilterConfig::new(model).with_sensor_noise(model, arw, vrw);
    cfg.mode = Mode::OpenLoop;
    let phi0 = units::parse_quantity_as(&priors.phi0, "rad")?;
    let nabla = units::parse_quantity_as(&priors.nabla, "m/s^2")?;
    let d = units::parse_quantity_as(&priors.d, "s^2/m")?;
    for s in ["phi_n", "phi_e"] {
        cfg.set_prior(model, s, phi0);
    }
    for s in ["nabla_x", "nabla_y", "nabla_z"] {
        cfg.set_prior(model, s, nabla);
    }
    for s in ["d_x", "d_y", "d_z"] {
        cfg.set_prior(model, s, d);
    }
    Ok(cfg)
}

/// Result of one case.
#[derive(Debug, Clone, Serialize)]
pub struct CaseResult {
    /// Case name.
    pub name: String,
    /// Model error RMS [arcsec], north and east, per model.
    pub model_error_rms_arcsec: BTreeMap<String, [f64; 2]>,
    /// RMS of (north, east) of P28 over that of P31.
    pub ratio: f64,
    /// Priors used.
    pub priors: Priors,
    /// Window of the RMS [s].
    pub window_s: [f64; 2],
}

/// Runs one case with both models on one simulation; returns the result and the two runs.
pub fn run_case(
    case: &Case,
    priors: &Priors,
    seed: u64,
    mut progress: impl FnMut(&str, f64),
) -> anyhow::Result<(CaseResult, SimOutput, Vec<FilterRun>)> {
    let sc = Scenario::parse(&case.scenario, case.name)?;
    let sim = simulate(&sc, |f| progress("simulate", f));
    let aid = aiding_from_truth(&sim, priors, case.velocity_updates, seed)?;
    let mut rms = BTreeMap::new();
    let mut runs = Vec::new();
    for m in ["P28", "P31"] {
        let model = Model::parse(m)?;
        let cfg = config(&model, priors)?;
        let run = filter::run(
            &model,
            &cfg,
            &sim.imu,
            sim.start,
            &aid,
            Some(&sim.truth),
            |f| progress(m, f),
        );
        let e = filter::model_error_rms_arcsec(&run, case.window.0, case.window.1)
            .ok_or_else(|| anyhow::anyhow!("case {}: no truth in the RMS window", case.name))?;
        rms.insert(m.to_string(), e);
        runs.push(run);
    }
    let norm = |v: &[f64; 2]| v[0].hypot(v[1]);
    let ratio = norm(&rms["P28"]) / norm(&rms["P31"]);
    Ok((
        CaseResult {
            name: case.name.to_string(),
            model_error_rms_arcsec: rms,
            ratio,
            priors: priors.clone(),
            window_s: [case.window.0, case.window.1],
        },
        sim,
        runs,
    ))
}
