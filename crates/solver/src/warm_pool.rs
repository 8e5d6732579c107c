//! Keeps the other threads of the rayon pool awake while a run steps, so that each of the
//! step's ~60 parallel loops starts on threads that are already polling for work.
//!
//! Why: a rayon worker that finds no work for a few tens of microseconds goes to sleep on a
//! futex, and waking it costs more than a short parallel loop. A step alternates parallel
//! loops with short serial parts (prefix sums, counting sorts, scalar recurrences of the
//! Krylov solvers), so with two threads most loops paid that wake-up
//! (docs/notes/performance.md).
//!
//! This is what OpenMP runtimes do by default (active waiting for a while before
//! sleeping). The cost is CPU time, not wall time: while the stepping thread works alone,
//! the others spin in [`rayon::yield_now`] (which runs any job they can steal) and yield
//! the core to the OS scheduler between polls, so other processes on an oversubscribed
//! machine still get it. Rayon has no setting for its sleep threshold, hence this.
//!
//! Results do not change: which thread runs a task never changes what the task computes
//! (the parallel loops are deterministic by construction, `tests/determinism.rs`).

use std::sync::atomic::{AtomicBool, Ordering};

/// Runs `op` on the current thread while the pool's other threads poll for work; with one
/// thread, just runs `op`. Call it from a worker thread of the pool (the run driver does).
pub fn with_warm_workers<R: Send>(op: impl FnOnce() -> R + Send) -> R {
    if rayon::current_num_threads() == 1 {
        return op();
    }
    let done = AtomicBool::new(false);
    let me = rayon::current_thread_index();
    rayon::scope(|s| {
        // Every thread gets one copy; the stepping thread's copy returns at once (it would
        // otherwise spin inside one of its own joins and never return to it).
        s.spawn_broadcast(|_, ctx| {
            if Some(ctx.index()) != me {
                while !done.load(Ordering::Acquire) {
                    if rayon::yield_now() != Some(rayon::Yield::Executed) {
                        std::thread::yield_now();
                    }
                }
            }
        });
        // Set on return and on unwinding alike: a panicking `op` must not leave the
        // scope waiting for spinners that never stop.
        struct Stop<'a>(&'a AtomicBool);
        impl Drop for Stop<'_> {
            fn drop(&mut self) {
                self.0.store(true, Ordering::Release);
            }
        }
        let _stop = Stop(&done);
        op()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    /// Parallel work inside runs on every thread and gives the serial result; the call
    /// returns (the spinners stop) with one, two and three threads.
    #[test]
    fn parallel_work_inside_completes_and_the_spinners_stop() {
        for threads in 1..=3 {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("a pool");
            let sum = pool.install(|| {
                with_warm_workers(|| {
                    (0..200u64)
                        .map(|k| (0..10_000u64).into_par_iter().map(|i| i ^ k).sum::<u64>())
                        .sum::<u64>()
                })
            });
            let want: u64 = (0..200u64).map(|k| (0..10_000u64).map(|i| i ^ k).sum::<u64>()).sum();
            assert_eq!(sum, want, "{threads} threads");
        }
    }

    /// A panic inside propagates to the caller instead of hanging the scope.
    #[test]
    fn a_panic_inside_propagates() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("a pool");
        let r = pool.install(|| std::panic::catch_unwind(|| with_warm_workers(|| panic!("inside"))));
        assert!(r.is_err());
    }
}
