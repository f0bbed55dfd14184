//! The C heap (glibc's malloc, which Rust's allocator, llvmpipe and the
//! Vulkan loader all use on Linux): how it is tuned, what it holds, and
//! handing freed memory back to the system. Elsewhere these do nothing.
//!
//! glibc keeps what a program frees for reuse. It returns memory to the
//! system on its own only from the top of a heap, and by default it raises
//! its mmap threshold each time a large block is freed, so that later large
//! temporaries (decoded images, BVH builds, llvmpipe's shader compilation)
//! come from the heaps too. In a long session the holes they leave stay
//! resident: RSS climbs by steps that a soak's live-heap figure does not
//! show. [`release_free_memory`] returns every free page, wherever it is.

/// What the heap holds now.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HeapUsage {
    /// Bytes in blocks the program holds (heap and mmapped blocks).
    pub in_use_bytes: u64,
    /// Bytes free in the heaps: kept for reuse, resident where touched.
    pub free_bytes: u64,
}

#[cfg(all(target_os = "linux", target_env = "gnu"))]
mod glibc {
    use super::HeapUsage;

    /// At most two malloc arenas. glibc gives each thread that allocates
    /// its own arena and never returns one; llvmpipe's rasteriser threads
    /// (made again with a recreated device), the shader-build and loading
    /// threads each leave one behind, and RSS crept up by steps: a
    /// 3000-frame soak grew 417 -> 549 MiB after its warm-up, 348 -> 372
    /// MiB with two arenas. `MALLOC_ARENA_MAX` in the environment still
    /// overrides this.
    pub fn limit_arenas() {
        if std::env::var_os("MALLOC_ARENA_MAX").is_none() {
            // SAFETY: mallopt only sets an allocator parameter; it is
            // called before any other thread exists.
            unsafe {
                libc::mallopt(libc::M_ARENA_MAX, 2);
            }
        }
    }

    pub fn usage() -> Option<HeapUsage> {
        // SAFETY: mallinfo2 only reads the allocator's counters.
        let info = unsafe { libc::mallinfo2() };
        Some(HeapUsage {
            in_use_bytes: (info.uordblks + info.hblkhd) as u64,
            free_bytes: info.fordblks as u64,
        })
    }

    pub fn release_free_memory() {
        // SAFETY: malloc_trim takes the arenas' locks itself; with 0 it
        // keeps no padding and releases every whole free page.
        unsafe {
            libc::malloc_trim(0);
        }
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
mod glibc {
    use super::HeapUsage;

    pub fn limit_arenas() {}

    pub fn usage() -> Option<HeapUsage> {
        None
    }

    pub fn release_free_memory() {}
}

/// Caps the number of malloc arenas; call first thing in `main`, before
/// any thread starts.
pub fn limit_arenas() {
    glibc::limit_arenas();
}

/// The heap's usage, None where the allocator does not report it.
pub fn usage() -> Option<HeapUsage> {
    glibc::usage()
}

/// Returns the heap's free pages to the system (`malloc_trim(0)`): a few
/// milliseconds, so the viewer calls it every few seconds, not per frame.
pub fn release_free_memory() {
    glibc::release_free_memory();
}

#[cfg(all(test, target_os = "linux", target_env = "gnu"))]
mod tests {
    use super::*;

    /// Other tests in this binary allocate and free (a GPU device's
    /// tens of megabytes) on their threads between two readings: a
    /// reading disturbed so is taken again, up to five times; a heap
    /// whose usage never shows the block fails all five.
    #[test]
    fn a_large_block_shows_in_use_until_freed() {
        let mut seen = Vec::new();
        for _ in 0..5 {
            let before = usage().unwrap();
            let block = vec![1u8; 256 << 20];
            let holding = usage().unwrap();
            drop(std::hint::black_box(block));
            let after = usage().unwrap();
            if holding.in_use_bytes >= before.in_use_bytes + (240 << 20)
                && after.in_use_bytes + (240 << 20) <= holding.in_use_bytes
            {
                return;
            }
            seen.push((before, holding, after));
        }
        panic!("a 256 MiB block did not show in use, then freed: {seen:#?}");
    }
}
