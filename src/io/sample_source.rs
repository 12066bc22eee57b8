//! The leaf every IMU reader stands on: the [`SampleSource`] trait (samples in file order) and
//! the limits of what any IMU measures. Readers build sources; [`crate::io::imu_stream`] wraps
//! a source into a validated stream and dispatches a file to its reader, never the other way.

use crate::io::imu::ImuSample;
use crate::io::units::STANDARD_GRAVITY;
use anyhow::Result;

/// Largest angular rate any IMU measures [rad/s].
pub const MAX_RATE: f64 = 100.0;
/// Largest specific force any IMU measures [m/s²] (2000 g).
pub const MAX_FORCE: f64 = 2000.0 * STANDARD_GRAVITY;
/// A reader of one IMU format that hands out samples in file order.
pub trait SampleSource {
    /// The next sample and the file line it came from (0 when it has no line of its own), or
    /// None at the end.
    fn next_sample(&mut self) -> Result<Option<(ImuSample, usize)>>;
    /// Fraction of the input read so far (for progress; 0 when unknown).
    fn fraction(&self) -> f64;
}

/// Samples per batch handed over by [`ReadAhead`]'s reading thread.
const READ_BATCH: usize = 1024;
/// Batches [`ReadAhead`] reads ahead (memory stays bounded: 4 × 1024 samples).
const READ_AHEAD: usize = 4;

/// What the reading thread hands over.
enum Batch {
    /// Samples in file order, and the fraction of the input read after them.
    Samples(Vec<(ImuSample, usize)>, f64),
    /// The source's error, after the samples before it.
    Failed(anyhow::Error),
    /// The end of the input.
    End,
}

/// A source read on its own thread, a few batches ahead of its consumer: reading and parsing a
/// text file overlap the navigation and the filter (the same samples, errors and lines, in the
/// same order).
pub struct ReadAhead {
    rx: std::sync::mpsc::Receiver<Batch>,
    current: std::vec::IntoIter<(ImuSample, usize)>,
    fraction: f64,
    done: bool,
}

impl ReadAhead {
    /// Starts reading `src` on a thread.
    pub fn spawn(mut src: Box<dyn SampleSource + Send>) -> Result<ReadAhead> {
        let (tx, rx) = std::sync::mpsc::sync_channel(READ_AHEAD);
        std::thread::Builder::new()
            .name("imu reader".into())
            .spawn(move || loop {
                let mut batch = Vec::with_capacity(READ_BATCH);
                let mut failed = None;
                let mut end = false;
                while batch.len() < READ_BATCH {
                    match src.next_sample() {
                        Ok(Some(s)) => batch.push(s),
                        Ok(None) => {
                            end = true;
                            break;
                        }
                        Err(e) => {
                            failed = Some(e);
                            break;
                        }
                    }
                }
                // a consumer that stopped ends the thread (its receiver is gone)
                if !batch.is_empty() && tx.send(Batch::Samples(batch, src.fraction())).is_err() {
                    return;
                }
                if let Some(e) = failed {
                    let _ = tx.send(Batch::Failed(e));
                    return;
                }
                if end {
                    let _ = tx.send(Batch::End);
                    return;
                }
            })
            .map_err(|e| anyhow::anyhow!("cannot start the IMU reading thread: {e}"))?;
        Ok(ReadAhead {
            rx,
            current: Vec::new().into_iter(),
            fraction: 0.0,
            done: false,
        })
    }
}

impl SampleSource for ReadAhead {
    fn next_sample(&mut self) -> Result<Option<(ImuSample, usize)>> {
        loop {
            if let Some(s) = self.current.next() {
                return Ok(Some(s));
            }
            if self.done {
                return Ok(None);
            }
            match self.rx.recv() {
                Ok(Batch::Samples(v, f)) => {
                    self.current = v.into_iter();
                    self.fraction = f;
                }
                Ok(Batch::Failed(e)) => {
                    self.done = true;
                    return Err(e);
                }
                Ok(Batch::End) => self.done = true,
                Err(_) => {
                    // the thread ended without saying End: it panicked
                    self.done = true;
                    anyhow::bail!("the IMU reading thread stopped before the end of the file");
                }
            }
        }
    }
    fn fraction(&self) -> f64 {
        self.fraction
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples 1..=n, then an error when `fail`.
    struct Counting {
        k: usize,
        n: usize,
        fail: bool,
    }

    impl SampleSource for Counting {
        fn next_sample(&mut self) -> Result<Option<(ImuSample, usize)>> {
            if self.k == self.n {
                if self.fail {
                    anyhow::bail!("line {}: broken", self.k + 1);
                }
                return Ok(None);
            }
            self.k += 1;
            let s = ImuSample {
                t: self.k as f64,
                dtheta: nalgebra::Vector3::zeros(),
                dv: nalgebra::Vector3::zeros(),
            };
            Ok(Some((s, self.k)))
        }
        fn fraction(&self) -> f64 {
            self.k as f64 / self.n as f64
        }
    }

    #[test]
    fn read_ahead_hands_out_the_same_samples_then_the_same_end_or_error() {
        for (n, fail) in [(0, false), (5000, false), (2048, true), (3, true)] {
            let mut r = ReadAhead::spawn(Box::new(Counting { k: 0, n, fail })).unwrap();
            for k in 1..=n {
                let (s, line) = r.next_sample().unwrap().unwrap();
                assert_eq!((s.t, line), (k as f64, k));
            }
            match r.next_sample() {
                Ok(None) => assert!(!fail, "{n}"),
                Err(e) => assert!(fail && e.to_string() == format!("line {}: broken", n + 1)),
                Ok(Some(_)) => panic!("{n}: a sample past the end"),
            }
            // after the end, the end again
            assert!(matches!(r.next_sample(), Ok(None)));
        }
    }
}
