//! The soak's resident memory: read once the allocator has handed its free pages back, sampled
//! every simulated minute for the curve and after every attempt for the growth, and the
//! growth per attempt fitted to those samples.

use serde::Serialize;

/// The resident memory at one moment of the soak.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MemorySample {
    pub simulated_s: f64,
    /// Attempts ended by then.
    pub attempts: u64,
    pub bytes: u64,
}

/// How the resident memory grew per attempt after the first round through every scene: over
/// all those attempts, and over their second half alone. Growth that levels off (an allocator
/// settling, caches filled once) shows a late slope far below the whole one; a leak keeps
/// both alike.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Growth {
    pub per_attempt_bytes: f64,
    pub late_per_attempt_bytes: f64,
    /// The attempts the slopes were fitted over.
    pub attempts: u64,
}

impl Growth {
    /// Fitted (least squares) to `samples`, one after each attempt, from the attempt that
    /// ended the first round (`first_round`) on.
    pub fn of(samples: &[MemorySample], first_round: u64) -> Self {
        let after: Vec<&MemorySample> = samples
            .iter()
            .filter(|s| s.attempts >= first_round)
            .collect();
        let late = &after[after.len() / 2..];
        Self {
            per_attempt_bytes: slope(&after),
            late_per_attempt_bytes: slope(late),
            attempts: after.len() as u64,
        }
    }
}

/// The least-squares slope of bytes against attempts (0 with fewer than two samples).
fn slope(samples: &[&MemorySample]) -> f64 {
    let n = samples.len() as f64;
    if samples.len() < 2 {
        return 0.0;
    }
    let mean_x = samples.iter().map(|s| s.attempts as f64).sum::<f64>() / n;
    let mean_y = samples.iter().map(|s| s.bytes as f64).sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for s in samples {
        let dx = s.attempts as f64 - mean_x;
        sxy += dx * (s.bytes as f64 - mean_y);
        sxx += dx * dx;
    }
    match sxx > 0.0 {
        true => sxy / sxx,
        false => 0.0,
    }
}

/// This process's resident memory (bytes), from `/proc/self/status`, once the allocator has
/// handed its free pages back to the system: what is live, not what the allocator keeps
/// cached for threads that have ended (each attempt's cut worker gets an arena of its own).
pub fn resident_bytes() -> Result<u64, String> {
    release_free_memory();
    let status = std::fs::read_to_string("/proc/self/status")
        .map_err(|e| format!("cannot read /proc/self/status for the resident memory: {e}"))?;
    status
        .lines()
        .find_map(|line| line.strip_prefix("VmRSS:"))
        .and_then(|kb| kb.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        .map(|kb| kb * 1024)
        .ok_or_else(|| "no VmRSS line in /proc/self/status".into())
}

/// Hands the allocator's free pages, in every arena, back to the system (glibc's `malloc_trim`).
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn release_free_memory() {
    unsafe extern "C" {
        fn malloc_trim(pad: usize) -> std::ffi::c_int;
    }
    // SAFETY: `malloc_trim` takes a byte count and only returns free memory to the system.
    unsafe { malloc_trim(0) };
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn release_free_memory() {}

#[cfg(test)]
mod tests {
    use super::*;

    fn samples(bytes: impl Fn(u64) -> u64) -> Vec<MemorySample> {
        (0..40)
            .map(|k| MemorySample {
                simulated_s: k as f64,
                attempts: k,
                bytes: bytes(k),
            })
            .collect()
    }

    /// A steady leak of 5 MB an attempt is fitted as such, early and late; growth that stops
    /// halfway has a late slope of nothing.
    #[test]
    fn a_leak_keeps_its_slope_and_a_settling_allocator_does_not() {
        let leak = Growth::of(&samples(|k| 1_000_000_000 + 5_000_000 * k), 10);
        assert!((leak.per_attempt_bytes - 5e6).abs() < 1.0);
        assert!((leak.late_per_attempt_bytes - 5e6).abs() < 1.0);
        assert_eq!(leak.attempts, 30);
        let settling = Growth::of(&samples(|k| 1_000_000_000 + 5_000_000 * k.min(24)), 10);
        assert!(settling.per_attempt_bytes > 1e6);
        assert_eq!(settling.late_per_attempt_bytes, 0.0);
    }
}
