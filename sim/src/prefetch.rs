//! A cache prefetch hint: asks the processor to start loading a value's cache line now, so that a later
//! read finds it close. It never changes results; where no hint instruction is available it does nothing.

/// Prefetches the cache line that holds `value` into all cache levels.
#[inline(always)]
pub fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: PREFETCHT0 (SSE, part of every x86-64 processor) only hints the cache; it never faults,
    // even on a bad address, and `value` is a valid reference anyway.
    unsafe {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        _mm_prefetch::<_MM_HINT_T0>(value as *const T as *const i8);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}
