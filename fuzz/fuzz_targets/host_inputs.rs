//! The host's readers get arbitrary bytes: `las_in::read_points` (LAS/LAZ) and
//! `Trajectory::parse_csv` must return an error or a value, never panic, and never allocate
//! from an unchecked header field (libFuzzer's `-malloc_limit_mb` catches such an
//! allocation; `scripts/test.sh` runs with `-malloc_limit_mb=512`).
//!
//! Byte 0 selects the reader: even = LAS/LAZ, odd = trajectory CSV. `read_points` takes a
//! path, so the LAS bytes go through a per-process file under the temporary directory
//! (`/dev/shm` when present: no disk I/O).
#![no_main]

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use curbtrace_host_sim::io::las_in::{read_points, ReadOptions};
use curbtrace_host_sim::io::trajectory::Trajectory;
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

fuzz_target!(|data: &[u8]| {
    let Some((&sel, bytes)) = data.split_first() else {
        return;
    };
    if sel & 1 == 0 {
        let path = scratch();
        std::fs::write(path, bytes).expect("scratch file");
        let opts = ReadOptions {
            scanner: (sel & 2 != 0).then_some(u16::from(sel >> 2)),
        };
        if let Ok((cols, info)) = read_points(path, &opts, &mut |_, _| {}) {
            assert_eq!(cols.len() as u64, info.points_selected);
            assert!(cols.len() as u64 <= info.points_in_file);
            // Sorted by time (the reader's contract).
            let t = &cols.t;
            assert!(
                t.windows(2)
                    .all(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Less)),
                "not sorted by time"
            );
        }
    } else {
        let text = String::from_utf8_lossy(bytes);
        if let Ok(tr) = Trajectory::parse_csv(Path::new("fuzz.csv"), &text) {
            if let Some((a, b)) = tr.time_range() {
                assert!(a <= b);
                for t in [a, (a + b) / 2.0, b, a - 1.0, b + 1.0] {
                    let _ = tr.pose_at(t);
                }
            }
        }
    }
});
