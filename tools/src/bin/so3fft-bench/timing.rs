//! Clocks: wall and process CPU time of each transform, and the library's stage times.

use so3fft::StageTimes;
use std::time::Instant;

/// CPU time of the whole process (all threads) in seconds; NaN where unavailable. Against
/// the wall time it shows whether the run had its cores (the machine is shared).
pub fn cpu_seconds() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec that outlives the call.
    if unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) } != 0 {
        return f64::NAN;
    }
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

/// One timed transform.
#[derive(Clone, Copy, Debug)]
pub struct Timed {
    /// Wall time around the call, seconds.
    pub wall: f64,
    /// Process CPU time of the call (all threads), seconds.
    pub cpu: f64,
    /// The library's stage times.
    pub stages: StageTimes,
}

/// Runs `transform` and times it.
pub fn time(transform: impl FnOnce() -> so3fft::Result<StageTimes>) -> so3fft::Result<Timed> {
    let (cpu, start) = (cpu_seconds(), Instant::now());
    let stages = transform()?;
    Ok(Timed {
        wall: start.elapsed().as_secs_f64(),
        cpu: cpu_seconds() - cpu,
        stages,
    })
}

/// The times of every run of one configuration, per direction.
#[derive(Default)]
pub struct RunTimes {
    pub forward: Vec<Timed>,
    pub inverse: Vec<Timed>,
}

impl RunTimes {
    /// Times one inverse.
    pub fn inverse(
        &mut self,
        transform: impl FnOnce() -> so3fft::Result<StageTimes>,
    ) -> so3fft::Result<()> {
        self.inverse.push(time(transform)?);
        Ok(())
    }

    /// Times one forward.
    pub fn forward(
        &mut self,
        transform: impl FnOnce() -> so3fft::Result<StageTimes>,
    ) -> so3fft::Result<()> {
        self.forward.push(time(transform)?);
        Ok(())
    }
}

/// Median of `field` over `runs` (which must not be empty).
pub fn median_of(runs: &[Timed], field: impl Fn(&Timed) -> f64) -> f64 {
    crate::workload::median(&runs.iter().map(field).collect::<Vec<_>>())
}
