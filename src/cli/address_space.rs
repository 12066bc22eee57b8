//! How many explain-eval jobs fit under an address-space limit (`ulimit -v`, RLIMIT_AS): under
//! one, glibc's per-thread malloc arenas (64 MB of address space reserved each) are turned off
//! and the jobs are counted against what the limit leaves, so that a run either fits or is
//! refused naming --jobs before any work, instead of aborting on a failed allocation.

use anyhow::{bail, Result};

/// Address space one job takes for cases of `seconds` simulated seconds [bytes]: measured
/// (2026-12-07, max RSS of `--jobs 2` less `--jobs 1`, one malloc arena) 40 MB at 300 s and 168
/// MB at 1200 s, and 60 MB and 203 MB for the whole `--jobs 1` process: the case's samples and
/// the navigation tape its passes share (about 0.115 and 0.044 MB per simulated second), taken
/// as 0.125 + 0.055 = 0.18 MB/s plus 4 MB for the thread's stack and buffers (a review's
/// 5000-s case reached 851 MB of the 0.175 MB/s estimate's 879 before it was stopped).
pub fn job_bytes(seconds: f64) -> f64 {
    4e6 + 0.18e6 * seconds
}

/// The address-space limit of this process [bytes], if there is one.
fn limit() -> Option<u64> {
    let mut r = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit writes the struct it is given.
    let ok = unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut r) } == 0;
    // (rlim_t is u64 here but not on every platform)
    #[allow(clippy::unnecessary_cast)]
    let cur = r.rlim_cur as u64;
    (ok && r.rlim_cur != libc::RLIM_INFINITY).then_some(cur)
}

/// Under an address-space limit, one malloc arena for all threads: glibc reserves 64 MB of
/// address space for each further arena, which made `--jobs 2` abort under 150 MB where one job
/// takes 36 MB. Call first in main, before any thread exists.
pub fn one_arena_under_a_limit() {
    if limit().is_some() {
        #[cfg(all(target_os = "linux", target_env = "gnu"))]
        // SAFETY: mallopt only sets an allocator parameter; no other thread exists yet.
        unsafe {
            libc::mallopt(libc::M_ARENA_MAX, 1);
        }
    }
}

/// Address space this process maps now [bytes] (Linux: VmSize), else a guess of 32 MB.
fn in_use() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            let l = s.lines().find(|l| l.starts_with("VmSize:"))?;
            l.split_whitespace().nth(1)?.parse::<u64>().ok()
        })
        .map_or(32 << 20, |kb| kb << 10)
}

/// The number of jobs to run: `asked` (`--jobs`, else `cores`), checked against an
/// address-space limit when there is one (refused naming --jobs when asked for more than fit;
/// fewer than all cores, said so, when not asked).
pub fn fit_jobs(asked: Option<u64>, cores: usize, seconds: f64) -> Result<usize> {
    let Some(limit) = limit() else {
        return Ok(asked.map_or(cores, |j| j as usize));
    };
    let per_job = job_bytes(seconds);
    let margin = 16e6; // the pool, the progress bar and the output's writing
    let free = limit as f64 - in_use() as f64 - margin;
    let fit = (free / per_job).floor().max(0.0) as usize;
    let mb = |b: f64| b / 1e6;
    let said = format!(
        "each job needs about {:.0} MB of address space for --seconds {seconds}, and the limit (ulimit -v) of {:.0} MB leaves {:.0} MB",
        mb(per_job),
        mb(limit as f64),
        mb(free.max(0.0))
    );
    match asked {
        _ if fit == 0 => bail!(
            "--jobs: not even one job fits: {said}; raise the limit or give a shorter --seconds"
        ),
        Some(j) if j as usize > fit => bail!(
            "--jobs {j}: {said}, room for {fit}; give --jobs {fit} (or fewer), or raise the limit"
        ),
        Some(j) => Ok(j as usize),
        None if cores > fit => {
            eprintln!("note: {fit} jobs instead of one per core ({cores}): {said}");
            Ok(fit)
        }
        None => Ok(cores),
    }
}
