//! A fresh rayon pool of a set size, for the tests that compare thread counts or must step a world
//! inside a pool.

/// Runs `f` inside a fresh rayon pool of `threads` threads and returns what it returns.
pub fn on_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a rayon pool")
        .install(f)
}
