//! The host's readers get arbitrary bytes (`curbtrace_fuzz::host_inputs::check`):
//! `las_in::read_points` (LAS/LAZ) and `Trajectory::parse_csv` must return an error or a
//! value, never panic, and never allocate from an unchecked header field (libFuzzer's
//! `-malloc_limit_mb` catches such an allocation; `scripts/fuzz-smoke.sh` runs with
//! `-malloc_limit_mb=512`).
//!
//! `read_points` takes a path, so the LAS bytes go through a per-process file under the
//! temporary directory (`/dev/shm` when present: no disk I/O).
#![no_main]

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use curbtrace_fuzz::host_inputs::check;
use libfuzzer_sys::fuzz_target;

fn scratch() -> &'static PathBuf {
    static P: OnceLock<PathBuf> = OnceLock::new();
    P.get_or_init(|| {
        let dir = if Path::new("/dev/shm").is_dir() {
            PathBuf::from("/dev/shm")
        } else {
            std::env::temp_dir()
        };
        dir.join(format!("curbtrace-fuzz-{}.las", std::process::id()))
    })
}

fuzz_target!(|data: &[u8]| check(data, scratch()));
