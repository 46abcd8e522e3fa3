//! Cell storage of a grid field. Sensors and trail deposits read and write a large field at scattered
//! points (a 1 cm grid over 14.4 m x 8.1 m is 4.7 MB a pheromone, and 10,000 robots touch it all over
//! each step). With 4 KiB pages nearly every such access also misses the TLB, and on a virtual machine a
//! page walk is two walks. Large buffers are therefore anonymous mappings aligned to 2 MiB that ask the
//! kernel for transparent huge pages (Linux `MADV_HUGEPAGE`; a hint: where the kernel declines, they are
//! ordinary pages). Small buffers (batched environments hold thousands of small worlds) stay plain
//! vectors. Values are identical either way: only where they live changes.
use memmap2::MmapMut;
use std::ops::{Deref, DerefMut};
use std::ptr::NonNull;

/// Size and alignment of a transparent huge page on x86-64 and aarch64 Linux.
const HUGE_PAGE: usize = 2 << 20;
/// Buffers of at least this many bytes are mapped for huge pages.
const MAPPED_MIN_BYTES: usize = HUGE_PAGE;

/// A zero-initialised, fixed-length `[f32]` (see the module docs for where it lives).
pub struct CellBuffer {
    /// First value and number of values, fixed at construction: sensing reads cells through this
    /// slice millions of times a step, so taking it must cost no more than a `Vec`'s.
    ptr: NonNull<f32>,
    len: usize,
    /// Owns the memory `ptr` points into (never resized, so the values never move).
    owner: Storage,
}

// SAFETY: a `CellBuffer` owns its values exclusively (like a `Vec<f32>`): the pointer is into memory
// that `owner` owns and that no one else can reach, shared access only reads and mutation takes
// `&mut self`.
unsafe impl Send for CellBuffer {}
// SAFETY: as above; `&CellBuffer` only gives out `&[f32]`.
unsafe impl Sync for CellBuffer {}

/// The owner of a buffer's memory: held only to keep the values alive and to free them on drop.
enum Storage {
    Heap(#[allow(dead_code)] Vec<f32>),
    Mapped(#[allow(dead_code)] MmapMut),
}

impl CellBuffer {
    /// `len` zeros.
    pub fn zeros(len: usize) -> Self {
        let bytes = len * std::mem::size_of::<f32>();
        let on_heap = |len| {
            let mut v = vec![0.0f32; len];
            (
                NonNull::new(v.as_mut_ptr()).expect("a Vec's pointer is non-null"),
                Storage::Heap(v),
            )
        };
        let (ptr, storage) = if bytes >= MAPPED_MIN_BYTES {
            mapped(len).unwrap_or_else(|| on_heap(len))
        } else {
            on_heap(len)
        };
        CellBuffer {
            ptr,
            len,
            owner: storage,
        }
    }

    /// Whether the values live in a mapping that asked for huge pages.
    pub fn is_mapped(&self) -> bool {
        matches!(self.owner, Storage::Mapped(_))
    }
}

/// An anonymous mapping with room to start the values on a huge-page boundary and to end them on one (so
/// that every huge page they touch lies inside the mapping), advised for huge pages. `None` if the
/// mapping fails (the caller falls back to the heap).
fn mapped(len: usize) -> Option<(NonNull<f32>, Storage)> {
    let bytes = len * std::mem::size_of::<f32>();
    let span = bytes.div_ceil(HUGE_PAGE) * HUGE_PAGE;
    let mut map = MmapMut::map_anon(span + HUGE_PAGE).ok()?;
    let offset = (map.as_ptr() as usize).next_multiple_of(HUGE_PAGE) - map.as_ptr() as usize;
    #[cfg(target_os = "linux")]
    {
        // Only a hint: a kernel without transparent huge pages keeps small ones, values unchanged.
        let _ = map.advise_range(memmap2::Advice::HugePage, offset, span);
    }
    // The mapping is page-aligned and zero-filled, and `offset + bytes` lies within it.
    let values: &mut [f32] = bytemuck::cast_slice_mut(&mut map[offset..offset + bytes]);
    let ptr = NonNull::new(values.as_mut_ptr()).expect("a mapping's address is non-null");
    Some((ptr, Storage::Mapped(map)))
}

impl Deref for CellBuffer {
    type Target = [f32];
    #[inline(always)]
    fn deref(&self) -> &[f32] {
        // SAFETY: `ptr` points to `len` initialised f32 owned by `owner`, which lives as long as
        // `self` and never moves or resizes them (moving a `Vec` or a mapping does not move its data).
        unsafe { std::slice::from_raw_parts(self.ptr.as_ptr(), self.len) }
    }
}

impl DerefMut for CellBuffer {
    #[inline(always)]
    fn deref_mut(&mut self) -> &mut [f32] {
        // SAFETY: as in `deref`; `&mut self` makes this the only access.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.as_ptr(), self.len) }
    }
}

impl Default for CellBuffer {
    fn default() -> Self {
        CellBuffer::zeros(0)
    }
}

impl std::fmt::Debug for CellBuffer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CellBuffer")
            .field("len", &self.len())
            .field("mapped", &self.is_mapped())
            .finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_buffers_are_heap_vectors_of_zeros() {
        let b = CellBuffer::zeros(1000);
        assert!(!b.is_mapped());
        assert_eq!(b.len(), 1000);
        assert!(b.iter().all(|&v| v == 0.0));
    }

    #[test]
    fn large_buffers_start_on_a_huge_page_and_hold_exactly_their_values() {
        let len = 1440 * 810; // a 1 cm grid over 14.4 m x 8.1 m
        let mut b = CellBuffer::zeros(len);
        assert!(b.is_mapped());
        assert_eq!(b.len(), len);
        assert_eq!(b.as_ptr() as usize % HUGE_PAGE, 0);
        assert!(b.iter().all(|&v| v == 0.0));
        for (k, v) in b.iter_mut().enumerate() {
            *v = k as f32;
        }
        assert_eq!(b[len - 1], (len - 1) as f32);
        assert_eq!(
            b.iter().map(|&v| v as f64).sum::<f64>(),
            (len as f64 - 1.0) * len as f64 / 2.0
        );
    }
}
