//! A global allocator for the fuzz targets that aborts on any single allocation larger than
//! [`LIMIT`] bytes. libFuzzer's `-malloc_limit_mb` needs a sanitizer's malloc hooks, which a
//! build with `-s none` (stable Rust) lacks, and a huge allocation that the kernel grants
//! lazily would not show in the RSS limit: this guard makes a capacity taken from a declared
//! count in the input (the bug class of "header says 10¹² nodes") a crash that libFuzzer saves.

use std::alloc::{GlobalAlloc, Layout, System};

/// Largest single allocation allowed (1 GiB); the inputs are at most a few KiB and the build
/// size guards keep legitimate meshes far below this.
pub const LIMIT: usize = 1 << 30;

/// The guard: [`System`] below [`LIMIT`], abort above it.
pub struct Guard;

fn too_large(size: usize) -> ! {
    // eprintln! of integers writes through stderr's unbuffered handle without allocating.
    eprintln!("alloc_guard: allocation of {size} bytes exceeds the fuzzing limit of {LIMIT} bytes");
    std::process::abort()
}

// SAFETY: every method forwards to `System` with the caller's layout unchanged, or aborts.
unsafe impl GlobalAlloc for Guard {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if layout.size() > LIMIT {
            too_large(layout.size());
        }
        // SAFETY: as the caller's contract.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if layout.size() > LIMIT {
            too_large(layout.size());
        }
        // SAFETY: as the caller's contract.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: as the caller's contract.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > LIMIT {
            too_large(new_size);
        }
        // SAFETY: as the caller's contract.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}
