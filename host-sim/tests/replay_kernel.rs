//! `curbtrace replay` writes the core's input stream; `curbtrace kernel` runs the host build
//! of the core over it. Their line and candidate counts match the in-process replay.

mod common;

use curbtrace_core::wire::{OutputHeaderRepr, Packet, PacketKind, MAX_PACKET_LEN};
use std::process::Command;

#[test]
fn replay_then_kernel_matches_the_in_process_run() {
    let dir = tempfile::tempdir().unwrap();
    let road = common::Road {
        length_m: 6.0,
        ..Default::default()
    };
    let las = dir.path().join("road.las");
    let traj = dir.path().join("trajectory.csv");
    road.write(&las, &traj);
    let stream = dir.path().join("stream.bin");
    let results = dir.path().join("results.bin");
    let bin = env!("CARGO_BIN_EXE_curbtrace");
    let r = Command::new(bin)
        .arg("replay")
        .arg(&las)
        .arg("--trajectory")
        .arg(&traj)
        .arg("-o")
        .arg(&stream)
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let k = Command::new(bin)
        .arg("kernel")
        .arg(&stream)
        .arg("-o")
        .arg(&results)
        .output()
        .unwrap();
    let kerr = String::from_utf8_lossy(&k.stderr);
    assert!(k.status.success(), "{kerr}");
    assert!(kerr.contains("0 CRC errors"), "{kerr}");

    // Parse the output packets: count lines (fragment 0) and candidates.
    let bytes = std::fs::read(&results).unwrap();
    let (mut at, mut lines, mut cands) = (0usize, 0u64, 0u64);
    while at < bytes.len() {
        let len = usize::from(u16::from_le_bytes([bytes[at + 4], bytes[at + 5]]));
        assert!(len <= MAX_PACKET_LEN);
        let p = Packet::new_checked(&bytes[at..at + len]).unwrap();
        assert_eq!(p.check().unwrap(), PacketKind::Output);
        let (h, _) = OutputHeaderRepr::parse(&p).unwrap();
        if h.first == 0 {
            lines += 1;
            cands += u64::from(h.left.is_some()) + u64::from(h.right.is_some());
        }
        at += len;
    }
    let cfg = curbtrace_host_sim::config::Config::default();
    let rep = curbtrace_host_sim::pipeline::replay_file(
        &las,
        &traj,
        &cfg,
        &Default::default(),
        &curbtrace_host_sim::pipeline::Progress::hidden(),
    )
    .unwrap();
    assert_eq!(lines, rep.kernel.counters.scanlines);
    assert_eq!(cands, rep.kernel.candidates.len() as u64);
    assert_eq!(lines, 75, "6 m at 8 m/s, 100 lines/s");
}
