//! A global allocator that counts: the system's, counting the allocations and reallocations every
//! thread makes, for the tests that a running step allocates nothing. A test binary installs it with
//!
//! ```ignore
//! #[global_allocator]
//! static ALLOCATOR: colcos_testkit::alloc::Counting = colcos_testkit::alloc::Counting;
//! ```
//!
//! (a type rather than a `#[global_allocator]` here, so that only the binaries that ask for it count).
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

/// The system allocator, counting allocations and reallocations into one process-wide counter.
pub struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

/// Allocations and reallocations so far, on every thread (0 forever unless [`Counting`] is the
/// binary's global allocator).
pub fn allocations() -> usize {
    ALLOCATIONS.load(Relaxed)
}

/// Panics unless [`Counting`] is this binary's global allocator: without it [`allocations`] stays 0
/// and a test that something allocates nothing would pass whatever it does.
pub fn assert_installed() {
    let before = allocations();
    std::hint::black_box(Box::new(0u64));
    assert!(
        allocations() > before,
        "colcos_testkit::alloc::Counting is not this binary's global allocator"
    );
}

#[cfg(test)]
mod tests {
    /// This test binary keeps the system allocator: the check says so.
    #[test]
    #[should_panic(expected = "not this binary's global allocator")]
    fn the_check_fails_without_the_counting_allocator() {
        super::assert_installed();
    }
}
