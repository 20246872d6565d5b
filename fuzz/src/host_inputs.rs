//! The `host_inputs` check: arbitrary bytes into the host's readers,
//! `io::las_in::read_points` (LAS/LAZ) and `Trajectory::parse_csv`, which must return an
//! error or a value, never panic. Byte 0 selects the reader: even = LAS/LAZ, odd =
//! trajectory CSV.
//!
//! One file serves two builds: the libFuzzer target `fuzz_targets/host_inputs.rs` (through
//! this crate's `host` feature) and the host crate's test `host-sim/tests/fuzz_replay.rs`,
//! which includes it by path and replays the committed corpus and every saved crash on each
//! test run without a sanitizer-coverage build of the host's dependencies.

use std::cmp::Ordering;
use std::path::Path;

use curbtrace_host_sim::io::las_in::{read_points, ReadOptions};
use curbtrace_host_sim::io::trajectory::Trajectory;

/// Runs one input. `scratch` is a file the LAS bytes are written to (the reader takes a
/// path); the caller chooses it per process.
pub fn check(data: &[u8], scratch: &Path) {
    let Some((&sel, bytes)) = data.split_first() else {
        return;
    };
    if sel & 1 == 0 {
        std::fs::write(scratch, bytes).expect("scratch file");
        let opts = ReadOptions {
            scanner: (sel & 2 != 0).then_some(u16::from(sel >> 2)),
        };
        if let Ok((cols, info)) = read_points(scratch, &opts, &mut |_, _| {}) {
            assert_eq!(cols.len() as u64, info.points_selected);
            assert!(cols.len() as u64 <= info.points_in_file);
            // Sorted by time (the reader's contract).
            let t = &cols.t;
            assert!(
                t.windows(2)
                    .all(|w| w[1].partial_cmp(&w[0]) != Some(Ordering::Less)),
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
}
