//! With [`Counting`] as the global allocator, allocations and reallocations are counted and the
//! installation check passes.
use colcos_testkit::alloc::{Counting, allocations, assert_installed};

#[global_allocator]
static ALLOCATOR: Counting = Counting;

#[test]
fn allocations_and_reallocations_are_counted() {
    assert_installed();
    let before = allocations();
    let mut v: Vec<u64> = Vec::with_capacity(1);
    // Two elements outgrow the first block: a reallocation.
    v.extend([1, 2]);
    std::hint::black_box(&v);
    assert!(
        allocations() >= before + 2,
        "{} -> {}",
        before,
        allocations()
    );
}
