//! Memory for the reverse-mode tape of a chunk of windows.
//!
//! The forward pass writes a chunk's tape (≈ 110 MB for 4 windows of the paper's shapes) and
//! the reverse pass reads it back once per evaluation. The tape is a stream far larger than the
//! caches, and on 4 KiB pages it also misses the TLB. So it lives in an anonymous mapping that
//! Linux is asked to back with transparent huge pages (`MADV_HUGEPAGE`). The hint is best
//! effort: it does nothing where THP is off, and where the mapping fails a heap vector is used.

use memmap2::MmapMut;

/// A reusable buffer of `f64` for the tape. Its contents are unspecified: every value is
/// written before it is read.
#[derive(Debug, Default)]
pub(crate) struct TapeMemory(Buffer);

#[derive(Debug, Default)]
enum Buffer {
    #[default]
    Empty,
    Mapped(MmapMut),
    Heap(Vec<f64>),
}

impl TapeMemory {
    /// The first `len` values, after growing the buffer if it holds fewer.
    pub(crate) fn reserve(&mut self, len: usize) -> &mut [f64] {
        if self.values().len() < len {
            self.0 = Buffer::Empty; // release the old buffer before mapping the new one
            self.0 = allocate(len);
        }
        &mut self.values()[..len]
    }

    fn values(&mut self) -> &mut [f64] {
        match &mut self.0 {
            Buffer::Empty => &mut [],
            Buffer::Mapped(map) => bytemuck::cast_slice_mut(&mut map[..]),
            Buffer::Heap(v) => v,
        }
    }
}

fn allocate(len: usize) -> Buffer {
    match MmapMut::map_anon(len.max(1) * size_of::<f64>()) {
        Ok(map) => {
            // Before the first touch, so that the pages are faulted in as 2 MiB pages.
            #[cfg(target_os = "linux")]
            let _ = map.advise(memmap2::Advice::HugePage);
            Buffer::Mapped(map)
        }
        Err(_) => Buffer::Heap(vec![0.0; len]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grows_and_keeps_what_fits() {
        let mut t = TapeMemory::default();
        assert!(t.reserve(0).is_empty());
        let a = t.reserve(1000);
        assert_eq!(a.len(), 1000);
        a.iter_mut().enumerate().for_each(|(i, v)| *v = i as f64);
        // Smaller requests reuse the buffer.
        let b = t.reserve(10);
        assert_eq!(b, (0..10).map(|i| i as f64).collect::<Vec<_>>());
        let c = t.reserve(1 << 20);
        assert_eq!(c.len(), 1 << 20);
        c[(1 << 20) - 1] = 2.5;
        assert_eq!(t.reserve(1 << 20)[(1 << 20) - 1], 2.5);
    }
}
