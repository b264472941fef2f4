//! The process's CPU time (all its threads, user + system), for the benchmarks: a stage whose
//! work is spread over a pool is charged all of it, which its wall time hides on a machine
//! with several cores and overstates on one shared with other work.

/// CPU milliseconds used by this process so far; `None` where the clock cannot be read.
pub fn process_cpu_ms() -> Option<f64> {
    #[cfg(unix)]
    {
        let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
        // SAFETY: clock_gettime writes one timespec through a valid pointer.
        let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
        (rc == 0).then_some(ts.tv_sec as f64 * 1e3 + ts.tv_nsec as f64 * 1e-6)
    }
    #[cfg(not(unix))]
    {
        None
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_clock_advances_with_work() {
        let a = super::process_cpu_ms().unwrap();
        let mut x = 0u64;
        for i in 0..20_000_000u64 {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(i);
        }
        std::hint::black_box(x);
        let b = super::process_cpu_ms().unwrap();
        assert!(b > a, "{a} -> {b}");
    }
}
