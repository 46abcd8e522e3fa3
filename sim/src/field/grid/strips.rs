//! A row-major grid cut into strips of columns that threads sweep row by row, each strip owning its
//! columns (the column-wise passes cannot be written as disjoint chunks of the slice).
use rayon::prelude::*;

/// Columns per strip of the column-wise sweeps (implicit y-solve, vertical wind).
const STRIP_COLS: usize = 128;

/// A row-major grid split into strips of columns that may be processed concurrently.
pub(super) struct StripGrid<'a> {
    ptr: SyncPtr,
    nx: usize,
    ny: usize,
    _borrow: std::marker::PhantomData<&'a mut [f32]>,
}

#[derive(Clone, Copy)]
struct SyncPtr(*mut f32);
// SAFETY: the pointer is only used to build slices of disjoint column strips (see `Strip`).
unsafe impl Send for SyncPtr {}
unsafe impl Sync for SyncPtr {}

/// Columns `[i0, i0 + width)` of every row of a [`StripGrid`].
pub(super) struct Strip<'a> {
    ptr: SyncPtr,
    nx: usize,
    pub(super) ny: usize,
    i0: usize,
    width: usize,
    _borrow: std::marker::PhantomData<&'a mut [f32]>,
}

impl<'a> StripGrid<'a> {
    pub(super) fn new(values: &'a mut [f32], nx: usize, ny: usize) -> Self {
        assert_eq!(values.len(), nx * ny);
        StripGrid {
            ptr: SyncPtr(values.as_mut_ptr()),
            nx,
            ny,
            _borrow: std::marker::PhantomData,
        }
    }

    pub(super) fn for_each_strip(self, parallel: bool, f: impl Fn(&mut Strip<'_>) + Sync + Send) {
        let (nx, ny, ptr) = (self.nx, self.ny, self.ptr);
        let nstrips = nx.div_ceil(STRIP_COLS);
        let run = |k: usize| {
            let i0 = k * STRIP_COLS;
            let width = STRIP_COLS.min(nx - i0);
            // Each strip owns its columns exclusively: no two strips alias.
            let mut s = Strip {
                ptr,
                nx,
                ny,
                i0,
                width,
                _borrow: std::marker::PhantomData,
            };
            f(&mut s);
        };
        if parallel {
            (0..nstrips).into_par_iter().for_each(run);
        } else {
            (0..nstrips).for_each(run);
        }
    }
}

impl Strip<'_> {
    pub(super) fn row(&mut self, j: usize) -> &mut [f32] {
        assert!(j < self.ny);
        // SAFETY: in bounds (j < ny, i0 + width <= nx); the strip holds its columns exclusively and the
        // returned slice borrows `self` mutably.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.0.add(j * self.nx + self.i0), self.width) }
    }

    /// Row `other` (read) and row `j` (write) of the strip; `other != j`.
    pub(super) fn rows2(&mut self, other: usize, j: usize) -> (&[f32], &mut [f32]) {
        assert!(other < self.ny && j < self.ny && other != j);
        // SAFETY: distinct rows of the strip do not overlap; both in bounds; borrows of `self`.
        unsafe {
            let o =
                std::slice::from_raw_parts(self.ptr.0.add(other * self.nx + self.i0), self.width);
            let c =
                std::slice::from_raw_parts_mut(self.ptr.0.add(j * self.nx + self.i0), self.width);
            (o, c)
        }
    }
}
