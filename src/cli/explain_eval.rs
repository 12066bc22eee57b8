//! `sinsmodel explain-eval --cases N [--seed S] [--first I] [--groups d,kaq,…] [--jobs J]
//! [--seconds T] --out DIR` and `sinsmodel explain-eval --merge DIR… --out DIR`: how well explain
//! finds hidden effects, over seeded cases in parallel (rayon), deterministic for a seed whatever
//! the number of jobs; shards of one campaign (`--first`) merge into the same numbers.

use anyhow::{bail, Context, Result};
use clap::Args;
use rayon::prelude::*;
use sinsmodel::experiment::eval_check::{
    check_case, check_spec, missing_ranges, parse_groups, spec_differs,
};
use sinsmodel::experiment::eval_report::{headline, markdown};
use sinsmodel::experiment::explain_eval::{self, CaseResult, EvalSpec};
use sinsmodel::io::atomic_file::{self, OutputDir};
use sinsmodel::report::plot::{self, Scale, Series};
use sinsmodel::report::progress;
use sinsmodel::sim::hidden::GROUPS;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Arguments of `explain-eval`.
#[derive(Args)]
pub struct EvalArgs {
    /// Number of cases (1 to 100000).
    #[arg(long)]
    cases: Option<usize>,
    /// Campaign seed (0 to 1000000000000; default 1).
    #[arg(long, value_parser = clap::value_parser!(u64).range(0..=1_000_000_000_000))]
    seed: Option<u64>,
    /// Index of the first case (shards of one campaign: `--first 0 --cases 100`, `--first 100 …`).
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u64).range(0..=1_000_000_000))]
    first: u64,
    /// Groups to draw from (default the sensor groups d,kaq,kas,kao,kgf,kgq,size; `all` for
    /// every group: also GNSS, reference, turntable, two-term and misstated-noise groups).
    #[arg(long, value_delimiter = ',')]
    groups: Option<Vec<String>>,
    /// Threads (default: all cores, or as many as an address-space limit `ulimit -v` leaves room
    /// for: about 4 MB + 0.18 MB per simulated second each).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=256))]
    jobs: Option<u64>,
    /// Simulated seconds per case (300 to 7200; default 600).
    #[arg(long, allow_negative_numbers = true)]
    seconds: Option<f64>,
    /// Family-wise α of explain, in [1e-12, 0.5] (default 0.01).
    #[arg(long, allow_negative_numbers = true)]
    alpha: Option<f64>,
    /// Merge the `cases.json` of these evaluation directories instead of running cases.
    #[arg(long, num_args = 1..)]
    merge: Vec<PathBuf>,
    /// Output DIRECTORY (not a file; navigate's --out is a file): eval.json, eval.md,
    /// cases.json, power_curve.png, power_by_group.png.
    #[arg(long)]
    out: PathBuf,
    /// Test only: a deliberately broken selector (names a pseudo-random candidate).
    #[arg(long, hide = true)]
    broken_selector: bool,
}

/// The stored run: its spec and its cases.
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Stored {
    spec: EvalSpec,
    cases: Vec<CaseResult>,
}

/// Runs the command.
pub fn run(args: &EvalArgs) -> Result<()> {
    if !args.merge.is_empty() {
        let given = [
            ("--cases", args.cases.is_some()),
            ("--first", args.first != 0),
            ("--groups", args.groups.is_some()),
            ("--seed", args.seed.is_some()),
            ("--seconds", args.seconds.is_some()),
            ("--alpha", args.alpha.is_some()),
            ("--jobs", args.jobs.is_some()),
            ("--broken-selector", args.broken_selector),
        ];
        if let Some((opt, _)) = given.iter().find(|g| g.1) {
            bail!("--merge combines finished runs, whose settings are in their cases.json: give only the directories and --out, not {opt}");
        }
        return merge(args);
    }
    let n = args
        .cases
        .context("--cases N is required (or --merge DIR…)")?;
    if !(1..=100_000).contains(&n) {
        bail!("--cases {n}: expected 1 to 100000");
    }
    let seconds = args.seconds.unwrap_or(600.0);
    if !(seconds.is_finite() && (300.0..=7200.0).contains(&seconds)) {
        bail!("--seconds {seconds}: expected 300 to 7200 s");
    }
    let alpha = args.alpha.unwrap_or(0.01);
    if !(alpha.is_finite() && (1e-12..=0.5).contains(&alpha)) {
        bail!("--alpha {alpha}: expected a level in [1e-12, 0.5]");
    }
    let groups: Vec<String> = match &args.groups {
        Some(g) => parse_groups(g).map_err(|e| anyhow::anyhow!("--groups: {e}"))?,
        None => GROUPS.iter().map(|s| s.to_string()).collect(),
    };
    if args.jobs == Some(0) {
        bail!("--jobs 0: at least one thread");
    }
    let spec = EvalSpec {
        seed: args.seed.unwrap_or(1),
        groups,
        seconds,
        alpha,
        ..EvalSpec::default()
    };
    // --out checked now (its staging made and removed); the staging that holds the result is
    // made only once the cases are computed, so a run that dies computing leaves none behind
    drop(OutputDir::create(&args.out, &[], "explain-eval")?);
    let mut opts = explain_eval::default_options();
    opts.broken_selector = args.broken_selector;
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let jobs = super::address_space::fit_jobs(args.jobs, cores, seconds)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .with_context(|| format!("--jobs {jobs}: cannot start {jobs} threads"))?;
    let pb = progress::bar(n as u64, "cases");
    let done = AtomicUsize::new(0);
    let t0 = std::time::Instant::now();
    let results: Vec<Result<CaseResult>> = pool.install(|| {
        (args.first as usize..args.first as usize + n)
            .into_par_iter()
            .map(|i| {
                // (what --merge would refuse is not written: a bug, said as such)
                let r = explain_eval::run_case(&spec, i, &opts)
                    .and_then(|c| match check_case(&spec, &c) {
                        Ok(()) => Ok(c),
                        Err(e) => bail!("its result fails the check --merge makes: {e} (a bug)"),
                    })
                    .with_context(|| format!("case {i} (seed {})", spec.seed));
                pb.set_position(done.fetch_add(1, Ordering::Relaxed) as u64 + 1);
                r
            })
            .collect()
    });
    pb.finish_and_clear();
    let cases: Vec<CaseResult> = results.into_iter().collect::<Result<_>>()?;
    let wall = t0.elapsed().as_secs_f64();
    let out = OutputDir::create(&args.out, &[], "explain-eval")?;
    write(&out, &spec, &cases, Some(wall))?;
    out.commit()?;
    let s = explain_eval::summarize(&spec, &cases);
    for line in headline(&s) {
        eprintln!("{line}");
    }
    eprintln!(
        "{n} case(s) in {wall:.1} s ({:.2} s per case on one thread); wrote {}",
        cases.iter().map(|c| c.seconds_taken).sum::<f64>() / n as f64,
        args.out.display()
    );
    Ok(())
}

fn merge(args: &EvalArgs) -> Result<()> {
    let mut spec: Option<(EvalSpec, &Path)> = None;
    let mut cases: Vec<(CaseResult, &Path)> = Vec::new();
    for d in &args.merge {
        if d.is_file() {
            bail!(
                "--merge {}: a file; give the directory an explain-eval run wrote (it holds cases.json)",
                d.display()
            );
        }
        let path = d.join("cases.json");
        let text = sinsmodel::io::lines::read_small_text(&path, "explain-eval result")
            .with_context(|| format!("--merge: cannot read {}", path.display()))?;
        let stored: Stored = serde_json::from_str(&text).map_err(|e| {
            let hint = if ["NaN", "Infinity"].iter().any(|w| text.contains(w)) {
                " (it holds NaN or Infinity, which JSON has no words for: edited by hand?)"
            } else {
                ""
            };
            anyhow::anyhow!(
                "--merge: {} is not an explain-eval cases file of this version: {e}{hint}",
                path.display()
            )
        })?;
        // a stored campaign is input like any other: its settings checked before they are used
        check_spec(&stored.spec).map_err(|e| {
            anyhow::anyhow!(
                "--merge: {}: its campaign settings are not ones explain-eval writes: {e}",
                path.display()
            )
        })?;
        match &spec {
            None => spec = Some((stored.spec, d.as_path())),
            Some((s, first)) => {
                if let Some(why) = spec_differs(s, &stored.spec) {
                    bail!(
                        "--merge: {} belongs to another campaign than {}: {why}",
                        d.display(),
                        first.display()
                    );
                }
            }
        }
        let n = stored.cases.len();
        let sp = &spec
            .as_ref()
            .context("--merge: no campaign settings read")?
            .0;
        for (k, c) in stored.cases.into_iter().enumerate() {
            if let Some((_, other)) = cases.iter().find(|x| x.0.index == c.index) {
                bail!(
                    "--merge: case {} is in {} and in {}: merge each shard once",
                    c.index,
                    other.display(),
                    d.display()
                );
            }
            // a stored case is input like any other: checked against what its index draws
            check_case(sp, &c).map_err(|e| {
                anyhow::anyhow!(
                    "--merge: {}: case {} (entry {} of {n}): {e}; not merged (edited by hand, damaged, or from another version of sinsmodel?)",
                    path.display(),
                    c.index,
                    k + 1
                )
            })?;
            cases.push((c, d.as_path()));
        }
    }
    let spec = spec.context("--merge needs at least one directory")?.0;
    if cases.is_empty() {
        bail!("--merge: the given runs hold no case (a run holds at least one)");
    }
    let mut cases: Vec<CaseResult> = cases.into_iter().map(|x| x.0).collect();
    cases.sort_by_key(|c| c.index);
    let indices: Vec<usize> = cases.iter().map(|c| c.index).collect();
    if let Some(&(a, b)) = missing_ranges(&indices).first() {
        let d = EvalSpec::default();
        let mut opts = String::new();
        if spec.groups != d.groups {
            opts.push_str(&format!(" --groups {}", spec.groups.join(",")));
        }
        if spec.alpha != d.alpha {
            opts.push_str(&format!(" --alpha {}", spec.alpha));
        }
        bail!(
            "--merge: {} missing between the shards (the given ones hold {} to {}, each run a contiguous range): merge the shards that hold them too, or run them (at most 100000 cases per run), the first: explain-eval --seed {} --first {a} --cases {} --seconds {}{opts} --out DIR",
            if a == b {
                format!("case {a} is")
            } else {
                format!("cases {a}–{b} are")
            },
            indices[0],
            indices[indices.len() - 1],
            spec.seed,
            (b - a + 1).min(100_000),
            spec.seconds
        );
    }
    let inputs: Vec<&Path> = args.merge.iter().map(|p| p.as_path()).collect();
    let out = OutputDir::create(&args.out, &inputs, "explain-eval")?;
    write(&out, &spec, &cases, None)?;
    out.commit()?;
    for line in headline(&explain_eval::summarize(&spec, &cases)) {
        eprintln!("{line}");
    }
    eprintln!(
        "merged {} case(s) of {} run(s); wrote {}",
        cases.len(),
        args.merge.len(),
        args.out.display()
    );
    Ok(())
}

fn write(out: &OutputDir, spec: &EvalSpec, cases: &[CaseResult], wall: Option<f64>) -> Result<()> {
    let s = explain_eval::summarize(spec, cases);
    let mut v = serde_json::to_value(&s)?;
    if let Some(w) = wall {
        v["seconds_wall"] = serde_json::json!(w);
    }
    v["seconds_per_case"] = serde_json::json!(
        cases.iter().map(|c| c.seconds_taken).sum::<f64>() / cases.len().max(1) as f64
    );
    v["case_seconds"] = serde_json::json!(spec.seconds);
    // where a case's time goes: simulation and sizing, explain, the rest (oracle, scoring)
    let mean =
        |f: fn(&CaseResult) -> f64| cases.iter().map(f).sum::<f64>() / cases.len().max(1) as f64;
    v["seconds_per_case_setup"] = serde_json::json!(mean(|c| c.seconds_taken_setup));
    v["seconds_per_case_explain"] = serde_json::json!(mean(|c| c.seconds_taken_explain));
    atomic_file::write_text(&out.file("eval.json"), &serde_json::to_string_pretty(&v)?)?;
    let stored = Stored {
        spec: spec.clone(),
        cases: cases.to_vec(),
    };
    atomic_file::write_text(
        &out.file("cases.json"),
        &serde_json::to_string_pretty(&stored)?,
    )?;
    // power curve: measured per bin against theory
    let measured: Vec<(f64, f64)> = s
        .power_curve
        .iter()
        .filter_map(|b| Some(((b.lambda_lo * b.lambda_hi).sqrt(), b.detection_rate?)))
        .collect();
    let c_thr = explain_eval::first_threshold(s.alpha, s.candidates_tested_median as usize);
    let theory: Vec<(f64, f64)> = (0..=60)
        .map(|k| {
            let l = 10f64.powf(1.0 + 2.0 * k as f64 / 60.0);
            (l, explain_eval::power(l, c_thr))
        })
        .collect();
    plot::line_plot(
        &out.file("power_curve.png"),
        "explain: detection against noncentrality λ = θ² I",
        "λ",
        "detection rate",
        &[
            Series {
                label: "measured (per λ bin)".into(),
                points: measured,
            },
            Series {
                label: format!(
                    "theory: the first test, χ²₁(λ) at Holm's first threshold (α {}, {} candidates)",
                    s.alpha, s.candidates_tested_median
                ),
                points: theory.clone(),
            },
        ],
        Scale::LogX,
    )?;
    // per group: measured detection per λ bin, one line each, beside the stated test's curve
    let mut groups: Vec<Series> = s
        .by_group
        .iter()
        .filter(|(_, g)| g.cases > 0)
        .map(|(name, g)| Series {
            label: name.clone(),
            points: g
                .power_curve
                .iter()
                .filter_map(|b| Some(((b.lambda_lo * b.lambda_hi).sqrt(), b.detection_rate?)))
                .collect(),
        })
        .collect();
    groups.push(Series {
        label: "theory (the first test)".into(),
        points: theory,
    });
    plot::line_plot(
        &out.file("power_by_group.png"),
        "explain: detection against λ, per group",
        "λ",
        "detection rate",
        &groups,
        Scale::LogX,
    )?;
    atomic_file::write_text(
        &out.file("eval.md"),
        &markdown(&s, cases.len(), spec.seconds),
    )?;
    Ok(())
}
