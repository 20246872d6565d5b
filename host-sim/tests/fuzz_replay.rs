//! The `host_inputs` fuzz target's check (`fuzz/src/host_inputs.rs`) on its committed
//! corpus and on every input that once crashed it (`fuzz/regressions/host_inputs/`), in the
//! ordinary test build. The fuzzing itself needs a sanitizer-coverage build of the host's
//! whole dependency tree, which `scripts/fuzz-smoke.sh` leaves to the long runs of
//! `docs/robustness.md`; the saved inputs run on every test run here.
//!
//! libFuzzer's `-malloc_limit_mb=512` is kept by the allocator below: it refuses a single
//! allocation over 512 MiB (one sized by an unchecked header field), which ends the test
//! binary with "memory allocation of N bytes failed".

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::{Path, PathBuf};

#[path = "../../fuzz/src/host_inputs.rs"]
mod host_inputs;

/// The largest single allocation allowed, as the fuzz runs' `-malloc_limit_mb=512`.
const MALLOC_LIMIT: usize = 512 << 20;

struct Limited;

// SAFETY: forwards to the system allocator, and answers an oversized request with null,
// the allocator's "out of memory".
unsafe impl GlobalAlloc for Limited {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if layout.size() > MALLOC_LIMIT {
            return std::ptr::null_mut();
        }
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > MALLOC_LIMIT {
            return std::ptr::null_mut();
        }
        System.realloc(ptr, layout, new_size)
    }
}

#[global_allocator]
static ALLOC: Limited = Limited;

/// The files of `fuzz/<dir>/host_inputs`, sorted, at least one.
fn inputs(dir: &str) -> Vec<PathBuf> {
    let d = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../fuzz")
        .join(dir)
        .join("host_inputs");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&d)
        .unwrap_or_else(|e| panic!("{}: {e}", d.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    assert!(!files.is_empty(), "{}: no inputs", d.display());
    files
}

fn replay(dir: &str) {
    let scratch = tempfile::tempdir().unwrap();
    let las = scratch.path().join("input.las");
    for f in inputs(dir) {
        let data = std::fs::read(&f).unwrap();
        // Each input as it is, and with byte 0 flipped to the other reader, so every file
        // meets both the LAS/LAZ and the CSV path.
        host_inputs::check(&data, &las);
        if let Some((&sel, rest)) = data.split_first() {
            let flipped: Vec<u8> = std::iter::once(sel ^ 1)
                .chain(rest.iter().copied())
                .collect();
            host_inputs::check(&flipped, &las);
        }
    }
}

#[test]
fn the_committed_corpus_runs_clean() {
    replay("corpus");
}

#[test]
fn every_saved_crash_runs_clean() {
    replay("regressions");
}
